"""Where along a path a tip's G first reaches its Benzeggagh–Kenane toughness.

A path's history holds, per converged state and tip, G, G_I and G_II (N/mm, the model's
virtual crack closure). The criterion is r = √(G / G_c(ψ)) ≥ 1, G_c(ψ) = GIc + (GIIc − GIc)
ψ^eta with ψ = G_II / G (:func:`sandwich.fracture.bk_toughness`). Between the last state with
r < 1 and the first with r ≥ 1 the crossing is placed where r, interpolated linearly along the
step, is 1: r is linear in the load wherever the response is (G ∝ λ² at a fixed mode mix), so
the interpolation is exact in a linear analysis; elsewhere its error is second order in the
step. Every probe and the mode mix ψ are interpolated at the same fraction of the step; G there
is G_c(ψ) (r = 1), split into G_I = (1 − ψ) G and G_II = ψ G.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sandwich.fracture import bk_toughness
from sandwich.results import StepRecord
from sandwich.results.fracture import column_names
from sandwich.scene import Toughness


@dataclass(frozen=True)
class Crossing:
    """The state on a path where a tip's G reaches G_c (interpolated between two states).

    ``index`` is the position in the history of the last state before it, ``fraction`` how far
    along the step to the next one it lies; ``peak_load`` is the largest load factor on the path
    up to it (above ``load_factor`` when the path passed a load maximum first).
    """

    debond: int
    tip: str
    index: int
    fraction: float
    load_factor: float
    probes: dict[str, float]
    G: float
    GI: float
    GII: float
    Gc: float
    peak_load: float
    bracket: tuple[float, float]  # the load factors of the two states around it

    @property
    def position(self) -> float:
        """Where along the path it lies, in states (index + fraction): earlier is smaller."""
        return self.index + self.fraction


def criterion_ratio(toughness: Toughness, record: StepRecord, debond: int,
                    tip: str) -> float | None:
    """The ratio r = √(G / G_c) of one tip at one state; ``None`` where it carries no G."""
    values = [record.extra.get(n) for n in column_names(debond, tip)]
    if any(v is None for v in values):
        return None
    g, gi, gii = (float(v) for v in values)
    return math.sqrt(max(g, 0.0) / bk_toughness(toughness, gi, gii))


def first_crossing(toughness: Toughness, history: list[StepRecord], debond: int,
                   tip: str) -> Crossing | None:
    """The first place on ``history`` where the tip's r reaches 1; ``None`` if it never does."""
    names = column_names(debond, tip)
    before: tuple[int, float] | None = None  # (index, r) of the last state with r < 1
    peak = -math.inf
    for j, rec in enumerate(history):
        r = criterion_ratio(toughness, rec, debond, tip)
        if r is None:
            before = None  # no G here: a crossing cannot be placed across it
            peak = max(peak, rec.load_factor)
            continue
        if r >= 1.0:
            if before is None:
                t, i = 1.0, max(j - 1, 0)  # already above at its first evaluated state
            else:
                i, r0 = before
                t = (1.0 - r0) / (r - r0)
            a, b = history[i], rec
            lam = a.load_factor + t * (b.load_factor - a.load_factor)
            psi = _between(_mix(a, names), _mix(b, names), t)
            gc = bk_toughness(toughness, 1.0 - psi, psi)  # G = G_c(ψ) there: r = 1
            probes = {k: _between(a.probes.get(k), v, t) for k, v in b.probes.items()}
            return Crossing(debond, tip, i, t, lam, probes, gc, (1.0 - psi) * gc, psi * gc, gc,
                            max(peak, lam), (a.load_factor, b.load_factor))
        before = (j, r)
        peak = max(peak, rec.load_factor)
    return None


def _mix(record: StepRecord, names: tuple[str, str, str]) -> float | None:
    """ψ = G_II / G of a state (``None`` where it carries no G or G = 0: no mix there)."""
    g, gii = record.extra.get(names[0]), record.extra.get(names[2])
    if g is None or gii is None or float(g) <= 0.0:
        return None
    return min(max(float(gii) / float(g), 0.0), 1.0)


def _between(a: float | None, b: float, t: float) -> float:
    """The value a + t (b − a), or b where a is missing."""
    return float(b) if a is None else float(a) + t * (float(b) - float(a))
