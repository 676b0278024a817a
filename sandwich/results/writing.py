"""Writers of the result-file contract.

A solve writes, as one set (:func:`write_solution`), into its folder:

- ``history.csv``: one row per converged step,
  ``step, load_factor, <one column per probe (mm)>, iterations[, more columns]``;
- ``profiles.csv``: ``step, x, w_top, w_bottom, sigma_zz_top, sigma_zz_bottom, tau_core[, more]``
  (interface normal stress at the core's top and bottom boundary, core shear at mid-core, MPa);
- ``summary.json``: ``model, scene, converged, steps, final_load_factor, limit_points``
  (``kind, step, load_factor, probes``, ``between_load_factors``: the states that enclose
  the point, and for a point located within its step ``located_at_step_fraction``),
  ``wall_seconds, dofs`` and more;
- ``fields.pvd`` + ``fields_NNNNN.vtu`` when the model returns 2D field frames (ParaView);
- ``tip_tractions.csv`` when the scene (given) has debond tips: σzz and τ of the interface
  around each tip at every profile step (:mod:`sandwich.results.tractions`).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from sandwich.results.fracture import is_release_column
from sandwich.results.tractions import scene_tips, tip_tractions_csv
from sandwich.results.types import PROFILE_COLUMNS, FieldFrame, Solution
from sandwich.results.vtu import pvd_text, vtu_text

NAME_MAX = 255  # bytes of one file or folder name (Linux file systems)
RESULT_SET_NAMES = frozenset({"history.csv", "profiles.csv", "summary.json", "fields.pvd",
                              "tip_tractions.csv"})


def _finite(value: float) -> float | None:
    """Map a non-finite float to ``None`` so that no NaN is ever written."""
    return float(value) if math.isfinite(value) else None


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())  # as a plain open() would (mkstemp makes 0600)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _csv_text(header: list[str], rows: list[list[object]]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buf.getvalue()


def _cell(value: object) -> object:
    if isinstance(value, float | np.floating):
        v = float(value)
        if not math.isfinite(v):
            raise ValueError("refusing to write a non-finite value into a result file")
        return repr(v)
    return value


def _extra_cell(extra: dict, name: str) -> object:
    """A history cell: empty for a G column without a value (not evaluated), else 0 if absent."""
    value = extra.get(name)
    if value is None:
        return "" if is_release_column(name) else _cell(0.0)
    return _cell(value)


def history_csv(solution: Solution, probe_names: Sequence[str] = ()) -> str:
    """Render ``history.csv``; ``probe_names`` head its columns when no step converged."""
    probe_names = list(solution.history[0].probes) if solution.history else list(probe_names)
    extra_names = sorted({k for r in solution.history for k in r.extra})
    header = ["step", "load_factor", *probe_names, "iterations", *extra_names]
    rows = [
        [r.step, _cell(r.load_factor), *(_cell(r.probes[n]) for n in probe_names), r.iterations,
         *(_extra_cell(r.extra, n) for n in extra_names)]
        for r in solution.history
    ]
    return _csv_text(header, rows)


def profiles_csv(solution: Solution) -> str:
    """Render ``profiles.csv`` (long format: one row per step and station)."""
    if not solution.profiles:
        return _csv_text(["step", *PROFILE_COLUMNS], [])
    names = list(PROFILE_COLUMNS) + sorted(
        {k for p in solution.profiles for k in p.columns} - set(PROFILE_COLUMNS)
    )
    rows: list[list[object]] = []
    for p in solution.profiles:
        n = len(p.columns["x"])
        for i in range(n):
            rows.append([p.step, *(_cell(float(p.columns[c][i])) if c in p.columns else ""
                                   for c in names)])
    return _csv_text(["step", *names], rows)


def summary_dict(solution: Solution) -> dict[str, object]:
    """Build the ``summary.json`` content."""
    out: dict[str, object] = {
        "model": solution.model,
        "scene": solution.scene,
        "converged": solution.converged,
        "message": solution.message,
        "warnings": list(solution.warnings),
        "steps": len(solution.history),
        "final_load_factor": _finite(solution.final_load_factor),
        "limit_points": [
            {"kind": lp.kind, "step": lp.step, "load_factor": _finite(lp.load_factor),
             "probes": {k: _finite(v) for k, v in lp.probes.items()},
             **({"between_load_factors": [_finite(v) for v in lp.between]}
                if lp.between is not None else {}),
             **({"located_at_step_fraction": _finite(lp.located_at)}
                if lp.located_at is not None else {})}
            for lp in solution.limit_points
        ],
        "wall_seconds": _finite(solution.wall_seconds),
        "dofs": solution.dofs,
    }
    for k, v in solution.extra.items():
        out[k] = _finite(v) if isinstance(v, float) else v
    return out


def result_texts(solution: Solution, scene: object | None = None) -> dict[str, str]:
    """Every file of ``solution``'s result set, by name (refuses non-finite values first).

    With ``scene``, also ``tip_tractions.csv`` when the scene has debond tips
    (:mod:`sandwich.results.tractions`).
    """
    files = {
        "history.csv": history_csv(solution, [p.name for p in getattr(scene, "probes", ())]),
        "profiles.csv": profiles_csv(solution),
        "summary.json": json.dumps(summary_dict(solution), indent=2, allow_nan=False) + "\n",
    }
    if solution.fields:
        files.update(_field_files(solution.fields))
    if scene is not None and scene_tips(scene):
        files["tip_tractions.csv"] = tip_tractions_csv(scene, solution.profiles)
    return files


def is_result_file(name: str) -> bool:
    """Whether ``name`` is one a result set may hold (so a rerun may replace it)."""
    return name in RESULT_SET_NAMES or bool(re.fullmatch(r"fields_\d+\.vtu", name))


def write_solution(solution: Solution, out_dir: Path, scene: object | None = None) -> list[Path]:
    """Write the result set of ``solution`` into ``out_dir`` as a whole; return its paths.

    The files are written into a temporary sibling folder which then takes the place of
    ``out_dir``: a reader sees the old set or the new one, never a mix (an older run's VTU
    frames do not survive a rerun). A folder that holds files other than result files (a user's
    folder given as ``--out``) keeps them: the result files are then replaced one by one, and
    result files of the old set that the new one lacks are removed.

    Raises
    ------
    ValueError
        If a value is not finite (nothing is written then).
    OutputError
        If ``out_dir`` cannot be a result folder (see :func:`check_output_folder`).
    """
    out_dir = Path(out_dir)
    files = result_texts(solution, scene)
    check_output_folder(out_dir)
    out_dir = Path(os.path.abspath(out_dir))
    foreign = out_dir.is_dir() and any(not is_result_file(f.name) and not f.name.startswith(".")
                                       for f in out_dir.iterdir())
    if foreign or out_dir == Path(os.getcwd()):  # never swap away the folder we stand in
        for old in out_dir.iterdir():
            if is_result_file(old.name) and old.name not in files:
                old.unlink()
        for name, text in files.items():
            atomic_write_text(out_dir / name, text)
        return [out_dir / n for n in files]
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.new-"))
    try:
        for name, text in files.items():
            _write_file(tmp / name, text)
        if out_dir.exists():
            old = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.old-"))
            os.replace(out_dir, old / out_dir.name)
            os.replace(tmp, out_dir)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, out_dir)
        os.chmod(out_dir, 0o777 & ~_umask())
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return [out_dir / n for n in files]


class OutputError(OSError):
    """A result folder that cannot be written: where and why."""


def check_output_folder(folder: Path) -> None:
    """Refuse, before any work, a folder that cannot take a result set.

    Raises :class:`OutputError` when ``folder`` (or its nearest existing parent) is a file, or
    is not writable, or when its name cannot be a folder (a NUL character, a name longer than
    :data:`NAME_MAX` bytes).
    """
    folder = Path(folder)
    if "\0" in str(folder):  # the system cannot take it (Python raises ValueError)
        shown = str(folder).replace("\0", "\\0")
        raise OutputError(f"{shown}: cannot name a folder (a NUL character)")
    try:
        if folder.exists() and not folder.is_dir():
            raise OutputError(f"{folder}: exists and is not a folder")
        probe = folder
        while not probe.exists():
            if probe.parent == probe:
                break
            probe = probe.parent
    except OSError as exc:  # a name too long, a symlink loop, an I/O error
        raise OutputError(f"{folder}: cannot be used as a folder ({exc.strerror or exc})"
                          ) from None
    if not probe.is_dir():
        raise OutputError(f"{folder}: {probe} is not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"{folder}: {probe} is not writable")
    for part in folder.parts:  # a name the folder's file system would refuse when writing
        if len(os.fsencode(part)) > NAME_MAX:
            raise OutputError(f"{folder}: a name of {len(os.fsencode(part))} bytes is longer "
                              f"than the {NAME_MAX} a folder name may have")


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _write_file(path: Path, text: str) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        fh.write(text)


def _field_files(frames: list[FieldFrame]) -> dict[str, str]:
    """VTU per frame plus a ``fields.pvd`` collection (time = load factor)."""
    out: dict[str, str] = {}
    entries = []
    for frame in frames:
        arrays = [frame.displacement, *frame.point_data.values(), *frame.cell_data.values()]
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise ValueError("refusing to write a non-finite value into a field file")
        name = f"fields_{frame.step:05d}.vtu"
        out[name] = vtu_text(frame.points, frame.cells,
                             {"displacement": frame.displacement, **frame.point_data},
                             frame.cell_data)
        entries.append((frame.load_factor, name))
    out["fields.pvd"] = pvd_text(entries)
    return out
