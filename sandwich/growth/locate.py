"""The onset of growth on a path as an equilibrium state, where interpolation is not enough.

:func:`~sandwich.growth.crossing.first_crossing` interpolates r = √(G/G_c) across the step that
crosses 1: exact in a linear analysis, second order in the step otherwise, and poor where G
jumps inside the step (a debonded face that buckles in it). :func:`located` then solves the
path again with the scene's stopping target moved onto the crossing (the ``until`` probe's
value, or the load factor where the scene stops on it), so that the path ends on an
equilibrium there: the path follower hits a target exactly. The target is updated by regula
falsi on r between the two states that bracket 1 until r is within :data:`ONSET_RTOL` of 1
(G within twice that of G_c), at most :data:`MAX_SOLVES` times.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from sandwich.fracture import bk_toughness
from sandwich.growth.crossing import Crossing, criterion_ratio
from sandwich.results import Solution, StepRecord
from sandwich.results.fracture import column_names
from sandwich.scene import Scene

#: r = √(G/G_c) within this of 1 is the onset (G within 0.5 % of G_c, the load within ≈ 0.25 %
#: where G ∝ λ²)
ONSET_RTOL = 2.5e-3
#: A crossing interpolated across a step whose loads differ by less than this (relative to the
#: crossing's load) is kept as interpolated: its error is second order in that step
NARROW_STEP = 0.01
MAX_SOLVES = 8


def needs_solving(scene: Scene, c: Crossing, history: list[StepRecord]) -> bool:
    """Whether the interpolated crossing ``c`` is to be solved for.

    Not in a linear analysis (exact), nor across a step narrower than :data:`NARROW_STEP`, nor
    where the quadratic through the step's states and the one before puts r = 1 within a
    tenth of :data:`ONSET_RTOL` of the linear interpolation (r is straight there in λ).
    """
    if scene.analysis.kind == "linear":
        return False
    width = abs(c.bracket[1] - c.bracket[0])
    if width <= NARROW_STEP * max(abs(c.load_factor), 1e-300):
        return False
    if c.index < 1:
        return True
    t = scene.debonds[c.debond].toughness
    pts = [(history[k].load_factor, criterion_ratio(t, history[k], c.debond, c.tip))
           for k in (c.index - 1, c.index, c.index + 1)]
    if any(r is None for _, r in pts) or not pts[0][0] < pts[1][0] < pts[2][0]:
        return True
    lam, r = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    roots = np.roots(np.polyfit(lam, r - 1.0, 2))
    inside = [x.real for x in roots if abs(x.imag) < 1e-12 and lam[1] <= x.real <= lam[2]]
    if len(inside) != 1:
        return True
    return abs(inside[0] - c.load_factor) > 0.1 * ONSET_RTOL * abs(c.load_factor)


def located(scene: Scene, solve: Callable[..., Solution], c: Crossing,
            history: list[StepRecord], progress: Callable | None = None
            ) -> tuple[Crossing, Solution | None]:
    """The onset as the end state of a path stopped on it, and that path's solution.

    Returns ``(c, None)`` where the path cannot be stopped there (a re-solve that does not
    reach its target) or r does not come within :data:`ONSET_RTOL` of 1.
    """
    name = scene.analysis.until_probe
    quantity = (lambda r: r.probes[name]) if name is not None else (lambda r: r.load_factor)
    t = scene.debonds[c.debond].toughness
    lo, hi = history[c.index], history[c.index + 1]
    q_lo, q_hi = quantity(lo), quantity(hi)
    r_lo = criterion_ratio(t, lo, c.debond, c.tip)
    r_hi = criterion_ratio(t, hi, c.debond, c.tip)
    if None in (r_lo, r_hi) or r_hi == r_lo or q_hi == q_lo:
        return c, None
    side = 0  # Illinois: which end was kept last time (halve its r-distance if kept twice)
    for _ in range(MAX_SOLVES):
        target = q_lo + (1.0 - r_lo) / (r_hi - r_lo) * (q_hi - q_lo)
        analysis = (dataclasses.replace(scene.analysis, until_value=target)
                    if name is not None else
                    dataclasses.replace(scene.analysis, until_load_factor=target))
        solution = solve(dataclasses.replace(scene, analysis=analysis), progress=progress)
        if not solution.converged or not solution.history:
            return c, None
        end = solution.history[-1]
        r = criterion_ratio(t, end, c.debond, c.tip)
        if r is None:
            return c, None
        if abs(r - 1.0) <= ONSET_RTOL:
            return _at(c, solution.history, t), solution
        if r < 1.0:
            q_lo, r_lo = quantity(end), r
            if side == -1:
                r_hi = 1.0 + 0.5 * (r_hi - 1.0)
            side = -1
        else:
            q_hi, r_hi = quantity(end), r
            if side == 1:
                r_lo = 1.0 - 0.5 * (1.0 - r_lo)
            side = 1
    return c, None


def _at(c: Crossing, history: list[StepRecord], toughness) -> Crossing:
    """The crossing at the last state of ``history`` (its G as computed there)."""
    end = history[-1]
    g, gi, gii = (float(end.extra[n]) for n in column_names(c.debond, c.tip))
    before = history[-2].load_factor if len(history) > 1 else end.load_factor
    return dataclasses.replace(c, index=len(history) - 2, fraction=1.0,
                               load_factor=end.load_factor, probes=dict(end.probes), G=g, GI=gi,
                               GII=gii, Gc=bk_toughness(toughness, gi, gii),
                               peak_load=max(r.load_factor for r in history),
                               bracket=(before, end.load_factor))
