"""Valid-but-unusual scenes (tests/scenes/unusual, written by tests/scenes/make_unusual.py):
every command answers them without an internal error or a traceback.

A run may stop before its target (exit 1, with the reason) — a one-step budget does — and a
feature smaller than a 2D mesh level resolves is refused for that level (exit 2, naming the
scene file and key), but nothing exits 3 or prints a traceback. The 2D solves are the heavy part
(``make test-heavy``).
"""

from pathlib import Path

import pytest

from sandwich.cli import EXIT_INTERNAL, main

CORPUS = sorted((Path(__file__).resolve().parent / "scenes" / "unusual").glob("*.toml"))


def test_corpus_is_large_enough():
    assert len(CORPUS) >= 30


def _run(argv, capsys):
    code = main(argv)
    out = capsys.readouterr()
    text = out.out + out.err
    assert "Traceback" not in text and "internal error" not in text, text[-2000:]
    assert code != EXIT_INTERNAL
    return code, text


def test_every_unusual_scene_validates(capsys):
    code, _ = _run(["validate", *map(str, CORPUS)], capsys)
    assert code == 0


@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem)
def test_beam_solves_every_unusual_scene(path, tmp_path, capsys):
    code, _ = _run(["solve", str(path), "--model", "beam", "--out", str(tmp_path), "--quiet"],
                   capsys)
    assert code in (0, 1)
    assert (tmp_path / "summary.json").is_file() and (tmp_path / "history.csv").is_file()


@pytest.mark.dolfinx
@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem)
def test_every_unusual_scene_meshes(path, tmp_path, capsys):
    pytest.importorskip("gmsh")
    code, text = _run(["mesh", str(path), "--out", str(tmp_path), "--level", "coarse"], capsys)
    assert code == 0 or (code == 2 and f"{path}: debonds[" in text), text


@pytest.mark.heavy
@pytest.mark.dolfinx
@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem)
def test_2d_solves_every_unusual_scene(path, tmp_path, capsys):
    pytest.importorskip("dolfinx")
    code, text = _run(["solve", str(path), "--model", "2d", "--level", "coarse", "--out",
                       str(tmp_path), "--quiet"], capsys)
    assert code in (0, 1) or (code == 2 and f"{path}: debonds[" in text), text
