"""Bifurcation detection (pitchfork), step cutting, unrecoverable failures, Newton divergence.

Closed forms: Pitchfork — fundamental path y = 0, x = λP/k1, tangent diag(k1, k2 − x), so the
inertia changes at λ_c = k1 k2 / P with λ still increasing; BoundedDomain — u = λ/(1 + λ);
Saturating — u = artanh(λ), no equilibrium for λ ≥ 1.
"""

import math

import numpy as np
import pytest
from solver_toys import BoundedDomain, Pitchfork, Saturating, VonMisesTruss

from sandwich.solver import (
    NewtonSettings,
    PathOptions,
    follow_path,
    solve_equilibrium,
    solve_linear,
)

TOL = 1e-8


@pytest.mark.parametrize("control", ["load", "arc-length"])
def test_pitchfork_is_reported_as_bifurcation_not_limit_point(control):
    system = Pitchfork()
    lam_c = system.critical_load_factor
    opts = PathOptions(control=control, until_load_factor=2.5 * lam_c, tol=TOL)
    result = follow_path(system, opts, ["x", "y"])
    assert result.reached_target, result.message
    lam = np.array([s.load_factor for s in result.states])
    x = np.array([s.probes["x"] for s in result.states])
    y = np.array([s.probes["y"] for s in result.states])
    assert np.all(np.diff(lam) > 0)  # no load maximum on this path
    np.testing.assert_allclose(x, lam * system.p_ref / system.k1, rtol=0, atol=TOL * lam.max())
    np.testing.assert_array_equal(y, 0.0)
    neg = [s.negative_pivots for s in result.states]
    assert neg == [int(xi > system.k2) for xi in x]  # closed-form inertia diag(k1, k2 − x)
    assert [lp.kind for lp in result.limit_points] == ["bifurcation"]
    k = result.limit_points[0].step
    assert lam[k - 1] < lam_c <= lam[k]


def test_too_large_step_is_cut_and_the_path_continues():
    system = BoundedDomain()
    # a tangent predictor of Δλ ≥ 1 from u = 0 lands outside the domain (u ≥ 1): must be cut
    opts = PathOptions(control="load", until_load_factor=4.0, initial_increment=4.0, tol=TOL)
    result = follow_path(system, opts, ["u"])
    assert result.reached_target, result.message
    assert result.states[1].cuts >= 3 and result.states[1].load_factor < 1.0
    assert result.states[-1].load_factor == 4.0
    lam = np.array([s.load_factor for s in result.states])
    u = np.array([s.probes["u"] for s in result.states])
    # closed form; the residual bound |u/(1−u) − λ| ≤ tol·max λ maps to u through du/dλ ≤ 1
    np.testing.assert_allclose(u, lam / (1.0 + lam), rtol=0, atol=TOL * lam.max())


def test_path_with_no_equilibrium_beyond_some_load_stops_and_keeps_its_states():
    system = Saturating()
    opts = PathOptions(control="load", until_load_factor=2.0, tol=TOL)
    result = follow_path(system, opts, ["u"])
    assert not result.reached_target
    last = result.states[-1]
    assert len(result.states) > 2
    assert f"step {last.step + 1}" in result.message
    assert f"λ = {last.load_factor:.6g}" in result.message
    assert f"u = {last.probes['u']:.6g}" in result.message
    lam = np.array([s.load_factor for s in result.states])
    u = np.array([s.probes["u"] for s in result.states])
    assert np.all(np.isfinite(u)) and np.all(lam < 1.0)
    # closed form u = artanh λ, checked on the residual: |tanh u − λ| ≤ tol·max λ
    assert np.abs(np.tanh(u) - lam).max() <= TOL * lam.max()
    assert len(system.commits) == len(result.states)


def test_newton_reports_divergence_instead_of_raising():
    res = solve_equilibrium(Saturating(), 2.0, settings=NewtonSettings(max_iterations=10))
    assert not res.converged and res.reason
    assert np.all(np.isfinite(res.u))
    res = solve_equilibrium(BoundedDomain(), 1.0, u0=np.array([2.0]))  # outside the domain
    assert not res.converged and "non-finite" in res.reason


def test_newton_fixed_load_converges_to_the_closed_form():
    truss = VonMisesTruss()
    (_, l_max), _ = truss.limit_points()
    lam = 0.5 * l_max
    res = solve_equilibrium(truss, lam, settings=NewtonSettings(tol=TOL))
    assert res.converged
    assert abs(truss.bar_force(res.u[0]) - lam) <= TOL * lam
    assert res.factorization.negative_pivots == 0


def test_solve_linear_is_k0_inverse_f():
    truss = VonMisesTruss(spring=50.0)
    k0 = truss.tangent(np.zeros(2))
    u = solve_linear(truss, 3.0)
    np.testing.assert_allclose(k0 @ u, 3.0 * truss.f_ref, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(
    "kwargs",
    [dict(control="bogus"), dict(until_probe="w"), dict(control="displacement"),
     dict(until_load_factor=0.0), dict(max_steps=0)],
)
def test_invalid_options_are_rejected(kwargs):
    with pytest.raises(ValueError):
        PathOptions(**kwargs)


def test_states_never_hold_nan_even_when_the_model_returns_nan():
    system = BoundedDomain()
    result = follow_path(system, PathOptions(until_load_factor=50.0, initial_increment=50.0), ["u"])
    for s in result.states:
        assert np.all(np.isfinite(s.u)) and math.isfinite(s.load_factor)
        assert all(math.isfinite(v) for v in s.probes.values())
