"""The contact gap and its derivatives (pure NumPy)."""

import numpy as np
import pytest

from reference2d import contact as ct

pytestmark = pytest.mark.dolfinx


def test_gap_gradient_and_hessian_match_finite_differences():
    rng = np.random.default_rng(1)
    for _ in range(5):
        X = rng.standard_normal(8)
        X[6:] += 3.0  # keep the chord away from zero length
        g, dg, H = ct.gap_with_derivatives(X[:2], X[2:4], X[4:6], X[6:])
        h = 1e-6
        E = np.eye(8)
        fd_g = np.array([(ct.gap_with_derivatives(*np.split(X + h * E[i], 4))[0]
                          - ct.gap_with_derivatives(*np.split(X - h * E[i], 4))[0]) / (2 * h)
                         for i in range(8)])
        fd_H = np.array([(ct.gap_with_derivatives(*np.split(X + h * E[i], 4))[1]
                          - ct.gap_with_derivatives(*np.split(X - h * E[i], 4))[1]) / (2 * h)
                         for i in range(8)])
        assert np.allclose(dg, fd_g, atol=1e-8)
        assert np.allclose(H, fd_H, atol=1e-7)
        assert np.allclose(H, H.T)


def test_gap_sign_and_value():
    # core lip along +x: normal +z; a point 0.3 above the anchor has gap +0.3
    g, _, _ = ct.gap_with_derivatives(np.array([1.0, 0.3]), np.array([1.0, 0.0]),
                                      np.array([0.0, 0.0]), np.array([2.0, 0.0]))
    assert g == pytest.approx(0.3)
    g, _, _ = ct.gap_with_derivatives(np.array([1.0, -0.2]), np.array([1.0, 0.0]),
                                      np.array([0.0, 0.0]), np.array([2.0, 0.0]))
    assert g == pytest.approx(-0.2)


def test_slave_weights_integrate_length():
    x = np.array([1.0, 2.0, 3.0, 4.0, 5.0])  # between tips 0 and 6: 3 quadratic facets
    w = ct.slave_weights(x, 0.0, 6.0)
    # Simpson weights: mid 2/3 h, shared corner 1/6 h + 1/6 h with h = 2
    assert np.allclose(w, [4 / 3, 2 / 3, 4 / 3, 2 / 3, 4 / 3])
