"""Every benchmark module imports, from the project root, without running its benchmark.

The benchmarks are run as modules (``python -m benchmarks.<name>``) and import the installed
``sandwich`` package; a renamed or moved module they use breaks them silently, since no other
test runs them (they take minutes to hours). Importing is cheap: a module's work is in its
``main``, behind ``if __name__ == "__main__"``; FEniCSx is imported inside the functions that
solve the 2D model, so that no module here needs it at import.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def benchmark_modules() -> list[str]:
    """The dotted names of every module file under ``benchmarks/`` (packages included)."""
    names = (p.relative_to(ROOT).with_suffix("").as_posix().replace("/", ".")
             for p in (ROOT / "benchmarks").rglob("*.py"))
    return sorted(n.removesuffix(".__init__") for n in names)


def test_the_walk_finds_the_scripts_the_sweeps_and_the_shared_cases():
    modules = benchmark_modules()
    for name in ("benchmarks", "benchmarks.beam_speed", "benchmarks.sweeps.tradeoff",
                 "benchmarks.cases.fracture_cases", "benchmarks.provenance"):
        assert name in modules


def test_every_benchmark_module_imports_and_runs_nothing():
    """All modules imported in one fresh interpreter with no arguments: no error, no output."""
    modules = benchmark_modules()
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-c", "import " + ", ".join(modules)], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout == "", p.stdout[-3000:]  # a module that runs at import prints its rows


def test_no_benchmark_edits_the_import_path():
    """The benchmarks import the installed package: none of them edits ``sys.path``."""
    edits = [p.relative_to(ROOT).as_posix() for p in (ROOT / "benchmarks").rglob("*.py")
             if "sys.path" in p.read_text(encoding="utf-8")]
    assert edits == []
