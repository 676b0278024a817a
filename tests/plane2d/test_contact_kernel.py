"""The contact gap and its derivatives (pure NumPy)."""

import numpy as np
import pytest

from sandwich.plane2d import contact as ct

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


def test_batched_gap_derivatives_equal_the_single_slave_ones():
    # reference: gap_with_derivatives, itself checked against central differences above
    rng = np.random.default_rng(7)
    X = rng.standard_normal((6, 8))
    X[:, 6:] += 3.0
    d = X[:, 0:2] - X[:, 2:4]
    a = X[:, 6:8] - X[:, 4:6]
    g, dg, H = ct.gaps_with_derivatives(d, a)
    for i in range(6):
        g1, dg1, H1 = ct.gap_with_derivatives(np.zeros(2) + d[i], np.zeros(2), X[i, 4:6], X[i, 6:8])
        assert g[i] == pytest.approx(g1, rel=1e-13, abs=1e-14)
        assert np.allclose(dg[i], dg1, rtol=1e-13, atol=1e-14)
        assert np.allclose(H[i], H1, rtol=1e-12, atol=1e-13)


def test_evaluate_forces_are_the_gradient_of_the_contact_energy():
    # reference: central differences of Π = ½ k b Σ w ⟨−g⟩² over all nodes of a small chain
    rng = np.random.default_rng(3)
    n = 5  # slaves 0..4, core nodes 5..11 (chain of 7: tips 5 and 11)
    x_core = np.column_stack([np.linspace(0, 6, 7), np.zeros(7)])
    x_ref = np.vstack([x_core[1:6], x_core])
    pair = ct.ContactPair(np.arange(n), np.arange(n) + 6,
                          np.column_stack([np.arange(n) + 5, np.arange(n) + 7]),
                          np.full(n, 0.7), 50.0, 2.0, x_ref[:n, 0])
    u = 0.05 * rng.standard_normal((12, 2))
    u[:n, 1] -= 0.03  # some slaves penetrate, some not
    st = ct.evaluate(pair, x_ref, u)
    assert 0 < len(st.active) < n

    def energy(v):
        gaps = ct.evaluate(pair, x_ref, v.reshape(12, 2), want_tangent=False).gap
        return 0.5 * 50.0 * 2.0 * np.sum(0.7 * np.minimum(gaps, 0.0) ** 2)

    h = 1e-7
    E = np.eye(24)
    fd = np.array([(energy(u.ravel() + h * E[i]) - energy(u.ravel() - h * E[i])) / (2 * h)
                   for i in range(24)])
    assert np.allclose(st.nodal_forces(12).ravel(), fd, rtol=1e-6, atol=1e-8)
