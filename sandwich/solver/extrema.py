"""Load maxima and minima located within the step that passes them.

A load extremum (limit point) used to be reported at the converged state with the extreme load
factor: below a maximum by ½ |λ''| δ², δ the distance from the state to the true top — second
order in the step, and on long steps not small (fig. 7 c1 as shipped: its top state λ 762.7
between 555.9 and 706.8; docs/beam_speed.md).

Each converged state already has the load tangent t = K⁻¹ f_ref (the next step's predictor), so
the load curve's slope there comes free: along the equilibrium path K du = f_ref dλ, so the
curve's probe w = c·u moves as dw/dλ = c·t (:attr:`sandwich.solver.path.PathState.probe_rate`).
A step A → B passes a load extremum where the curve's tangent in the (w, λ) plane turns its λ
component over while its w component keeps its sense (a turning point of w — a snap-back — is
the other way round and is not an extremum of λ). The tangents are oriented forward along the
step (an acute angle with its chord in the scaled plane, as the arc-length predictor's sign).

Over such a step λ is taken as the cubic Hermite interpolant of λ(w) through both states' values
and slopes dλ/dw = 1/(c·t); its stationary point inside the step is the located extremum. The
error in its load factor is fourth order in the step where λ(w) is smooth (the interpolant's),
against the second order of the extreme state (`tests/solver/test_solver_extremum_location.py`
measures both on the von Mises truss, closed form). The other probes are interpolated linearly
in w between the states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Extremum", "SlopeEnd", "hermite_extremum", "located_in", "turns_over"]


@dataclass(frozen=True)
class Extremum:
    """A load extremum located within the step that ends at a path state.

    ``kind`` is ``"max"`` or ``"min"``; ``fraction`` the located point's fraction of the step's
    change of the curve's probe; ``load_factor`` and ``probes`` the located point's;
    ``between`` the load factors of the step's two states.
    """

    kind: str
    fraction: float
    load_factor: float
    probes: dict[str, float]
    between: tuple[float, float]


def turns_over(dw: float, dlam: float, rate_a: float, rate_b: float, w_scale: float,
               lam_scale: float) -> str | None:
    """Which load extremum a step passes: ``"max"``, ``"min"`` or None.

    ``dw``, ``dlam``: the step's change of the probe and of λ; ``rate_a``, ``rate_b``: dw/dλ
    at its two states; ``w_scale``, ``lam_scale``: the units of the curve's plane. Each state's
    tangent (rate, 1) is turned forward (acute with the chord); a max is a tangent whose λ
    component goes from rising to falling while its w component keeps its sense (a min the
    other way). None where the tangents are not finite, the chord has no w component, or w
    turns too.
    """
    if not (math.isfinite(rate_a) and math.isfinite(rate_b)) or dw == 0.0 \
            or not (w_scale > 0.0 and lam_scale > 0.0):
        return None
    chord = (dw / w_scale, dlam / lam_scale)

    def forward(rate: float) -> tuple[float, float]:
        t = (rate / w_scale, 1.0 / lam_scale)
        return t if t[0] * chord[0] + t[1] * chord[1] >= 0.0 else (-t[0], -t[1])

    ta, tb = forward(rate_a), forward(rate_b)
    if ta[0] * tb[0] <= 0.0:  # w turns within the step (or a tangent is parallel to λ): no
        return None
    if ta[1] > 0.0 > tb[1]:
        return "max"
    if ta[1] < 0.0 < tb[1]:
        return "min"
    return None


def hermite_extremum(dw: float, lam_a: float, lam_b: float, rate_a: float,
                     rate_b: float) -> tuple[float, float] | None:
    """The stationary point (x, λ) of λ's cubic Hermite interpolant over a step, x ∈ (0, 1).

    λ(x) through (0, ``lam_a``) and (1, ``lam_b``) with dλ/dx = ``dw``/rate at either end
    (x the fraction of the step's probe change ``dw``, rate = dw/dλ). The slopes must have
    opposite signs (:func:`turns_over`); the quadratic λ'(x) then has exactly one root in
    (0, 1). None where it cannot be found (a rate of zero).
    """
    if rate_a == 0.0 or rate_b == 0.0:
        return None
    s0, s1 = dw / rate_a, dw / rate_b
    if not s0 * s1 < 0.0:
        return None
    d = lam_b - lam_a
    c2 = 3.0 * d - 2.0 * s0 - s1
    c3 = -2.0 * d + s0 + s1
    roots = np.roots([3.0 * c3, 2.0 * c2, s0]) if c3 != 0.0 or c2 != 0.0 else np.empty(0)
    inside = [float(r.real) for r in np.atleast_1d(roots)
              if abs(r.imag) <= 1e-12 * max(1.0, abs(r.real)) and 0.0 < r.real < 1.0]
    if not inside:
        return None
    x = min(inside, key=lambda r: abs(s0 + 2.0 * c2 * r + 3.0 * c3 * r * r))
    return x, lam_a + x * (s0 + x * (c2 + x * c3))


@dataclass(frozen=True)
class SlopeEnd:
    """A converged equilibrium on a step across a load extremum, with its slope.

    ``f`` its fraction of the step's size from the state before, its load factor, probes and
    dw/dλ (``rate``) of the curve's probe there.
    """

    f: float
    load_factor: float
    probes: dict[str, float]
    rate: float


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
