"""Read a scene file: TOML text → the checks of :mod:`sandwich.scene_checks` → a typed Scene."""

from __future__ import annotations

import stat
import tomllib
from pathlib import Path

from sandwich.scene import Problem, Scene, SceneError
from sandwich.scene_checks import build_scene


def load_scene(path: str | Path) -> Scene:
    """Read, check and return the scene in ``path``; raise :class:`SceneError` if it is bad.

    Every way a file can fail to be a scene is a :class:`SceneError` naming the file and the
    reason: absent, not a regular file (a folder, a FIFO, a symlink loop), unreadable, not UTF-8
    (a UTF-8 byte-order mark is accepted), not TOML, nested too deeply, or a scene the checks
    refuse.
    """
    path = Path(path)
    data = read_toml_file(path, "scene", SceneError)
    fname = str(path)
    try:
        return build_scene(data, fname, source=path)
    except RecursionError:
        raise SceneError([Problem(fname, "-", "nested too deeply to be a scene")]) from None


def read_toml_file(path: Path, what: str, error: type[Exception] = SceneError) -> dict:
    """The TOML table of ``path``, or ``error([Problem])`` naming the file and why it is not one.

    Shared by scene and study files: absent, not a regular file (a folder, a FIFO, a symlink
    loop), unreadable, a NUL in the name, not UTF-8 (a byte-order mark is accepted), not TOML,
    nested too deeply to be a ``what``.
    """
    fname = str(path)
    if "\0" in fname:  # the system cannot take it (Python raises ValueError)
        raise error([Problem(fname.replace("\0", "\\0"), "-",
                             "cannot be read (a NUL character in the file name)")])
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise error([Problem(fname, "-", "no such file")]) from None
    except OSError as exc:  # a symlink loop, a name too long
        raise error([Problem(fname, "-", f"cannot be read ({exc.strerror or exc})")]) from None
    if not stat.S_ISREG(mode):
        raise error([Problem(fname, "-", "not a regular file")])
    try:
        raw = path.read_bytes()
    except OSError as exc:  # no permission, an I/O error
        raise error([Problem(fname, "-", f"cannot be read ({exc.strerror or exc})")]) from None
    try:
        return tomllib.loads(raw.decode("utf-8-sig"))
    except UnicodeDecodeError as exc:
        raise error([Problem(fname, "-", f"not UTF-8 text ({exc.reason})")]) from None
    except tomllib.TOMLDecodeError as exc:
        raise error([Problem(fname, "-", f"not valid TOML: {exc}")]) from None
    except RecursionError:
        raise error([Problem(fname, "-", f"nested too deeply to be a {what}")]) from None
