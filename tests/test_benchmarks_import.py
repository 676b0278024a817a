"""Every benchmark module imports, from the project root, without running its benchmark.

The benchmarks are run as modules (``python -m benchmarks.<name>``) and import the installed
``sandwich`` package; a renamed or moved module they use breaks them silently, since no other
test runs them (they take minutes to hours). Importing is cheap: a module's work is in its
``main``, behind ``if __name__ == "__main__"``; FEniCSx is imported inside the functions that
solve the 2D model, so that no module here needs it at import.
"""

import importlib
import pkgutil
import sys
from pathlib import Path

import pytest

import benchmarks

ROOT = Path(__file__).resolve().parents[1]
MODULES = sorted(m.name for m in pkgutil.walk_packages(benchmarks.__path__, "benchmarks."))


def test_the_benchmark_modules_are_found():
    """The walk sees the scripts, the sweeps package and the shared cases (not an empty list)."""
    for name in ("benchmarks.beam_speed", "benchmarks.sweeps.tradeoff",
                 "benchmarks.cases.fracture_cases", "benchmarks.provenance"):
        assert name in MODULES
    files = {p.relative_to(ROOT).with_suffix("").as_posix().replace("/", ".")
             for p in (ROOT / "benchmarks").rglob("*.py")}
    assert {f.removesuffix(".__init__") for f in files} == {*MODULES, "benchmarks"}


@pytest.mark.parametrize("name", MODULES)
def test_a_benchmark_module_imports_without_running(name, monkeypatch, capsys):
    """Imported with no arguments on the command line, a module neither runs nor prints."""
    monkeypatch.setattr(sys, "argv", [name])
    module = importlib.import_module(name)
    assert module.__name__ == name
    assert capsys.readouterr().out == ""


def test_no_benchmark_edits_the_import_path():
    """The benchmarks import the installed package: none of them edits ``sys.path``."""
    edits = [p.relative_to(ROOT).as_posix() for p in (ROOT / "benchmarks").rglob("*.py")
             if "sys.path" in p.read_text(encoding="utf-8")]
    assert edits == []
