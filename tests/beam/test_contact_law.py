"""The regularised (shifted softplus) contact law of sandwich.beam.contact_law.

References: the closed-form energy (dilogarithm) differentiated by central finite differences; the
law's own definition for the limits (p = 0 for g ≥ 0, p → ε(−g − c s) deep in contact).
"""

import numpy as np

from sandwich.beam.contact import pair_kinematics, penalty_response
from sandwich.beam.contact_law import (
    SHIFT,
    contact_energy,
    penalty_blocks,
    penalty_blocks_numpy,
    penalty_kernel,
    pressure_law,
)
from sandwich.beam.contact_search import contact_pairs

EPS = 2.24e4  # N/mm³, the default penalty for the paper's Rohacell core
S = 1e-6  # mm, the default regularisation width for 0.5 mm faces


def test_pressure_is_the_energy_derivative_and_stiffness_its_derivative():
    g = -S * np.array([0.5, 5.0, 20.0, 24.0, 25.0, 26.0, 30.0, 60.0, 400.0])
    p, dp = pressure_law(g, EPS, S)
    h = 1e-4 * S
    fd_p = -(contact_energy(g + h, EPS, S) - contact_energy(g - h, EPS, S)) / (2 * h)
    fd_dp = (pressure_law(g + h, EPS, S)[0] - pressure_law(g - h, EPS, S)[0]) / (2 * h)
    assert np.allclose(p, fd_p, rtol=1e-6, atol=1e-12 * EPS * S)
    assert np.allclose(dp, fd_dp, rtol=1e-6)


def test_no_force_when_open_and_plain_penalty_deep_in_contact():
    p, dp = pressure_law(np.array([0.0, 1e-9, 1.0]), EPS, S)
    assert np.all(p == 0) and np.all(dp == 0)
    g = np.array([-1e-3, -1e-2])
    p, dp = pressure_law(g, EPS, S)
    assert np.allclose(p, EPS * (-g - SHIFT * S), rtol=1e-9)
    assert np.allclose(dp, -EPS, rtol=1e-9)
    # the stiffness jump left at g = 0 is ε e^(-c): negligible against any structure
    assert -pressure_law(np.array([-1e-15 * S]), EPS, S)[1][0] < 1e-10 * EPS


def test_penetration_is_at_most_offset_plus_plain_penalty():
    g = -np.logspace(-9, -2, 50)
    p, _ = pressure_law(g, EPS, S)
    assert np.all(-g <= SHIFT * S + p / EPS + 1e-15)


def test_contact_tangent_matches_finite_differences_in_the_smooth_band():
    rng = np.random.default_rng(7)
    x = np.linspace(0.0, 10.0, 6)
    pairs = contact_pairs("top", np.arange(1, 5), x, 60.0)
    u = rng.normal(size=20 * 6) * 0.05
    # place every pair's gap inside the band where the stiffness changes most (g ≈ −c s)
    w_face = pairs.dofs[:, 1]
    for _ in range(5):  # Newton on the face w to hit the target gaps
        k = pair_kinematics(pairs, u)
        target = -SHIFT * S * np.array([0.6, 0.9, 1.0, 1.2])
        u[w_face] -= (k.gap - target) / k.grad[:, 1]
    k = pair_kinematics(pairs, u)
    assert np.all(k.gap < 0) and np.all(k.gap > -2 * SHIFT * S)
    f, K, _, _ = penalty_response(pairs, u, EPS, S)
    step = 1e-4 * S
    for m in range(pairs.size):
        for j in range(6):
            du = np.zeros_like(u)
            du[pairs.dofs[m, j]] = step
            fp = penalty_response(pairs, u + du, EPS, S)[0][m]
            fm = penalty_response(pairs, u - du, EPS, S)[0][m]
            fd = (fp - fm) / (2 * step)
            assert np.allclose(K[m][:, j], fd, rtol=1e-5, atol=1e-6 * np.abs(K[m]).max())


def test_compiled_penalty_blocks_are_the_numpy_law_to_round_off():
    """The compiled blocks (contact_kernel.penalty_blocks) against the NumPy reference
    (pressure_law, then the outer products): open, in the softplus knee, deep, and the plain
    penalty (s = 0); relative round-off of each block's largest entry."""
    kernel = penalty_kernel()
    if kernel is None:
        import pytest

        pytest.skip("numba is not installed: the NumPy blocks are the only ones")
    rng = np.random.default_rng(3)
    gap = -S * np.array([-2.0, 0.0, 0.5, 20.0, 25.0, 30.0, 400.0, 1e5])
    m, n = gap.size, 10
    grad = rng.normal(size=(m, n))
    hess = rng.normal(size=(m, n, n))
    hess = hess + hess.transpose(0, 2, 1)
    area = rng.uniform(1.0, 3.0, m)
    for smoothing in (S, 0.0):
        f, K, p = penalty_blocks(gap, grad, hess, area, EPS, smoothing)
        f0, K0, p0 = penalty_blocks_numpy(gap, grad, hess, area, EPS, smoothing)
        assert np.all(p[:2] == 0) and np.all(f[:2] == 0) and np.all(K[:2] == 0)  # open
        scale = np.abs(K0).max(axis=(1, 2))[:, None, None] + 1e-300
        assert np.allclose(p, p0, rtol=1e-13, atol=0)
        assert np.all(np.abs(K - K0) <= 1e-13 * scale)
        assert np.all(np.abs(f - f0) <= 1e-13 * (np.abs(f0).max(axis=1)[:, None] + 1e-300))
        assert np.any(p0 > 0)
