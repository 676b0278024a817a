"""Hostile scene files and names: refused with file, key and reason (exit 2), never a traceback.

Each case is one that a probe of the command line found to crash or to write outside its folder
(issue 16); the expected reasons are written here from the contract, not copied from the code.
"""

import os
from pathlib import Path

import pytest

from sandwich.cli import main

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = (ROOT / "scenes" / "default.toml").read_text()


def _validate(path, capsys):
    code = main(["validate", str(path)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, err


@pytest.mark.parametrize("name", ["../escape", "/tmp/abs", "..", ".hidden", "a/b", "a b",
                                  "x" * 101, "nul\u0000name"])
def test_a_scene_name_that_cannot_be_a_folder_is_refused(tmp_path, capsys, name):
    path = tmp_path / "s.toml"
    escaped = name.replace("\\", "\\\\").replace('"', '\\"').replace("\u0000", "\\u0000")
    path.write_text(DEFAULT.replace('name = "default"', f'name = "{escaped}"', 1))
    code, err = _validate(path, capsys)
    assert code == 2 and f"{path}: name: " in err and "cannot name a result folder" in err


def test_a_probe_name_that_cannot_be_a_file_name_is_refused(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(DEFAULT.replace('name = "w_top_mid"', 'name = "../../w"', 1))
    code, err = _validate(path, capsys)
    assert code == 2 and "probes[0].name" in err and "cannot name a result folder" in err


def test_a_folder_and_a_fifo_are_not_scene_files(tmp_path, capsys):
    code, err = _validate(tmp_path, capsys)
    assert code == 2 and "not a regular file" in err
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    code, err = _validate(fifo, capsys)
    assert code == 2 and "not a regular file" in err


def test_a_symlink_loop_is_not_called_missing(tmp_path, capsys):
    loop = tmp_path / "loop.toml"
    loop.symlink_to(loop)
    code, err = _validate(loop, capsys)
    assert code == 2 and "no such file" not in err and str(loop) in err


def test_a_byte_order_mark_is_accepted(tmp_path, capsys):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + DEFAULT.encode())
    code, _ = _validate(path, capsys)
    assert code == 0


def test_deeply_nested_toml_is_refused_in_words(tmp_path, capsys):
    path = tmp_path / "deep.toml"
    path.write_text(DEFAULT + "\nbomb = " + "[" * 100_000 + "]" * 100_000 + "\n")
    code, err = _validate(path, capsys)
    assert code == 2 and str(path) in err


@pytest.mark.parametrize("old, new, key, words", [
    ("length = 300.0", "length = 1e308", "beam.length", "beyond any physical scale"),
    ("width = 60.0", "width = 1e-300", "beam.width", "below the smallest size"),
    ("max_steps = 400", "max_steps = 400\ntol = 1e-300", "analysis.tol", "below round-off"),
    ("nu = 0.3", "nu = 0.9999999", ".nu", "nearly singular"),
    ("nu = 0.3", "nu = -0.9999999", ".nu", "nearly singular"),
])
def test_physically_meaningless_numbers_are_refused(tmp_path, capsys, old, new, key, words):
    assert old in DEFAULT, old
    path = tmp_path / "s.toml"
    path.write_text(DEFAULT.replace(old, new, 1))
    code, err = _validate(path, capsys)
    assert code == 2 and key in err and words in err
