"""The onset of growth on a path as an equilibrium state, where interpolation is not enough.

:func:`~sandwich.growth.crossing.first_crossing` interpolates r = √(G/G_c) across the step that
crosses 1: exact in a linear analysis, second order in the step otherwise, and poor where G
jumps inside the step (a debonded face that buckles in it). :func:`located` then solves the
path again with the scene's stopping target moved onto the crossing (the ``until`` probe's
value, or the load factor where the scene stops on it), so that the path ends on an
equilibrium there: the path follower hits a target exactly. The target is updated by regula
falsi on r between the two states that bracket 1 until r is within :data:`ONSET_RTOL` of 1
(G within twice that of G_c), at most :data:`MAX_SOLVES` times.

A length after the first is solved first to a target a little beyond its onset extrapolated
from the lengths before (:func:`predicted_target`): a path need not go on to the scene's end to
find where its debond grows.
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
#: A length's path first goes this much beyond the onset extrapolated from the lengths before
#: (relative, in the ``until`` quantity), and on to the scene's target only where no tip
#: reaches G_c by then
PREDICT_MARGIN = 0.25


def target_quantity(scene: Scene) -> Callable[[StepRecord], float]:
    """The quantity the scene stops on, of a state: its ``until`` probe, else the load."""
    name = scene.analysis.until_probe
    return (lambda r: r.probes[name]) if name is not None else (lambda r: r.load_factor)


def with_target(scene: Scene, value: float) -> Scene:
    """``scene`` stopping where its ``until`` quantity (probe, else load factor) is ``value``."""
    a = scene.analysis
    a = (dataclasses.replace(a, until_value=value) if a.until_probe is not None
         else dataclasses.replace(a, until_load_factor=value))
    return dataclasses.replace(scene, analysis=a)


def predicted_target(scene: Scene, onsets: list[float]) -> float | None:
    """Where a path need go to meet the next length's onset: ``None`` for the scene's end.

    ``onsets`` are the ``until`` quantity at the onsets so far; the next is extrapolated
    linearly from the last two (the last alone after one) and the path asked to go
    :data:`PREDICT_MARGIN` beyond it, never beyond the scene's own target.
    """
    end = (scene.analysis.until_value if scene.analysis.until_probe is not None
           else scene.analysis.until_load_factor)
    if not onsets or end is None:
        return None
    guess = onsets[-1] if len(onsets) == 1 else 2.0 * onsets[-1] - onsets[-2]
    if guess * end <= 0.0:  # not on the way to the scene's target
        return None
    value = guess * (1.0 + PREDICT_MARGIN)
    return None if abs(value) >= abs(end) else value


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
    quantity = target_quantity(scene)
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
        solution = solve(with_target(scene, target), progress=progress)
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
