"""Load maxima and minima located within the step that passes them.

A load extremum (limit point) used to be reported at the converged state with the extreme load
factor: below a maximum by ½ |λ''| δ², δ the distance from the state to the true top — second
order in the step, and on long steps not small (fig. 7 c1 as shipped: its top state λ 762.7
between 555.9 and 706.8; docs/speed.md).

Each converged state already has the load tangent t = K⁻¹ f_ref (the next step's predictor), so
the load curve's slope there comes free: along the equilibrium path K du = f_ref dλ, so the
curve's probe w = c·u moves as dw/dλ = c·t (:attr:`sandwich.solver.path.PathState.probe_rate`).
A step A → B passes a load extremum where the path's tangent (t, 1) turns its λ component over
while its w component (c·t) keeps the sense of the step's change of w (a turning point of w —
a snap-back — is the other way round and is not an extremum of λ). Each state's tangent is
oriented forward along the step in the path's own space: its sense is that of
t·Δu + ψ² Δλ over the step's change (Δu, Δλ), as the retrace guard measures turns.

Over such a step λ is taken as the cubic Hermite interpolant of λ(w) through both states' values
and slopes dλ/dw = 1/(c·t); its stationary point inside the step is the located extremum. The
error in its load factor is fourth order in the step where λ(w) is smooth (the interpolant's),
against the second order of the extreme state (`tests/solver/test_solver_extremum_location.py`
measures both on the von Mises truss, closed form). Where w is about to turn at an end, λ(w)
is not smooth and the cubic swells: a located maximum above the meeting point of the two end
tangent lines (a minimum below it) is refused — a concave top lies below it — and the extreme
state is reported as before. The other probes are interpolated linearly in w between the
states.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["Extremum", "SlopeEnd", "hermite_extremum", "located_in", "turns_over"]


@dataclass(frozen=True)
class Extremum:
    """A load extremum located within the step that ends at a path state.

    ``kind`` is ``"max"`` or ``"min"``; ``fraction`` the located point's fraction of the step's
    change of the curve's probe; ``load_factor`` and ``probes`` the located point's;
    ``between`` the load factors of the step's two states (or of the narrowed bracket's ends).
    """

    kind: str
    fraction: float
    load_factor: float
    probes: dict[str, float]
    between: tuple[float, float]


def turns_over(dw: float, rate_a: float, rate_b: float, sense_a: float,
               sense_b: float) -> str | None:
    """Which load extremum a step passes: ``"max"``, ``"min"`` or None.

    ``dw``: the step's change of the probe; ``rate_a``, ``rate_b``: dw/dλ at its two ends;
    ``sense_a``, ``sense_b``: the sense (±1) in which the tangent (t, 1) at each end points
    forward along the step. A max is a forward tangent whose λ component goes from rising to
    falling while its w component (sense × rate) moves w the way the step does at both ends (a
    min the other way). None where a rate is not finite, the step does not move w, or w turns
    within it.
    """
    if not (math.isfinite(rate_a) and math.isfinite(rate_b)) or dw == 0.0 \
            or sense_a == 0.0 or sense_b == 0.0:
        return None
    if sense_a * rate_a * dw <= 0.0 or sense_b * rate_b * dw <= 0.0:
        return None  # w turns within the step (or a tangent does not move it)
    if sense_a > 0.0 > sense_b:
        return "max"
    if sense_a < 0.0 < sense_b:
        return "min"
    return None


def _sign_change(g: Callable[[float], float]) -> float:
    """The root of ``g`` in (0, 1) by bisection; g(0) and g(1) have opposite signs.

    (Bisection rather than scipy.optimize: that import alone costs 50 ms of a 0.5-s run.)
    """
    lo, hi, g_lo = 0.0, 1.0, g(0.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        g_mid = g(mid)
        if g_mid == 0.0:
            return mid
        if (g_mid > 0.0) == (g_lo > 0.0):
            lo, g_lo = mid, g_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def hermite_extremum(dw: float, lam_a: float, lam_b: float, rate_a: float,
                     rate_b: float) -> tuple[float, float] | None:
    """The stationary point (x, λ) of λ's cubic Hermite interpolant over a step, x ∈ (0, 1).

    λ(x) through (0, ``lam_a``) and (1, ``lam_b``) with dλ/dx = ``dw``/rate at either end
    (x the fraction of the step's probe change ``dw``, rate = dw/dλ). The slopes must have
    opposite signs (:func:`turns_over`); λ'(x) then has exactly one root in (0, 1). None where
    a rate is zero, or where the stationary value lies beyond the meeting point of the end
    tangent lines (above it for a maximum, below for a minimum: the cubic has swollen where w
    is about to turn, and the point is not trusted).
    """
    if rate_a == 0.0 or rate_b == 0.0:
        return None
    s0, s1 = dw / rate_a, dw / rate_b
    if not s0 * s1 < 0.0:
        return None
    d = lam_b - lam_a
    c2 = 3.0 * d - 2.0 * s0 - s1
    c3 = -2.0 * d + s0 + s1
    x = _sign_change(lambda r: s0 + r * (2.0 * c2 + 3.0 * c3 * r))
    lam = lam_a + x * (s0 + x * (c2 + x * c3))
    # the end tangents λ_a + s0 x and λ_b + s1 (x − 1) meet at x_m (s0 − s1 ≠ 0: opposite signs)
    x_m = (d - s1) / (s0 - s1)
    lam_m = lam_a + s0 * x_m
    if (lam - lam_m) * (1.0 if s0 > 0.0 else -1.0) > 1e-12 * max(abs(lam), abs(lam_m)):
        return None
    return x, lam


@dataclass(frozen=True)
class SlopeEnd:
    """A converged equilibrium on a step across a load extremum, with its slope.

    ``f`` its fraction of the step's size from the state before, its load factor, probes,
    dw/dλ (``rate``) of the curve's probe there and the sense (±1) in which its tangent points
    forward along the step.
    """

    f: float
    load_factor: float
    probes: dict[str, float]
    rate: float
    sense: float


def located_in(lo: SlopeEnd, hi: SlopeEnd, name: str) -> tuple[float, float] | None:
    """The extremum of the bracket lo–hi: (the fraction of the step, in ``f``, its λ).

    The stationary point of λ's cubic Hermite interpolant in the probe ``name`` between the
    ends (:func:`hermite_extremum`), its ``f`` interpolated linearly in the probe.
    """
    dw = hi.probes[name] - lo.probes[name]
    found = hermite_extremum(dw, lo.load_factor, hi.load_factor, lo.rate, hi.rate)
    if found is None:
        return None
    x, lam = found
    return lo.f + x * (hi.f - lo.f), lam
