"""Read a result folder (``history.csv``, ``profiles.csv``, ``summary.json``, field frames) back.

This is the inverse of :func:`sandwich.results.writing.write_solution`: whatever a model wrote
is read back into the same typed :class:`~sandwich.results.types.Solution` it would have
returned in memory, field frames (``fields.pvd`` + VTU) included.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from sandwich.results.types import (
    PROFILE_COLUMNS,
    FieldFrame,
    LimitPoint,
    Profile,
    Solution,
    StepRecord,
)
from sandwich.results.vtu import read_pvd, read_vtu

RESULT_FILES = ("history.csv", "profiles.csv", "summary.json")
FIELDS_COLLECTION = "fields.pvd"
_SUMMARY_KEYS = {"model", "scene", "converged", "message", "steps", "final_load_factor",
                 "limit_points", "wall_seconds", "dofs", "warnings"}


class ResultMissing(FileNotFoundError):
    """A result folder that lacks one of the three result files."""


def _float(value: object) -> float:
    """A number from JSON/CSV; ``None`` or an empty cell becomes NaN in memory (never written)."""
    if value is None or value == "":
        return math.nan
    return float(value)  # type: ignore[arg-type]


def _read_history(path: Path) -> list[StepRecord]:
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise ValueError(f"{path}: empty file, expected a header row")
    header = rows[0]
    for needed in ("step", "load_factor", "iterations"):
        if needed not in header:
            raise ValueError(f"{path}: no '{needed}' column in header {header}")
    i_lf, i_it = header.index("load_factor"), header.index("iterations")
    probe_cols = header[i_lf + 1:i_it]
    extra_cols = header[i_it + 1:]
    records = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ValueError(f"{path}:{line}: {len(row)} cells, header has {len(header)}")
        records.append(StepRecord(
            step=int(row[0]),
            load_factor=float(row[i_lf]),
            probes={name: float(row[i_lf + 1 + k]) for k, name in enumerate(probe_cols)},
            iterations=int(row[i_it]),
            extra={name: (None if row[i_it + 1 + k] == "" else float(row[i_it + 1 + k]))
                   for k, name in enumerate(extra_cols)},  # empty: a G not evaluated
        ))
    return records


def _read_profiles(path: Path) -> list[Profile]:
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise ValueError(f"{path}: empty file, expected a header row")
    header = rows[0]
    if header[0] != "step" or not set(PROFILE_COLUMNS) <= set(header):
        raise ValueError(f"{path}: header {header} lacks step or one of {PROFILE_COLUMNS}")
    by_step: dict[int, list[list[str]]] = {}
    for row in rows[1:]:
        by_step.setdefault(int(row[0]), []).append(row)
    profiles = []
    for step, block in by_step.items():
        columns: dict[str, np.ndarray] = {}
        for j, name in enumerate(header[1:], start=1):
            cells = [r[j] for r in block]
            if all(c == "" for c in cells):
                continue  # this step has no such column
            columns[name] = np.array([_float(c) for c in cells])
        profiles.append(Profile(step=step, columns=columns))
    return profiles


def load_result(folder: str | Path, *, fields: bool = True) -> Solution:
    """Read the result files in ``folder`` into a :class:`~sandwich.results.Solution`.

    Parameters
    ----------
    folder
        A folder written by :func:`sandwich.results.write_solution`.
    fields
        Also read the field frames (``fields.pvd`` and its VTU files) when there are any.

    Returns
    -------
    Solution
        The solution as the model returned it (in-memory ``extra`` keys that were written into
        ``summary.json`` come back in ``extra``).

    Raises
    ------
    ResultMissing
        If one of ``history.csv``, ``profiles.csv``, ``summary.json`` is absent.
    ValueError
        If a file is malformed (the message names the file and line).
    """
    folder = Path(folder)
    absent = [n for n in RESULT_FILES if not (folder / n).is_file()]
    if absent:
        raise ResultMissing(f"{folder}: no {', '.join(absent)} (model not run here, or its run "
                            "did not finish)")
    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    limit_points = [
        LimitPoint(kind=lp["kind"], step=int(lp["step"]), load_factor=_float(lp["load_factor"]),
                   probes={k: _float(v) for k, v in lp.get("probes", {}).items()},
                   between=(tuple(_float(v) for v in lp["between_load_factors"])
                            if "between_load_factors" in lp else None),
                   located_at=(_float(lp["located_at_step_fraction"])
                               if "located_at_step_fraction" in lp else None))
        for lp in summary.get("limit_points", [])
    ]
    return Solution(
        model=str(summary.get("model", "")),
        scene=str(summary.get("scene", "")),
        history=_read_history(folder / "history.csv"),
        profiles=_read_profiles(folder / "profiles.csv"),
        converged=bool(summary.get("converged", False)),
        message=str(summary.get("message", "")),
        limit_points=limit_points,
        wall_seconds=_float(summary.get("wall_seconds")),
        dofs=int(summary.get("dofs", 0) or 0),
        extra={k: v for k, v in summary.items() if k not in _SUMMARY_KEYS},
        fields=read_field_frames(folder) if fields else [],
        warnings=[str(w) for w in summary.get("warnings", [])],
    )


def read_field_frames(folder: str | Path) -> list[FieldFrame]:
    """The field frames of a result folder (``fields.pvd`` + VTU), ``[]`` when it has none.

    The step comes from the file name ``fields_NNNNN.vtu``, the load factor from the
    collection's time value; ``displacement`` is taken out of the point data.
    """
    pvd = Path(folder) / FIELDS_COLLECTION
    if not pvd.is_file():
        return []
    frames = []
    for load_factor, name in read_pvd(pvd):
        points, cells, point_data, cell_data = read_vtu(pvd.parent / name)
        if "displacement" not in point_data:
            raise ValueError(f"{pvd.parent / name}: no displacement point data")
        disp = point_data.pop("displacement")[:, :2]
        step = int(Path(name).stem.rsplit("_", 1)[-1])
        frames.append(FieldFrame(step, load_factor, points[:, :2], cells, disp,
                                 point_data, cell_data))
    return frames
