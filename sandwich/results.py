"""Typed results every model returns, and their writers (the result-file contract).

A solve writes, atomically, into its folder:

- ``history.csv``: one row per converged step,
  ``step, load_factor, <one column per probe (mm)>, iterations[, more columns]``;
- ``profiles.csv``: ``step, x, w_top, w_bottom, sigma_zz_top, sigma_zz_bottom, tau_core[, more]``
  (interface normal stress at the core's top and bottom boundary, core shear at mid-core, MPa);
- ``summary.json``: ``model, scene, converged, steps, final_load_factor, limit_points,
  wall_seconds, dofs`` and more;
- ``fields.pvd`` + ``fields_NNNNN.vtu`` when the model returns 2D field frames (ParaView).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

PROFILE_COLUMNS = ("x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom", "tau_core")


@dataclass
class StepRecord:
    """One converged equilibrium state on the path."""

    step: int
    load_factor: float
    probes: dict[str, float]
    iterations: int
    extra: dict[str, float] = field(default_factory=dict)


@dataclass
class Profile:
    """Fields sampled along the beam axis at one converged step (mm, MPa).

    ``columns`` holds at least the names of ``PROFILE_COLUMNS`` (each an array over ``x``);
    models may add more (``p_contact_top``, ``u_top`` ...).
    """

    step: int
    columns: dict[str, np.ndarray]


@dataclass
class LimitPoint:
    """An extremum of the load factor along the path, or a bifurcation (tangent inertia change)."""

    kind: str  # "max" | "min" | "bifurcation"
    step: int
    load_factor: float
    probes: dict[str, float]


@dataclass
class FieldFrame:
    """Fields of one converged step on a 2D grid of the beam, for ParaView.

    ``points`` are reference coordinates (x, z) in mm, ``cells`` counter-clockwise quads (m, 4) or
    triangles (m, 3); ``displacement`` (n, 2) in mm; stresses in MPa as point or cell data.
    """

    step: int
    load_factor: float
    points: np.ndarray
    cells: np.ndarray
    displacement: np.ndarray
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)


@dataclass
class Solution:
    """What a solve returns: the equilibrium path, profiles and a summary."""

    model: str
    scene: str
    history: list[StepRecord]
    profiles: list[Profile]
    converged: bool
    message: str
    limit_points: list[LimitPoint]
    wall_seconds: float
    dofs: int
    extra: dict[str, object] = field(default_factory=dict)
    fields: list[FieldFrame] = field(default_factory=list)

    @property
    def final_load_factor(self) -> float:
        """Load factor of the last converged step (0 when none converged)."""
        return self.history[-1].load_factor if self.history else 0.0


def _finite(value: float) -> float | None:
    """Map a non-finite float to ``None`` so that no NaN is ever written."""
    return float(value) if math.isfinite(value) else None


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
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


def history_csv(solution: Solution) -> str:
    """Render ``history.csv``."""
    probe_names = list(solution.history[0].probes) if solution.history else []
    extra_names = sorted({k for r in solution.history for k in r.extra})
    header = ["step", "load_factor", *probe_names, "iterations", *extra_names]
    rows = [
        [r.step, _cell(r.load_factor), *(_cell(r.probes[n]) for n in probe_names), r.iterations,
         *(_cell(r.extra.get(n, 0.0)) for n in extra_names)]
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
        "steps": len(solution.history),
        "final_load_factor": _finite(solution.final_load_factor),
        "limit_points": [
            {"kind": lp.kind, "step": lp.step, "load_factor": _finite(lp.load_factor),
             "probes": {k: _finite(v) for k, v in lp.probes.items()}}
            for lp in solution.limit_points
        ],
        "wall_seconds": _finite(solution.wall_seconds),
        "dofs": solution.dofs,
    }
    for k, v in solution.extra.items():
        out[k] = _finite(v) if isinstance(v, float) else v
    return out


def write_solution(solution: Solution, out_dir: Path) -> list[Path]:
    """Write the three result files of ``solution`` into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    files = {
        "history.csv": history_csv(solution),
        "profiles.csv": profiles_csv(solution),
        "summary.json": json.dumps(summary_dict(solution), indent=2, allow_nan=False) + "\n",
    }
    if solution.fields:
        files.update(_field_files(solution.fields))
    paths = []
    for name, text in files.items():
        atomic_write_text(out_dir / name, text)
        paths.append(out_dir / name)
    return paths


def _field_files(frames: list[FieldFrame]) -> dict[str, str]:
    """VTU per frame plus a ``fields.pvd`` collection (time = load factor)."""
    from sandwich.vtu import pvd_text, vtu_text

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
