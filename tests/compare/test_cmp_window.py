"""Window-averaged profiles: exact on linear data, finite on an integrable singularity.

References are closed form: the average of a linear function over a window is its value at the
window centre; the average of |x − a|^(−1/2) over [a − W/2, a + W/2] is 4 √(W/2) / W.
"""

import numpy as np
import pytest

from sandwich.compare.profiles import window_average


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
