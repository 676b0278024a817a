"""Numba for the compiled kernels, with an on-disk cache that also works from a read-only install.

Compiled kernels (``beam_element.kernels``, :mod:`sandwich.solver.envelope`) are decorated with
:func:`njit`, i.e. ``numba.njit(cache=True)``: the machine code is written to disk on the first
call and loaded (not recompiled) by every later process. Where the cache lives:

1. ``$NUMBA_CACHE_DIR`` if the user set it;
2. else numba's default, ``__pycache__`` next to the kernel's source file, when that directory
   is writable (a source checkout or an editable install);
3. else numba's user-wide cache, ``$XDG_CACHE_HOME/numba`` (``~/.cache/numba``), when writable;
4. else (read-only install and read-only home) a directory under the system temporary directory,
   ``<tmp>/sandwich-numba-cache-<uid>``, set as ``NUMBA_CACHE_DIR`` before numba is imported.

:func:`cache_directory` says which one applies. ``import numba`` is deferred to the first kernel
module import, so code paths that never evaluate a kernel do not pay its ~0.15 s import.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["cache_directory", "njit"]

_HERE = Path(__file__).resolve()
_SOURCE_DIRS = (_HERE.parent, _HERE.parents[2] / "beam_element")  # the kernels' source dirs


def _writable(path: Path) -> bool:
    """Whether ``path`` (or, if it does not exist, its nearest existing parent) is writable."""
    p = path
    while not p.exists():
        if p.parent == p:
            return False
        p = p.parent
    return p.is_dir() and os.access(p, os.W_OK | os.X_OK)


def _user_cache() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "numba"


def cache_directory(source_dirs: tuple[Path, ...] = _SOURCE_DIRS) -> tuple[str, Path | None]:
    """Where numba will cache the kernels: ``(rule, directory)``.

    ``rule`` is ``"NUMBA_CACHE_DIR"``, ``"in-tree"``, ``"user"`` or ``"temporary"`` (numbered 1-4
    in the module docstring); ``directory`` is None for ``"in-tree"`` (one ``__pycache__`` per
    source directory).
    """
    env = os.environ.get("NUMBA_CACHE_DIR")
    if env:
        return "NUMBA_CACHE_DIR", Path(env)
    if all(_writable(d / "__pycache__") for d in source_dirs):
        return "in-tree", None
    user = _user_cache()
    if _writable(user):
        return "user", user
    return "temporary", Path(tempfile.gettempdir()) / f"sandwich-numba-cache-{os.getuid()}"


def _configure() -> None:
    """Point numba at a writable cache (rule 4) before it reads its configuration."""
    rule, directory = cache_directory()
    if rule == "temporary":
        os.environ["NUMBA_CACHE_DIR"] = str(directory)
        import sys

        numba = sys.modules.get("numba")
        if numba is not None:  # already imported by someone else: its config is read
            numba.config.CACHE_DIR = str(directory)


def njit(fn: Callable | None = None, *, reassociate: bool = False) -> Callable:
    """``numba.njit(cache=True)``, IEEE arithmetic.

    ``reassociate=True`` lets LLVM reorder sums (fastmath flags ``reassoc`` and ``contract``
    only: NaN and infinity keep their meaning), which vectorises dot-product loops; the result
    is then rounded differently from the loop as written, but reproducibly so.
    """
    if fn is None:
        return lambda f: njit(f, reassociate=reassociate)
    _configure()
    import numba

    flags = {"reassoc", "contract"} if reassociate else False
    # error_model "numpy": a division by zero gives inf/NaN (checked by the callers), not an
    # exception from inside the loop
    return numba.njit(cache=True, nogil=True, fastmath=flags, error_model="numpy")(fn)
