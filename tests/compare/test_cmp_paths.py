"""Curve errors and limit loads on analytic curves with known answers."""

import numpy as np
import pytest

from sandwich.compare.paths import Curve, curve_error, limit_loads, monotone_prefix


@pytest.mark.parametrize("eps", [0.002, 0.03, -0.05])
def test_curve_error_recovers_scale_factor(eps):
    x_ref = np.linspace(0.0, 15.0, 151)
    x = np.linspace(0.0, 14.0, 61)  # other sampling, shorter range
    f = lambda t: 10 * t - 0.02 * t**3  # noqa: E731
    err = curve_error(Curve("2d", x_ref, f(x_ref)), Curve("beam", x, (1 + eps) * f(x)), "q", "t")
    assert err.common_range == (0.0, 14.0)
    # linear interpolation of a cubic on a 0.23 mm grid: ≲ 1e-4 relative, far below |eps|
    assert err.l2_relative == pytest.approx(abs(eps), abs=2e-4)
    assert err.max_relative == pytest.approx(abs(eps), abs=2e-4)


def test_curve_error_is_zero_for_identical_curves_and_none_without_overlap():
    x = np.linspace(1.0, 2.0, 11)
    same = curve_error(Curve("a", x, x**2), Curve("b", x, x**2), "q", "t")
    assert same.l2_relative == 0.0 and same.max_relative == 0.0
    apart = curve_error(Curve("a", x, x), Curve("b", x + 5, x), "q", "t")
    assert apart.l2_relative is None and apart.common_range is None and "no common" in apart.note


def test_limit_load_found_at_analytic_maximum(synth):
    sol = synth.make_solution("2d", n_steps=150)
    lam = np.array([r.load_factor for r in sol.history])
    found = limit_loads(lam)
    w_max, lam_max = synth.analytic_limit()
    assert len(found) == 1
    assert abs(sol.history[found[0]].probes["w_top_mid"]) == pytest.approx(w_max, abs=0.1)
    assert lam[found[0]] == pytest.approx(lam_max, rel=1e-4)


def test_limit_loads_ignore_rising_paths_and_small_wiggles_but_see_two_drops():
    rising = np.linspace(0, 10, 50)
    assert limit_loads(rising) == []
    wiggle = rising.copy()
    wiggle[21] = wiggle[20] * (1 - 0.001)  # falls by 0.1 % then rises: noise, not a limit
    assert limit_loads(wiggle) == []
    dip = rising.copy()
    dip[21] = dip[20] * (1 - 0.01)  # falls by 1 % (above the 0.5 % threshold) then rises
    assert limit_loads(dip) == [20]
    t = np.linspace(0, 4 * np.pi, 400)
    two = t + 3 * np.sin(t)  # falls twice by several percent
    assert len(limit_loads(two)) == 2


def test_monotone_prefix_cuts_at_reversal():
    assert monotone_prefix(np.array([0.0, -1.0, -2.0, -1.5, -3.0])) == 3
    assert monotone_prefix(np.array([0.0, 1.0, 2.0])) == 3
