"""The contact law: penalty pressure of the gap, regularised by a shifted softplus.

Law. Penalty ε (N/mm³) on a node's tributary area A = b · (half the adjacent element lengths),
regularised over a gap width s (mm) by a shifted "softplus" (:func:`pressure_law`):

    p(g) = ε s [sp(−g/s − c) − sp(−c)]  for g < 0,   p = 0 for g ≥ 0   (pressure, MPa),
    sp(x) = ln(1 + eˣ),   dp/dg = −ε / (1 + e^(g/s + c)),   c = SHIFT = 25.

Far inside (−g ≫ c s) this is the plain penalty ε (−g − c s), offset by c s; near g = 0 the
stiffness −dp/dg rises smoothly over a few s around g = −c s. At g = 0, p = 0 exactly (the
unloaded and rigidly moved states carry no contact force) and dp/dg jumps by ε e⁻²⁵ (≈ 3e-7
N/mm³), far below any structural stiffness. s = 0 is the plain penalty ε ⟨−g⟩. Force
f = −p A ∂g/∂u and consistent tangent K = −A p'(g) ∂g ∂gᵀ − p A ∂²g (the second term is the
rotation of the normal); the energy A ∫_g^0 p(t) dt has a closed form (dilogarithm).

Why regularise. With the plain penalty the tangent jumps by ε A (≈ 1e7 N/mm for an 8 mm element)
when a pair opens. Where the face next to an opening pair buckles away from the core (debonds at
a clamp, fig. 7 C3/C4) the structure without that pair is unstable (a negative tangent
eigenvalue, measured −12 N/mm at 40 elements), so the opening is a limit point with a corner:
Newton jumps between the two tangents and the arc-length method cannot turn. A polynomial band
(p quadratic over |g| < δ) does not help: the stiffness falls from ε A to the structure's ~10 N/mm
only within 1e-6 δ of the band's edge, a corner again. The exponential tail of the softplus
spreads that fall over ~14 s, the path turns smoothly, and the arc-length method passes it with
steps down to ~s (:mod:`sandwich.beam.path_pass` lowers the step floor accordingly).

What it costs: the penetration at a pressure p is at most c s + p/ε, so with the default
s = 0.002 × bound (1e-6 mm for 0.5 mm faces; offset c s = 2.5e-5 mm) the bound 1e-3 × face
thickness holds wherever p ≤ ε × (bound − c s) (10.6 MPa for the paper's materials). The offset
is what limits s: near a debond tip the face must bend from g = 0 (tied) to g ≈ −c s, which
disturbs the pressure there (squeeze test, 10 mm from the tip: +0.56 % at s = 1e-5 mm,
+0.15 % at 2.5e-6 mm, within 0.1 % at 1e-6 mm; plain penalty 2e-3 %).
"""

from __future__ import annotations

import functools

import numpy as np

SHIFT = 25.0  # c: the softplus is centred at g = −c s, so dp/dg jumps by only ε e⁻²⁵ at g = 0


def pressure_law(
    gap: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Contact pressure p(g) (MPa) and its derivative dp/dg (N/mm³) of the shifted softplus.

    ``penalty`` is ε (N/mm³), ``smoothing`` the width s (mm) of the regularisation (see the
    module docstring); s = 0 is the plain penalty ε ⟨−g⟩.
    """
    check_law(penalty, smoothing)
    g = np.asarray(gap, dtype=float)
    if smoothing == 0:
        return penalty * np.maximum(-g, 0.0), np.where(g < 0, -penalty, 0.0)
    closed = g < 0
    x = -np.minimum(g, 0.0) / smoothing - SHIFT
    p = penalty * smoothing * (_softplus(x) - _softplus(-SHIFT))
    dp = -penalty * 0.5 * (1.0 + np.tanh(0.5 * x))  # −ε / (1 + e⁻ˣ)
    return np.where(closed, p, 0.0), np.where(closed, dp, 0.0)


def check_law(penalty: float, smoothing: float) -> None:
    """Raise ValueError unless the penalty ε is positive and the smoothing width s ≥ 0."""
    if not (np.isfinite(penalty) and penalty > 0):
        raise ValueError(f"contact penalty must be positive, got {penalty!r}")
    if not (np.isfinite(smoothing) and smoothing >= 0):
        raise ValueError(f"contact smoothing must be >= 0 mm, got {smoothing!r}")


def _softplus(x: np.ndarray | float) -> np.ndarray:
    """ln(1 + eˣ) without overflow."""
    return np.maximum(x, 0.0) + np.log1p(np.exp(-np.abs(x)))


def _softplus_integral(x: np.ndarray | float) -> np.ndarray:
    """∫_−∞^x ln(1 + eᵗ) dt = −Li₂(−eˣ), with Li₂(z) = ``scipy.special.spence(1 − z)``.

    For x > 0 the inversion formula −Li₂(−eˣ) = π²/6 + x²/2 + Li₂(−e⁻ˣ) avoids overflowing eˣ.
    """
    from scipy.special import spence

    x = np.asarray(x, dtype=float)
    a = np.abs(x)
    low = -spence(1.0 + np.exp(-a))  # the integral at −|x|
    return np.where(x > 0, np.pi**2 / 6 + 0.5 * a**2 - low, low)


def contact_energy(gap: np.ndarray, penalty: float, smoothing: float = 0.0) -> np.ndarray:
    """Energy per unit area ∫_g^0 p(t) dt (N/mm) of :func:`pressure_law` (closed form)."""
    g = np.minimum(np.asarray(gap, dtype=float), 0.0)
    if smoothing == 0:
        return 0.5 * penalty * g**2
    s, c = smoothing, SHIFT
    return penalty * (s**2 * (_softplus_integral(-g / s - c) - _softplus_integral(-c))
                      + s * _softplus(-c) * g)


def in_contact(gap: np.ndarray, smoothing: float) -> np.ndarray:
    """Pairs reported as in contact.

    Penetration beyond (c − 5) s (stiffness above 0.7 % of ε), or g < 0 for the plain penalty.
    """
    g = np.asarray(gap)
    return g < -(SHIFT - 5.0) * smoothing if smoothing > 0 else g < 0.0


@functools.cache
def penalty_kernel():
    """The compiled penalty blocks, or None without numba.

    :func:`sandwich.beam.contact_kernel.penalty_blocks`, imported on first use.
    """
    try:
        from sandwich.beam import contact_kernel
    except ImportError:
        return None
    return contact_kernel.penalty_blocks


def penalty_blocks(
    gap: np.ndarray, grad: np.ndarray, hess: np.ndarray, area: np.ndarray, penalty: float,
    smoothing: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force −p A ∂g, tangent −A p'(g) ∂g ∂gᵀ − p A ∂²g and pressure p of each pair.

    Compiled (:func:`sandwich.beam.contact_kernel.penalty_blocks`, the same law per pair) where
    numba is, else in NumPy from :func:`pressure_law`.
    """
    kernel = penalty_kernel()
    if kernel is not None and gap.size:
        check_law(penalty, smoothing)
        return kernel(np.ascontiguousarray(gap, dtype=float),
                      np.ascontiguousarray(grad, dtype=float),
                      np.ascontiguousarray(hess, dtype=float),
                      np.ascontiguousarray(area, dtype=float), float(penalty), float(smoothing),
                      SHIFT)
    return penalty_blocks_numpy(gap, grad, hess, area, penalty, smoothing)


def penalty_blocks_numpy(
    gap: np.ndarray, grad: np.ndarray, hess: np.ndarray, area: np.ndarray, penalty: float,
    smoothing: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`penalty_blocks` in NumPy (the reference the compiled one is tested against)."""
    p, dp = pressure_law(gap, penalty, smoothing)  # eq. (41): contact pressure, MPa
    f = -(p * area)[:, None] * grad
    K = (-dp * area)[:, None, None] * grad[:, :, None] * grad[:, None, :]
    K -= (p * area)[:, None, None] * hess
    return f, K, p
