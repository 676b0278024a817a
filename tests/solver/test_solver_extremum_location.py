"""A load extremum is located within the step that passes it (sandwich.solver.extrema).

References: closed forms. λ(w) = cos w near its maximum at w = 0 (the interpolant's order); the
von Mises truss of solver_toys.py, λ(w) = f(w)/P with its maximum where L³ = a² L0.
"""

import math

import numpy as np
import pytest
from solver_toys import VonMisesTruss

from sandwich.solver import PathOptions, follow_path
from sandwich.solver.extrema import hermite_extremum, turns_over


def _cos_step(h: float, at: float = 0.3) -> tuple[float, float]:
    """The located top of λ = cos w on a step of length h with the top at ``at`` of it."""
    wa, wb = -at * h, (1.0 - at) * h
    rate = lambda w: -1.0 / math.sin(w)  # dw/dλ  # noqa: E731
    x, lam = hermite_extremum(wb - wa, math.cos(wa), math.cos(wb), rate(wa), rate(wb))
    return wa + x * (wb - wa), lam


def test_the_located_load_is_fourth_order_in_the_step():
    # closed form: the top of cos w is λ = 1 at w = 0; the extreme state of a step is off by
    # ≈ w²/2 (second order), the interpolant's stationary point by O(h⁴) in λ, O(h³) in w
    hs = np.array([0.4, 0.2, 0.1, 0.05])
    errors = np.array([1.0 - _cos_step(h)[1] for h in hs])
    where = np.array([abs(_cos_step(h)[0]) for h in hs])
    order = np.polyfit(np.log(hs), np.log(np.abs(errors)), 1)[0]
    assert order > 3.8  # measured 4.0
    assert np.polyfit(np.log(hs), np.log(where), 1)[0] > 2.8  # measured 3.0
    state = 1.0 - math.cos(0.3 * hs[-1])  # the nearer state of the finest step
    assert abs(errors[-1]) < 1e-3 * state


def test_a_turn_of_the_probe_is_not_a_load_extremum():
    # (w, λ) plane, both scales 1; a step whose chord goes right and up
    assert turns_over(1.0, 0.2, 2.0, -2.0, 1.0, 1.0) == "max"  # λ rises, then falls; w forward
    assert turns_over(1.0, -0.2, -2.0, 2.0, 1.0, 1.0) == "min"
    # w rises then turns back (dw/dλ: + then −, small): a snap-back, λ rises throughout
    assert turns_over(0.1, 1.0, 0.5, -0.5, 1.0, 1.0) is None
    assert turns_over(1.0, 0.2, 2.0, 2.0, 1.0, 1.0) is None  # no turn
    assert turns_over(0.0, 0.2, 2.0, -2.0, 1.0, 1.0) is None  # no probe change
    assert turns_over(1.0, 0.2, math.inf, -2.0, 1.0, 1.0) is None


@pytest.mark.parametrize("h", [0.04, 0.02, 0.01])
def test_the_path_reports_the_truss_maximum_far_inside_the_second_order_bound(h):
    # displacement steps of h past the truss's maximum and minimum: the extreme state lies
    # below the maximum by up to ½ sup|λ''| h² (Taylor); the located one within 1 % of that
    # (measured 4e-6, 1.8e-7, 1.9e-8 relative at h = 0.04, 0.02, 0.01)
    truss = VonMisesTruss()
    (w_max, lam_max), _ = truss.limit_points()
    opts = PathOptions(control="displacement", until_probe="w", until_value=0.8,
                       initial_increment=h, max_increment=h, min_increment=h, tol=1e-12,
                       max_steps=1000)
    result = follow_path(truss, opts, ["w"])
    assert result.reached_target, result.message
    lp = next(lp for lp in result.limit_points if lp.kind == "max")
    w = np.array([s.probes["w"] for s in result.states])
    grid = np.linspace(w_max - h, w_max + h, 401)
    bound = 0.5 * np.abs(truss.bar_curvature(grid)).max() / truss.p_ref * h**2
    assert lp.located_at is not None and w[lp.step - 1] < lp.probes["w"] < w[lp.step]
    assert lp.between == (result.states[lp.step - 1].load_factor,
                          result.states[lp.step].load_factor)
    assert abs(lp.load_factor - lam_max) < 0.01 * bound
    assert abs(lp.probes["w"] - w_max) < 0.05 * h
    assert [p.kind for p in result.limit_points] == ["max", "min"]  # the inertia changes
    # at both are explained by them, not reported as bifurcations


def test_without_a_probe_the_extreme_state_is_reported_as_before():
    # arc-length to a load factor past the snap-through, no probe: no slope to locate with
    truss = VonMisesTruss()
    (_, lam_max), _ = truss.limit_points()
    opts = PathOptions(control="arc-length", until_load_factor=1.5 * lam_max, tol=1e-10,
                       max_increment=0.05 * lam_max, max_steps=400)
    result = follow_path(truss, opts, [])
    lps = [lp for lp in result.limit_points if lp.kind == "max"]
    assert lps and lps[0].located_at is None
    lam = [s.load_factor for s in result.states]
    assert lps[0].load_factor == lam[lps[0].step] == max(lam[: lps[0].step + 2])
