"""The import graph: layers point one way, no module cycle, no dynamic imports.

Read from the sources (every ``import`` statement, also those inside functions), not from what
happens to be loaded: docs/architecture.md names the layers.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# package -> the project packages it may import (the order of docs/architecture.md)
ALLOWED = {
    "sandwich": set(),
    "beam_element": {"sandwich"},
    "meshes": {"sandwich"},
    "reference2d": {"sandwich", "meshes"},
    "models": {"sandwich", "beam_element", "meshes", "reference2d"},
    "comparisons": {"sandwich", "models"},
    "studies": {"sandwich", "beam_element", "meshes", "reference2d", "models", "comparisons"},
    "sandwich_cli": {"sandwich", "meshes", "models", "comparisons", "studies"},
}
PACKAGES = set(ALLOWED)


def _modules():
    for pkg in ALLOWED:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            rel = path.relative_to(ROOT).with_suffix("")
            parts = list(rel.parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            yield ".".join(parts), path


def _imports(path):
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module
            yield from (f"{node.module}.{a.name}" for a in node.names)


def test_every_import_points_down_the_layers():
    wrong = []
    for name, path in _modules():
        pkg = name.split(".")[0]
        for target in _imports(path):
            top = target.split(".")[0]
            if top in PACKAGES and top != pkg and top not in ALLOWED[pkg]:
                wrong.append(f"{path.relative_to(ROOT)} imports {target}")
    assert not wrong, "\n".join(wrong)


def test_no_module_imports_itself_back():
    names = dict(_modules())
    graph = {n: {t for t in _imports(p) if t in names and t != n} for n, p in names.items()}
    # a package's __init__ re-exporting its modules is not a cycle of code: drop edges from a
    # package to its own submodules
    graph = {n: {t for t in ts if not t.startswith(n + ".")} for n, ts in graph.items()}
    cycles, state = [], {}

    def visit(n, stack):
        state[n] = 1
        for t in graph[n]:
            if state.get(t) == 1:
                cycles.append(" -> ".join(stack[stack.index(t):] + [t]))
            elif t not in state:
                visit(t, [*stack, t])
        state[n] = 2

    for n in graph:
        if n not in state:
            visit(n, [n])
    assert not cycles, "\n".join(cycles)


def test_no_dynamic_import_and_no_file_loaded_by_path():
    found = []
    for path in [p for _, p in _modules()] + sorted((ROOT / "tests").rglob("*.py")):
        if path == Path(__file__):
            continue
        text = path.read_text(encoding="utf-8")
        for word in ("import_module", "spec_from_file_location", "__import__("):
            if word in text:
                found.append(f"{path.relative_to(ROOT)}: {word}")
    assert not found, "\n".join(found)
