"""The hostile-input corpus of issue 16 through every command, in a sandbox.

Each class of hostile input a probe of the command line used (names that escape their folder,
NUL and over-long names, a parse bomb, absurd magnitudes, an unreadable file, a folder or a FIFO
as the scene, bad options, an unusable ``--out``) is run through ``validate``, ``solve`` (both
models), ``mesh`` and ``compare`` with the current folder an empty temporary folder. The
contract (README "exit codes", docs/scenes.md): every one is refused before any work with exit
code 2 (never 3), no traceback is printed, no model is called, nothing is written anywhere (the
sandbox is unchanged, the current folder stays empty, nothing escapes to its parents or /tmp).

The models are the synthetic solvers of this folder (a refusal must not reach them; a case the
guards let through would call them and fail). Which words each refusal uses is tested where the
check lives (tests/test_hostile_inputs.py, test_cmp_cli_runs.py, tests/test_memory_guard.py).
"""

import os
from pathlib import Path

import pytest

from sandwich.cli import main

FIG5_NAME = 'name = "paper-fig5-top-debond-40-load-top"'
SCENE_EDITS = {  # fig5 scene text: (old, new)
    "escaping name": (FIG5_NAME, 'name = "../../escape"'),
    "absolute name": (FIG5_NAME, 'name = "/tmp/abs"'),
    "dot-dot name": (FIG5_NAME, 'name = ".."'),
    "NUL in the name": (FIG5_NAME, 'name = "a\\u0000b"'),
    "300-character name": (FIG5_NAME, f'name = "{"x" * 300}"'),
    "escaping probe name": ('name = "w_top_mid"', 'name = "../w"'),
    "huge length": ("length = 300.0", "length = 1e308"),
    "tiny width": ("width = 60.0", "width = 1e-300"),
    "deeply nested TOML": ("[beam]", "bomb = " + "[" * 50_000 + "]" * 50_000 + "\n[beam]"),
}
OPTIONS = {  # option classes: argv, and the commands taking it
    "--refine -3": (["--refine", "-3"], ("solve-2d", "mesh")),
    "--refine 9": (["--refine", "9"], ("solve-2d", "mesh")),
    "--elements 0": (["--elements", "0"], ("solve-beam",)),
    "--elements -5": (["--elements", "-5"], ("solve-beam",)),
    "--level on the beam": (["--level", "fine"], ("solve-beam",)),
    "--elements on the 2D model": (["--elements", "40"], ("solve-2d",)),
}
COMMANDS = ("validate", "solve-beam", "solve-2d", "mesh", "compare")


def _argv(command: str, scene: str) -> list[str]:
    return {"validate": ["validate", scene], "solve-beam": ["solve", scene, "--model", "beam"],
            "solve-2d": ["solve", scene, "--model", "2d"], "mesh": ["mesh", scene],
            "compare": ["compare", scene]}[command]


def _tree(root: Path) -> dict[str, int]:
    """Every path under ``root`` with its size (folders 0), FIFOs not opened."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            out[str(p.relative_to(root))] = p.lstat().st_size if p.is_file() else 0
    return out


def _unreadable(path: Path, monkeypatch) -> None:
    """``path`` cannot be read: chmod 000, or (as root, whom chmod does not stop) a mock."""
    if os.geteuid() != 0:
        path.chmod(0o000)
        return
    real = Path.read_bytes

    def read_bytes(self):
        if self == path:
            raise PermissionError(13, "Permission denied", str(self))
        return real(self)

    monkeypatch.setattr(Path, "read_bytes", read_bytes)


def _read_only(folder: Path, monkeypatch) -> None:
    """``folder`` cannot be written: chmod 555, or (as root) ``os.access`` says so."""
    folder.mkdir()
    if os.geteuid() != 0:
        folder.chmod(0o555)
        return
    from sandwich.results import writing

    real = os.access
    monkeypatch.setattr(writing.os, "access", lambda p, mode, **kw: False if Path(p) == folder
                        else real(p, mode, **kw))


def _run(tmp_path, monkeypatch, capsys, argv):
    """Run ``argv`` from an empty current folder; check the sandbox contract; the stderr."""
    work = tmp_path / "cwd"
    work.mkdir()
    monkeypatch.chdir(work)
    before = _tree(tmp_path)
    try:
        code = main(argv)
    finally:
        for p in tmp_path.rglob("*"):  # a chmod 000/555 case: give the test's cleanup access
            if not p.is_symlink() and not p.is_fifo():
                p.chmod(0o755 if p.is_dir() else 0o644)
    printed = capsys.readouterr()
    assert code == 2, printed.err
    assert "Traceback" not in printed.err + printed.out
    assert "internal error" not in printed.err
    assert list(work.iterdir()) == []
    assert _tree(tmp_path) == before
    assert not (tmp_path.parent / "escape").exists() and not Path("/tmp/abs").exists()
    assert not (tmp_path / "results").exists()
    return printed.err


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("case", sorted(SCENE_EDITS))
def test_a_hostile_scene_is_refused_and_writes_nothing(tmp_path, scene_file, fake_models,
                                                       monkeypatch, capsys, case, command):
    old, new = SCENE_EDITS[case]
    assert old in scene_file.read_text()
    scene_file.write_text(scene_file.read_text().replace(old, new, 1))
    # no --out: the default folders (results/<scene>/...) are relative to the empty cwd
    err = _run(tmp_path, monkeypatch, capsys, _argv(command, str(scene_file)))
    assert str(scene_file) in err and fake_models == []


def _folder(tmp_path, scene_file, monkeypatch):
    (tmp_path / "folder.toml").mkdir()
    return tmp_path / "folder.toml"


def _fifo(tmp_path, scene_file, monkeypatch):
    os.mkfifo(tmp_path / "pipe.toml")
    return tmp_path / "pipe.toml"


def _unreadable_scene(tmp_path, scene_file, monkeypatch):
    _unreadable(scene_file, monkeypatch)
    return scene_file


SCENE_PATHS = {  # case: (tmp_path, scene_file, monkeypatch) -> the scene path given
    "folder as scene": _folder,
    "FIFO as scene": _fifo,
    "unreadable scene": _unreadable_scene,
    "NUL in the path": lambda tmp, scene, mp: Path(str(scene) + "\0.toml"),
    "300-character path": lambda tmp, scene, mp: tmp / ("y" * 300 + ".toml"),
}


def _out_file(tmp_path, monkeypatch):
    (tmp_path / "file").write_text("x")
    return tmp_path / "file"


def _out_read_only(tmp_path, monkeypatch):
    _read_only(tmp_path / "ro", monkeypatch)
    return tmp_path / "ro" / "sub"


OUTS = {  # case: (tmp_path, monkeypatch) -> the --out given
    "--out is a file": _out_file,
    "--out read-only": _out_read_only,
    "--out with NUL": lambda tmp, mp: Path(str(tmp / "o") + "\0x"),
    "--out 300-character name": lambda tmp, mp: tmp / ("z" * 300) / "sub",
}


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("case", sorted(SCENE_PATHS))
def test_a_scene_path_that_is_not_a_readable_file_is_refused(tmp_path, scene_file, fake_models,
                                                             monkeypatch, capsys, case,
                                                             command):
    path = SCENE_PATHS[case](tmp_path, scene_file, monkeypatch)
    err = _run(tmp_path, monkeypatch, capsys, _argv(command, str(path)))
    assert fake_models == [] and " -: " in err


@pytest.mark.parametrize("case, command", [(c, cmd) for c, (_, cmds) in sorted(OPTIONS.items())
                                           for cmd in cmds])
def test_a_bad_option_is_refused_and_writes_nothing(tmp_path, scene_file, fake_models,
                                                    monkeypatch, capsys, case, command):
    options, _ = OPTIONS[case]
    err = _run(tmp_path, monkeypatch, capsys,
               [*_argv(command, str(scene_file)), *options, "--out", str(tmp_path / "out")])
    assert fake_models == [] and options[0] in err


@pytest.mark.parametrize("command", [c for c in COMMANDS if c != "validate"])
@pytest.mark.parametrize("case", sorted(OUTS))
def test_an_unusable_output_folder_is_refused_before_any_work(tmp_path, scene_file, fake_models,
                                                              monkeypatch, capsys, case,
                                                              command):
    out = OUTS[case](tmp_path, monkeypatch)
    err = _run(tmp_path, monkeypatch, capsys,
               [*_argv(command, str(scene_file)), "--out", str(out)])
    assert fake_models == [] and ("folder" in err or "writable" in err)
