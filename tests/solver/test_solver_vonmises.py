"""Von Mises two-bar truss (1 DOF): load control stops at the load maximum, displacement and
arc-length control trace the full snap-through.

Reference values are closed form (see ``VonMisesTruss``): λ(w) = f(w)/P on the path and the
limit points at L³ = a² L0, λ_max = f(w_max)/P.
"""

import numpy as np
import pytest
from solver_toys import VonMisesTruss

from sandwich.solver import PathOptions, follow_path

TOL = 1e-8  # Newton tolerance used below (PathOptions.tol)


def _arrays(result, name="w"):
    lam = np.array([s.load_factor for s in result.states])
    w = np.array([s.probes[name] for s in result.states])
    return lam, w


def _assert_on_curve(truss, result, name="w"):
    """Closed form: |λ − f(w)/P| ≤ tol · max|λ| is exactly the residual test of a 1-load DOF."""
    lam, w = _arrays(result, name)
    assert np.all(np.isfinite(lam)) and np.all(np.isfinite(w))
    err = np.abs(lam - truss.bar_force(w) / truss.p_ref)
    assert err.max() <= TOL * np.abs(lam).max() * (1 + 1e-6) + 1e-12


def _assert_limit_within_step_resolution(truss, result, kind, name="w"):
    """The reported extremum is a state k; Taylor with remainder bounds its distance to the
    analytic extremum: |λ* − λ_k| ≤ ½ sup|λ''| h², h = the larger neighbouring w-spacing."""
    lam, w = _arrays(result, name)
    (w_max, l_max), (w_min, l_min) = truss.limit_points()
    exact = l_max if kind == "max" else l_min
    lps = [lp for lp in result.limit_points if lp.kind == kind]
    assert len(lps) == 1
    k = lps[0].step
    h = max(abs(w[k + 1] - w[k]), abs(w[k] - w[k - 1]))
    grid = np.linspace(w[k - 1], w[k + 1], 401)
    bound = 0.5 * np.abs(truss.bar_curvature(grid)).max() / truss.p_ref * h**2
    gap = exact - lps[0].load_factor if kind == "max" else lps[0].load_factor - exact
    assert -TOL * abs(exact) <= gap <= bound
    assert w[k - 1] <= (w_max if kind == "max" else w_min) <= w[k + 1]
    return gap, bound


def test_load_control_stops_just_below_the_load_maximum_with_a_clear_message():
    truss = VonMisesTruss()
    (_, l_max), _ = truss.limit_points()
    opts = PathOptions(control="load", until_load_factor=1.5 * l_max, tol=TOL,
                       min_increment=1e-5 * l_max)
    result = follow_path(truss, opts, ["w"])
    assert not result.reached_target
    last = result.states[-1]
    assert f"step {last.step + 1}" in result.message
    assert f"λ = {last.load_factor:.6g}" in result.message
    assert "limit point" in result.message
    _assert_on_curve(truss, result)
    # never beyond the maximum (no jump to the inverted branch), and stopped within 1e-3 λ_max
    assert last.load_factor <= l_max
    assert l_max - last.load_factor <= 1e-3 * l_max
    assert all(s.negative_pivots == 0 for s in result.states)
    assert [lp.kind for lp in result.limit_points] == []


@pytest.mark.parametrize("control", ["displacement", "arc-length"])
def test_full_snap_through_is_traced(control):
    truss = VonMisesTruss()
    (w_max, l_max), (w_min, l_min) = truss.limit_points()
    seen = []
    opts = PathOptions(control=control, until_probe="w", until_value=3.0 * truss.h, tol=TOL,
                       max_increment=0.02 if control == "displacement" else 0.015,
                       max_steps=500)
    result = follow_path(truss, opts, ["w"], progress=seen.append)
    assert result.reached_target, result.message
    lam, w = _arrays(result)
    _assert_on_curve(truss, result)
    assert abs(w[-1] - 3.0 * truss.h) <= opts.target_tol * 3.0 * truss.h
    assert np.all(np.diff(w) > 0)  # moves forward along the path, never back
    assert lam.min() < 0 < lam.max()  # passed through the negative-load part of the snap
    # inertia: one negative pivot exactly where the closed-form tangent f'(w) is negative
    neg = np.array([s.negative_pivots for s in result.states])
    np.testing.assert_array_equal(neg, (truss.bar_stiffness(w) < 0).astype(int))
    assert sorted(lp.kind for lp in result.limit_points) == ["max", "min"]
    for kind in ("max", "min"):
        gap, bound = _assert_limit_within_step_resolution(truss, result, kind)
        assert bound < 0.02 * l_max  # the step resolution makes this a real check
    # progress and commit saw every converged state, in order
    assert [s.step for s in seen] == list(range(len(result.states)))
    assert [c[1] for c in truss.commits] == [s.load_factor for s in result.states]


def test_load_control_hits_the_target_load_factor_exactly():
    truss = VonMisesTruss()
    (_, l_max), _ = truss.limit_points()
    target = 0.9 * l_max
    result = follow_path(truss, PathOptions(control="load", until_load_factor=target), ["w"])
    assert result.reached_target
    assert result.states[-1].load_factor == target
    _assert_on_curve(truss, result)


def test_arc_length_stops_on_a_load_factor_target_beyond_the_snap():
    truss = VonMisesTruss()
    (_, l_max), _ = truss.limit_points()
    target = 3.0 * l_max  # reached only on the inverted (tension) branch
    opts = PathOptions(control="arc-length", until_load_factor=target, tol=TOL)
    result = follow_path(truss, opts, ["w"])
    assert result.reached_target, result.message
    assert abs(result.states[-1].load_factor - target) <= opts.target_tol * target
    lam, w = _arrays(result)
    assert w[-1] > 2.0 * truss.h  # closed form: λ > λ_max only for w > 2h (inverted truss)
    _assert_on_curve(truss, result)


def test_max_steps_stops_with_states_kept():
    truss = VonMisesTruss()
    opts = PathOptions(control="arc-length", until_probe="w", until_value=3.0 * truss.h,
                       max_steps=3)
    result = follow_path(truss, opts, ["w"])
    assert not result.reached_target
    assert "max_steps = 3" in result.message
    assert [s.step for s in result.states] == [0, 1, 2, 3]
    _assert_on_curve(truss, result)
