"""Window-averaged profiles: exact on linear data, finite on an integrable singularity.

References are closed form: the average of a linear function over a window is its value at the
window centre; the average of |x − a|^(−1/2) over [a − W/2, a + W/2] is 4 √(W/2) / W.
"""

import numpy as np
import pytest

from sandwich.results.peaks import window_average


def test_linear_profile_average_is_its_centre_value():
    x = np.linspace(0.0, 100.0, 51)
    c, avg = window_average(x, 3.0 - 0.2 * x, 5.0)
    assert np.allclose(avg, 3.0 - 0.2 * c, atol=1e-12)
    assert c.min() >= 2.5 - 1e-12 and c.max() <= 97.5 + 1e-12


@pytest.mark.parametrize("n", [2001, 8001, 32001])
def test_singular_profile_average_converges_to_closed_form(n):
    x = np.linspace(0.0, 100.0, n)
    h = x[1] - x[0]
    a, width = 50.0 + h / 2, 5.0  # the pole between two samples, as in a mesh
    y = np.abs(x - a) ** -0.5
    c, avg = window_average(x, y, width)
    exact = 4.0 * np.sqrt(width / 2) / width
    at_pole = np.interp(a, c, avg)
    # the linear interpolant misses O(√h) of the integral next to the pole: 2√(2h) at most
    assert abs(at_pole - exact) <= 2.0 * np.sqrt(2 * h) / width
    assert y.max() > 4 * exact  # the raw peak, (h/2)^(-1/2), is far above it and grows


def test_window_wider_than_profile_is_refused():
    with pytest.raises(ValueError, match="window"):
        window_average(np.array([0.0, 1.0]), np.array([0.0, 1.0]), 5.0)


def _hat(x: np.ndarray, centre: float, height: float, half: float) -> np.ndarray:
    return height * np.maximum(0.0, 1.0 - np.abs(x - centre) / half)


def test_stress_changes_are_those_of_the_averaged_peak_magnitudes():
    """Closed form: a hat of height H and half-width 10 mm averaged over 5 mm centred on its
    top is H (1 − 5/40) = 0.875 H; the estimate compares magnitudes (equal and opposite shear
    peaks either side of a symmetric scene's middle), relative to the group's largest peak."""
    from sandwich.results.changes import stress_changes

    x = np.linspace(0.0, 100.0, 2001)
    before = {"x": x, "sigma_zz_top": _hat(x, 40.0, 2.0, 10.0),
              "sigma_zz_bottom": _hat(x, 70.0, -0.5, 10.0),
              "tau_core": _hat(x, 30.0, 1.0, 10.0) - _hat(x, 70.0, 1.0, 10.0)}
    after = {"x": x, "sigma_zz_top": _hat(x, 40.0, 2.2, 10.0),  # +10 %
             "sigma_zz_bottom": _hat(x, 70.0, -0.9, 10.0),  # +0.4 MPa: 0.35 of the top's peak
             "tau_core": _hat(x, 30.0, 1.0, 10.0) - _hat(x, 70.0, 1.03, 10.0)}  # the other side
    out = stress_changes(before, after)
    # σzz: the bottom's change 0.4 × 0.875 against the top's peak 2 × 0.875 (not the bottom's own)
    assert out["interface sigma_zz"] == pytest.approx(0.4 / 2.0, rel=1e-9)
    assert out["core tau"] == pytest.approx(0.03, rel=1e-9)
    assert stress_changes(before, before) == {"interface sigma_zz": 0.0, "core tau": 0.0}
    short = {k: v[:40] for k, v in before.items()}  # 2 mm of profile: shorter than the window
    assert stress_changes(short, short) == {}
