"""Numba for the compiled kernels, with an on-disk cache that also works from a read-only install.

Compiled kernels (``sandwich.beam.kernels``, :mod:`sandwich.solver.envelope`) are decorated with
:func:`njit`, i.e. ``numba.njit(cache=True)``: the machine code is written to disk on the first
call and loaded (not recompiled) by every later process. Where the cache lives:

1. ``$NUMBA_CACHE_DIR`` if the user set it;
2. else numba's default, ``__pycache__`` next to the kernel's source file, when that directory
   is writable (a source checkout or an editable install);
3. else numba's user-wide cache, ``$XDG_CACHE_HOME/numba`` (``~/.cache/numba``), when writable;
4. else (read-only install and read-only home) a directory under the system temporary directory,
   ``<tmp>/sandwich-numba-cache-<uid>``, set as ``NUMBA_CACHE_DIR`` before numba is imported.

:func:`cache_directory` says which one applies. ``import numba`` is deferred to the first call
that needs the JIT, so code paths that never do (no kernel evaluated, or every call covered by the
ahead-of-time build below) do not pay it.

**Ahead-of-time build.** Loading numba and its cached kernels costs ≈ 0.5-0.6 s per process
(``import numba``, its target initialisation, each kernel's cache entry; docs/speed.md),
more than a whole small scene's path. ``make setup`` therefore also compiles every kernel, for the
argument types a representative workload meets, into one extension module with numba's AOT
compiler (``scripts/build_kernels.py`` → ``sandwich/solver/_kernels_aot*.so`` and its manifest
``_kernels_aot.json``). :func:`njit` returns a :class:`Kernel`: a call whose arguments match an
exported signature exactly (array dtype, dimensions, layout, writeability; scalar types) runs the
AOT function, without importing numba; any other call, or every call when the build is missing,
stale (a kernel source file changed), made for another CPU, Python or numpy (``make setup``
also rebuilds it for another numba), or disabled by ``SANDWICH_KERNELS=jit``, runs numba's JIT as
before. Both are the same LLVM code from the same
source and flags (the exported wrappers call the JIT-flagged functions); the tests compare them
bit for bit. :func:`kernel_backend` says which applies and why.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import platform
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["Kernel", "aot_exports", "argument_matcher", "cache_directory", "kernel_backend",
           "kernels", "njit", "writable"]

_HERE = Path(__file__).resolve()
# the kernels' source dirs
_SOURCE_DIRS = (_HERE.parent, _HERE.parent / "envelope", _HERE.parents[1] / "beam")


def writable(path: Path) -> bool:
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
    if all(writable(d / "__pycache__") for d in source_dirs):
        return "in-tree", None
    user = _user_cache()
    if writable(user):
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
    """A compiled kernel (:class:`Kernel`): numba ``njit(cache=True)``, IEEE arithmetic.

    ``reassociate=True`` lets LLVM reorder sums (fastmath flags ``reassoc`` and ``contract``
    only: NaN and infinity keep their meaning), which vectorises dot-product loops; the result
    is then rounded differently from the loop as written, but reproducibly so.
    """
    if fn is None:
        return lambda f: njit(f, reassociate=reassociate)
    if not _numba_installed():  # as numba.njit would: the callers fall back to NumPy/SuperLU
        raise ImportError("numba is not installed")
    return Kernel(fn, reassociate)


@functools.cache
def _numba_installed() -> bool:
    from importlib.util import find_spec

    return find_spec("numba") is not None


_KERNELS: list[Kernel] = []


def kernels() -> list[Kernel]:
    """Every kernel defined so far (those of the modules imported)."""
    return list(_KERNELS)


class Kernel:
    """A numba kernel, run ahead-of-time compiled where the build has the call's signature.

    Calls from Python: the AOT function whose exported signature the arguments match exactly,
    else :attr:`jit`. Calls from other kernels (compiled code) always bind to :attr:`jit`'s
    dispatcher (``_numba_type_``), so the AOT build links the same functions as the JIT.
    """

    def __init__(self, fn: Callable, reassociate: bool, *, register: bool = True) -> None:
        """Wrap ``fn``; ``register``: list it in :func:`kernels` (what the AOT build compiles)."""
        self.py_func = fn
        self.reassociate = reassociate
        self.key = f"{fn.__module__}.{fn.__qualname__}"
        self._jit = None
        self._aot: tuple | None = None
        functools.update_wrapper(self, fn)
        if register:
            _KERNELS.append(self)

    @property
    def jit(self) -> Callable:
        """Numba's dispatcher (built, and numba imported, on first use)."""
        if self._jit is None:
            _configure()
            import numba

            flags = {"reassoc", "contract"} if self.reassociate else False
            # error_model "numpy": a division by zero gives inf/NaN (checked by the callers),
            # not an exception from inside the loop
            self._jit = numba.njit(cache=True, nogil=True, fastmath=flags,
                                   error_model="numpy")(self.py_func)
        return self._jit

    @property
    def _numba_type_(self) -> object:  # what numba sees when a kernel calls this one
        return self.jit._numba_type_

    def __call__(self, *args: object) -> object:
        """Run the kernel: the AOT function exported for exactly these types, else the JIT."""
        aot = self._aot
        if aot is None:  # this kernel's matchers, made on its first call (not every export's)
            aot = self._aot = _own_exports(self.key)
        for matches, fn in aot:
            if matches(args):
                return fn(*args)
        return self.jit(*args)

    def __repr__(self) -> str:
        return f"<Kernel {self.key}>"


# --- the ahead-of-time build ---------------------------------------------------------------

AOT_MODULE = "sandwich.solver._kernels_aot"
AOT_MANIFEST = _HERE.parent / "_kernels_aot.json"
ROOT = _HERE.parents[2]  # the kernel sources' paths in the manifest are relative to this
_backend = {"backend": "jit", "reason": "not loaded yet"}


def machine_key() -> dict[str, str]:
    """What an AOT build depends on besides the sources and numba: CPU, Python, numpy.

    ``cpu`` is empty where ``/proc/cpuinfo`` cannot be read; no build is used there
    (:func:`manifest_mismatch`): machine code for another CPU would not fail cleanly.
    """
    cpu = ""
    try:
        with open("/proc/cpuinfo") as fh:
            seen = set()
            for line in fh:
                k = line.split(":", 1)[0].strip()
                if k in ("model name", "flags") and k not in seen:
                    seen.add(k)
                    cpu += line
                if len(seen) == 2:
                    break
    except OSError:
        cpu = ""
    import numpy

    return {"cpu": hashlib.sha256(cpu.encode()).hexdigest() if cpu else "",
            "machine": platform.machine(), "python": sys.version.split()[0],
            "numpy": numpy.__version__}


def source_digest(paths: list[str]) -> str:
    """sha256 over the kernel source files (paths relative to the project root)."""
    h = hashlib.sha256()
    for rel in paths:
        h.update(rel.encode())
        h.update((ROOT / rel).read_bytes())
    return h.hexdigest()


def manifest_mismatch(manifest: dict) -> str:
    """Why the build described by ``manifest`` must not be used here ("" if it may)."""
    here = machine_key()
    if not here["cpu"]:
        return "this machine's CPU cannot be identified (no /proc/cpuinfo)"
    if manifest.get("machine") != here:
        return "the ahead-of-time build is for another machine or Python/numpy"
    if not all((ROOT / rel).is_file() for rel in manifest.get("files", ())):
        return "a kernel source of the ahead-of-time build is no longer there"
    if manifest.get("sources") != source_digest(manifest["files"]):
        return "a kernel source changed since the ahead-of-time build"
    return ""


def kernel_backend() -> dict[str, str]:
    """``{"backend": "aot" | "jit", "reason": ...}``: whether the AOT build is used, or why not."""
    aot_exports()
    return dict(_backend)


@functools.cache
def aot_exports() -> dict[str, tuple]:
    """Kernel key → ((exported types, AOT function), ...) from a valid build, else {}.

    A :class:`Kernel` makes the matchers of its own exports (:func:`argument_matcher`) on its first
    call: a run builds only those of the kernels it calls (fig. 5 at the paper's core: ≈ 7 ms
    of its solve for all 36 exports, made on the first evaluation).
    """
    def off(reason: str) -> dict:
        _backend.update(backend="jit", reason=reason)
        return {}

    if os.environ.get("SANDWICH_KERNELS", "").lower() == "jit":
        return off("SANDWICH_KERNELS=jit")
    try:
        manifest = json.loads(AOT_MANIFEST.read_text())
    except (OSError, ValueError):
        return off("no ahead-of-time build (make setup builds it)")
    try:
        mismatch = manifest_mismatch(manifest)
        if mismatch:
            return off(mismatch)
        if AOT_MODULE != "sandwich.solver._kernels_aot":
            raise ImportError(f"no module {AOT_MODULE}")  # (tests point it elsewhere)
        from sandwich.solver import _kernels_aot as module  # built by make setup
        out = {key: tuple((spec, getattr(module, name)) for name, spec in entries)
               for key, entries in manifest["exports"].items()}
    except Exception as exc:  # a broken build must never stop a run: the JIT is always there
        return off(f"the ahead-of-time build did not load ({type(exc).__name__}: {exc})")
    _backend.update(backend="aot", reason=f"{sum(map(len, out.values()))} exported signatures")
    return out


def _own_exports(key: str) -> tuple:
    """((argument matcher, AOT function), ...) of kernel ``key``; () sends it to the JIT.

    A manifest entry whose types cannot be read (a broken or foreign build) must not stop a
    run, as a build that does not load does not (:func:`aot_exports`): that kernel runs under
    the JIT.
    """
    try:
        return tuple((argument_matcher(spec), fn) for spec, fn in aot_exports().get(key, ()))
    except Exception:  # any malformed entry: the JIT is always there
        return ()


def argument_matcher(spec: list[list]) -> Callable[[tuple], bool]:
    """A function telling whether call arguments have exactly the exported types ``spec``.

    Each entry: ``["array", dtype, ndim, layout, writeable]`` or ``["float"]``, ``["int"]``,
    ``["bool"]``. An AOT function does not check its arguments (a wrong dtype is a crash), so
    nothing else is accepted.
    """
    import numpy as np

    env = {"nd": np.ndarray, "f8": (float, np.float64), "i8": (int, np.int64),
           "b1": (bool, np.bool_)}
    lines = [f"def matches(args):\n    if len(args) != {len(spec)}:\n        return False"]
    for i, s in enumerate(spec):
        a = f"args[{i}]"
        if s[0] == "array":
            _, dtype, ndim, layout, writeable = s
            env[f"d{i}"] = np.dtype(dtype)
            flags = [{"C": "c_contiguous", "F": "f_contiguous"}.get(layout), "aligned",
                     "writeable" if writeable else None]
            lines += [f"    a = {a}",
                      f"    if type(a) is not nd or a.ndim != {ndim}:\n        return False",
                      f"    t = a.dtype\n    if t is not d{i} and t != d{i}:\n        return False",
                      "    f = a.flags",  # one flags object per array (each access makes one)
                      f"    if not ({' and '.join(f'f.{x}' for x in flags if x)}):\n"
                      "        return False"]
        else:
            kind = {"float": "f8", "int": "i8", "bool": "b1"}[s[0]]
            lines.append(f"    if type({a}) not in {kind}:\n        return False")
    lines.append("    return True")
    exec("\n".join(lines), env)  # noqa: S102 - generated from the manifest's type specs
    return env["matches"]
