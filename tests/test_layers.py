"""The import graph: layers point one way, no module cycle, no dynamic imports.

Read from the sources (every ``import`` statement, also those inside functions), not from what
happens to be loaded: docs/architecture.md names the layers.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# layer -> the layers it may import (the order of docs/architecture.md). The contract is the
# ``sandwich`` package's own modules, ``sandwich.results`` and ``sandwich.solver``; every other
# subpackage of ``sandwich`` is a layer of its own.
ALLOWED = {
    "sandwich": set(),
    "sandwich.beam": {"sandwich"},
    "sandwich.meshes": {"sandwich"},
    "sandwich.plane2d": {"sandwich", "sandwich.meshes"},
    "sandwich.models": {"sandwich", "sandwich.beam", "sandwich.meshes", "sandwich.plane2d"},
    "sandwich.compare": {"sandwich", "sandwich.models"},
    "sandwich.studies": {"sandwich", "sandwich.beam", "sandwich.meshes", "sandwich.plane2d",
                         "sandwich.models", "sandwich.compare"},
    "sandwich.cli": {"sandwich", "sandwich.meshes", "sandwich.models", "sandwich.compare",
                     "sandwich.studies"},
}
LAYERS = set(ALLOWED)


def _layer(module):
    """The layer a dotted module name belongs to (None: not the project's)."""
    parts = module.split(".")
    if parts[0] != "sandwich":
        return None
    if len(parts) > 1 and "sandwich." + parts[1] in LAYERS:
        return "sandwich." + parts[1]
    return "sandwich"


def _modules():
    for path in sorted((ROOT / "sandwich").rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


def test_one_top_level_package():
    """Nothing but ``sandwich`` is installed: no other folder of the project is a package."""
    import tomllib

    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert cfg["tool"]["setuptools"]["packages"]["find"]["include"] == ["sandwich*"]
    others = sorted(p.parent.name for p in ROOT.glob("*/__init__.py")
                    if p.parent.name not in ("sandwich", "benchmarks"))
    assert not others, others


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
        layer = _layer(name)
        for target in _imports(path):
            top = _layer(target)
            if top is not None and top != layer and top not in ALLOWED[layer]:
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
