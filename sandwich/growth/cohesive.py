"""What a path with cohesive tips says of the growth: first growth, residual strength, arrest.

A debond grown by a cohesive law (``growth = { method = "cohesive", … }``) grows along the one
path: the model writes, per converged state, each tip's position ``tip_<debond>_<tip>`` (mm;
where the interface is fully debonded up to) and the length of its process zone
``process_zone_<debond>_<tip>`` (mm; damaged but still carrying traction). This module reads
them (any model that writes them).
"""

from __future__ import annotations

import numpy as np

from sandwich.results import StepRecord
from sandwich.scene import Scene

METHOD = "cohesive law"
MOVED = 1e-9  # mm: a tip that moved less than this has not grown
#: elements a process zone should span for the growth load not to depend on the mesh
PROCESS_ZONE_ELEMENTS = 3


def cohesive_tips(scene: Scene) -> list[tuple[int, str, float, float]]:
    """(debond, tip, origin, far end of its span) of every cohesive tip of ``scene``."""
    return [(s.debond, s.tip, s.origin, s.far) for s in scene.cohesive_spans()]


def cohesive_summary(scene: Scene, rows: list[StepRecord], element: float | None = None
                     ) -> tuple[dict[str, object], list[str]]:
    """The ``debond_growth`` entry of a path with cohesive tips, and the warnings it needs.

    ``first_growth_load``: the load of the first state where a tip has moved; a tip whose
    process zone comes within ``element`` mm (the element length at the span's end; default 0)
    of its span's end has run out of modelled interface (the interface beyond is tied), and
    the path from there on is not the growing debond's: ``residual_strength`` is the largest
    load along the path before that (the load's sign that of the path's first move;
    ``span_end_step`` the first state at a span's end, ``bounded`` whether the load came down
    from its largest before it), with a warning. Per tip its start, its position at the path's
    end and the longest process zone.
    """
    tips = cohesive_tips(scene)
    warnings: list[str] = []
    if not tips or not rows:
        return {}, warnings
    sign = next((1.0 if r.load_factor > 0 else -1.0 for r in rows if r.load_factor != 0), 1.0)
    moved = None
    stop = len(rows)  # rows[:stop]: the growth the spans model
    per_tip = {}
    for debond, tip, origin, far in tips:
        col = f"tip_{debond}_{tip}"
        zone = f"process_zone_{debond}_{tip}"
        towards = 1.0 if far > origin else -1.0
        seen = [(i, r) for i, r in enumerate(rows) if r.extra.get(col) is not None]
        if not seen:
            continue
        first = next((r for _, r in seen if abs(float(r.extra[col]) - origin) > MOVED), None)
        if first is not None and (moved is None or first.step < moved.step):
            moved = first
        end = float(seen[-1][1].extra[col])
        at_end = next((i for i, r in seen if abs(far - float(r.extra[col]) - towards * float(
            r.extra.get(zone) or 0.0)) <= (element or 0.0) + MOVED), None)
        per_tip[f"{debond}_{tip}"] = {
            "from": origin, "to": end, "span_end": far,
            "grew_mm": abs(end - origin),
            "longest_process_zone_mm": max(float(r.extra.get(zone) or 0.0) for _, r in seen),
            "first_growth_step": None if first is None else first.step}
        if at_end is not None:
            stop = min(stop, at_end)
            warnings.append(f"debond {debond} {tip} tip reached the end of its cohesive span at "
                            f"x = {far:g} mm (step {rows[at_end].step}): growth beyond it is not "
                            "modelled (the interface there is tied), and the residual strength "
                            "is the largest load before; a longer growth zone would let it run "
                            "on")
    modelled = rows[:max(stop, 1)]
    peak = max(modelled, key=lambda r: sign * r.load_factor)
    out: dict[str, object] = {
        "method": METHOD,
        "first_growth_load": None if moved is None or moved.step > modelled[-1].step
        else moved.load_factor,
        "first_growth_step": None if moved is None else moved.step,
        "residual_strength": peak.load_factor,
        "residual_strength_step": peak.step,
        "bounded": sign * modelled[-1].load_factor < sign * peak.load_factor,
        "span_end_step": None if stop == len(rows) else rows[stop].step,
        "tips": per_tip,
    }
    return out, warnings


def tip_columns(debond: int, tip: str, origin: float, direction: int, x: np.ndarray,
                broken: np.ndarray, damaged: np.ndarray) -> dict[str, float]:
    """One cohesive tip's history columns, from its nodes' committed damage (any model).

    ``x`` (mm) the nodes of the tip's span, ``broken`` whether each is fully debonded,
    ``damaged`` whether it has any damage. ``tip_<debond>_<tip>``: x of the farthest fully
    debonded node reached from ``origin`` through fully debonded nodes only (``origin`` while
    none is); ``process_zone_<debond>_<tip>``: the length (mm) from there to the farthest
    damaged node.
    """
    order = np.argsort(direction * (x - origin))
    dist = direction * (x[order] - origin)
    reached = np.cumprod(broken[order]).astype(bool)
    reach = float(dist[reached].max()) if reached.any() else 0.0
    hurt = damaged[order]
    far = float(dist[hurt].max()) if hurt.any() else reach
    key = f"{debond}_{tip}"
    return {f"tip_{key}": float(origin + direction * reach),
            f"process_zone_{key}": max(far - reach, 0.0) + 0.0}  # never −0.0


def process_zone_warnings(entry: dict[str, object], element: float, more: str) -> list[str]:
    """Warnings of the tips whose process zone is too short for the mesh.

    A tip whose longest process zone spans fewer than ``PROCESS_ZONE_ELEMENTS`` elements of
    ``element`` mm: the growth load then depends on the mesh. ``entry`` is
    :func:`cohesive_summary`'s; ``more`` says how to get more elements (the model's option).
    """
    out = []
    for key, tip in entry.get("tips", {}).items():
        zone = tip["longest_process_zone_mm"]
        if tip["grew_mm"] > 0 and element > 0 and zone < PROCESS_ZONE_ELEMENTS * element:
            out.append(f"tip {key}: its process zone ({zone:.3g} mm) spans fewer than "
                       f"{PROCESS_ZONE_ELEMENTS} elements of {element:.3g} mm: the growth load "
                       f"depends on the mesh ({more} or a lower sigma_c / tau_c resolve it)")
    return out


def cohesive_growing(scene: Scene) -> bool:
    """Whether a debond of ``scene`` grows by a cohesive law."""
    return any(d.growth is not None and d.growth.cohesive for d in scene.debonds)
