"""README.md is one page whose commands work.

Its code blocks hold exactly the two set-up commands (``make demo``, ``make test``) and the
tour's ``.venv/bin/sandwich`` commands; each tour command is run here, in order, through
``python -m sandwich.cli`` in a scratch folder holding copies of ``scenes/`` and ``studies/``
(so every result lands there, none in the repository), and must exit with the code the README
documents (0 unless its comment says ``exit N``). ``study`` and ``gallery`` runs are heavy.
"""

from __future__ import annotations

import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from sandwich.results.writing import RESULT_SET_NAMES
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SANDWICH = ".venv/bin/sandwich"
SETUP = ["make demo", "make test"]
HEAVY_COMMANDS = {"study", "gallery"}
TIMEOUT, HEAVY_TIMEOUT = 600, 3600  # s per command; a study or gallery on a loaded 2-core machine
MAX_LINES = 150
FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
EXIT_NOTE = re.compile(r"\bexit (\d)\b")


def code_lines() -> list[str]:
    """Every non-empty, non-comment line of the README's fenced code blocks."""
    lines = []
    for block in FENCE.findall(README.read_text(encoding="utf-8")):
        lines += [ln.strip() for ln in block.splitlines()
                  if ln.strip() and not ln.strip().startswith("#")]
    return lines


def tour() -> list[tuple[list[str], int]]:
    """The tour's commands as argument lists after ``sandwich``, with their expected exit code."""
    out = []
    for line in code_lines():
        if not line.startswith(SANDWICH + " "):
            continue
        comment = line.split(" #", 1)[1] if " #" in line else ""
        note = EXIT_NOTE.search(comment)
        out.append((shlex.split(line, comments=True)[1:], int(note.group(1)) if note else 0))
    return out


def test_readme_is_one_page():
    n = len(README.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, f"README.md has {n} lines, more than {MAX_LINES}"


def test_readme_has_exactly_the_two_setup_commands():
    make = [shlex.split(ln, comments=True) for ln in code_lines() if ln.startswith("make")]
    assert [" ".join(m) for m in make] == SETUP


def test_every_code_line_is_a_setup_or_a_tour_command():
    stray = [ln for ln in code_lines()
             if not ln.startswith("make ") and not ln.startswith(SANDWICH + " ")]
    assert stray == [], f"README code lines that no test runs: {stray}"


def test_the_tour_solves_each_model_and_compares():
    subcommands = [args[0] for args, _ in tour()]
    for needed in ("validate", "solve", "compare", "mesh"):
        assert needed in subcommands, f"the tour has no `sandwich {needed}`"
    models = {args[args.index("--model") + 1] for args, _ in tour() if "--model" in args}
    assert models == {"beam", "2d"}


def test_the_result_table_names_every_file_a_solve_writes():
    text = README.read_text(encoding="utf-8")
    for name in sorted(RESULT_SET_NAMES | {"fields_NNNNN.vtu"}):
        assert f"`{name}`" in text, f"README does not say that a solve writes {name}"


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    """A scratch folder with the shipped scenes and studies, where the tour writes."""
    work = tmp_path_factory.mktemp("tour")
    for folder in ("scenes", "studies"):
        shutil.copytree(ROOT / folder, work / folder)
    return work


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH")) if p)
    env.setdefault("MPLBACKEND", "Agg")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env


def _expand(args: list[str], cwd: Path) -> list[str]:
    """Shell globs (``scenes/*.toml``) expanded in ``cwd``, as the shell would."""
    out = []
    for a in args:
        hits = sorted(glob.glob(a, root_dir=cwd)) if any(c in a for c in "*?[") else []
        out += hits or [a]
    return out


def _check_result_folder(args: list[str], cwd: Path) -> None:
    """A solve's folder holds the files the README lists (tip tractions when there are tips)."""
    scene = load_scene(cwd / args[1])
    folder = cwd / "results" / scene.name / args[args.index("--model") + 1]
    names = {p.name for p in folder.iterdir()}
    expected = {"history.csv", "profiles.csv", "summary.json", "fields.pvd"}
    if any(d.start < d.end and (d.start > 0.0 or d.end < scene.length) for d in scene.debonds):
        expected.add("tip_tractions.csv")
    assert expected <= names, (folder, sorted(names))
    assert any(re.fullmatch(r"fields_\d+\.vtu", n) for n in names), sorted(names)


def _params():
    out = []
    for i, (args, code) in enumerate(tour()):
        heavy = args[0] in HEAVY_COMMANDS
        marks = [pytest.mark.heavy, pytest.mark.timeout(HEAVY_TIMEOUT)] if heavy else \
            [pytest.mark.timeout(TIMEOUT)]
        out.append(pytest.param(args, code, id=f"{i}-{'-'.join(args[:2])}", marks=marks))
    return out


@pytest.mark.dolfinx
@pytest.mark.parametrize(("args", "code"), _params())
def test_tour_command_runs(workspace, args, code):
    cmd = [sys.executable, "-m", "sandwich.cli", *_expand(args, workspace)]
    limit = HEAVY_TIMEOUT if args[0] in HEAVY_COMMANDS else TIMEOUT
    done = subprocess.run(cmd, cwd=workspace, env=_environment(), capture_output=True, text=True,
                          timeout=limit)
    assert done.returncode == code, (
        f"{' '.join(args)} exited {done.returncode}, README says {code}\n"
        f"{done.stdout[-2000:]}\n{done.stderr[-2000:]}")
    assert "Traceback" not in done.stderr
    if args[0] == "solve" and "--out" not in args:
        _check_result_folder(args, workspace)
