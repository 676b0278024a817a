"""2D spot checks of a beam study: which cases, and the beam-vs-2D error there.

:func:`select_checks` picks ``check = N`` cases: ⌈N/2⌉ where the beam's own error indicator is
largest (:func:`sandwich.studies.study_case.linear_indicator`, or the ``"auto"`` core's estimate),
then
the corners of the map (every axis at its first or last value), then more by the indicator if
the corners run out. Failed cases are never picked. :func:`check_errors` compares the beam's
numbers with the 2D model's on the same scene: (beam − 2D) / |2D|.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

from sandwich.studies.study_file import Study

COMPARED = ("capacity", "first_limit_load", "load_at_until", "initial_stiffness",
            "peak_sigma_zz_5mm", "peak_tau_core_5mm")


def corners(study: Study) -> list[int]:
    """Indices of the cases at the corners of the grid (each axis at its first or last value)."""
    ends = [sorted({0, len(a.values) - 1}) for a in study.axes]
    by_pos = {}
    sizes = [len(a.values) for a in study.axes]
    for combo in itertools.product(*ends):
        index = 0
        for pos, n in zip(combo, sizes, strict=True):
            index = index * n + pos
        by_pos[combo] = index
    present = {c.index for c in study.cases}
    return [i for i in by_pos.values() if i in present]


def select_checks(study: Study, records: dict[int, dict[str, Any]], n: int) -> list[int]:
    """The case indices to check with the 2D model (see the module docstring), at most ``n``.

    ``check = "all"`` (``study.check_all``): every case, whatever the beam did.
    """
    if study.check_all:
        return [c.index for c in study.cases]
    ok = {i for i, r in records.items() if r.get("status") in ("done", "stopped")}

    def indicator(i: int) -> float:
        v = records[i].get("indicator")
        return float(v) if isinstance(v, int | float) and math.isfinite(v) else -1.0

    ranked = sorted((i for i in ok if indicator(i) >= 0), key=lambda i: (-indicator(i), i))
    chosen: list[int] = []
    for i in ranked[: (n + 1) // 2]:
        chosen.append(i)
    for i in corners(study):
        if len(chosen) >= n:
            break
        if i in ok and i not in chosen:
            chosen.append(i)
    for i in ranked + sorted(ok):
        if len(chosen) >= n:
            break
        if i not in chosen:
            chosen.append(i)
    return chosen


def check_errors(beam: dict[str, Any], ref: dict[str, Any]) -> dict[str, Any]:
    """``error_<quantity>`` = (beam − 2D) / |2D| for each compared quantity (None if missing)."""
    out: dict[str, Any] = {}
    for q in COMPARED:
        b, r = beam.get(q), ref.get(q)
        ok = isinstance(b, int | float) and isinstance(r, int | float) and r not in (0, 0.0)
        out[f"error_{q}"] = (float(b) - float(r)) / abs(float(r)) if ok else None
        out[f"2d_{q}"] = r if isinstance(r, int | float) else None
    out["2d_core_crushed_load"] = ref.get("core_crushed_load")
    out["2d_status"] = ref.get("status", "")
    out["2d_reason"] = ref.get("reason", "")
    out["2d_seconds"] = ref.get("wall_seconds")
    return out
