"""The contact gap along the slave's deformed normal (eq. 42), with its derivatives.

Same-x pairs. The slave boundary's deformed tangent is t ∝ (1 + u_c,x, w_c,x), its outward
normal n = s_n (−w_c,x, 1 + u_c,x)/ℓ with ℓ = |(1 + u_c,x, w_c,x)| and s_n = +1 on the core's
top, −1 on its bottom, i.e. n = s_n(−sin β, cos β) with β the slope angle of eq. (42). With the
displacement jump Δ = (u_face − u_core, w_face − w_core) (face and core surfaces coincide in the
reference state),

    g = n · Δ = s_n (−w_c,x Δu + (1 + u_c,x) Δw) / ℓ,

which is eq. (41)'s w̄_face − w̄_core. g < 0 is penetration. A closest-point pair's gap is the
same expression with Δ → r and (1 + u_c,x, w_c,x) → X_ξ (:mod:`sandwich.beam.contact_projection`):
:func:`gap_derivatives` serves both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.beam.contact_search import NORMAL_SIGN, ContactPairs

# d(Δu, Δw, a = 1 + u_c,x, c = w_c,x) / d(pair DOFs): the chain from gap variables to DOFs.
_D = np.array([
    [1.0, 0.0, -1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, -1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
])



@dataclass(frozen=True)
class PairKinematics:
    """Gap g, its gradient and Hessian on the pair's block DOFs, and the tangential sliding."""

    gap: np.ndarray  # (m,) mm, negative = penetration
    grad: np.ndarray  # (m, n) on ContactPairs.block_dofs
    hess: np.ndarray  # (m, n, n)
    sliding: np.ndarray  # (m,) mm
    xi: np.ndarray | None = None  # (m,) closest point's coordinate on its segment, [0, 1]
    segment: np.ndarray | None = None  # (m,) chosen segment (local index)
    outside: np.ndarray | None = None  # (m,) bool: no searched segment holds the projection


def gap_derivatives(
    r1: np.ndarray, r2: np.ndarray, a: np.ndarray, c: np.ndarray, s_n: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap g = s_n (a r2 − c r1)/√(a² + c²) with gradient and Hessian in (r1, r2, a, c)."""
    ℓ = np.sqrt(a**2 + c**2)
    q = -c * r1 + a * r2  # ℓ n·r / s_n
    z = np.zeros_like(ℓ)
    dq = np.stack([-c, a, r2, -r1], axis=-1)
    dℓ = np.stack([z, z, a / ℓ, c / ℓ], axis=-1)
    d2q = np.zeros((*ℓ.shape, 4, 4))
    d2q[..., 0, 3] = d2q[..., 3, 0] = -1.0
    d2q[..., 1, 2] = d2q[..., 2, 1] = 1.0
    d2ℓ = np.zeros((*ℓ.shape, 4, 4))
    d2ℓ[..., 2, 2], d2ℓ[..., 3, 3] = c**2 / ℓ**3, a**2 / ℓ**3
    d2ℓ[..., 2, 3] = d2ℓ[..., 3, 2] = -a * c / ℓ**3
    ℓ1, q1 = ℓ[..., None], q[..., None]
    dg = s_n * (dq / ℓ1 - q1 * dℓ / ℓ1**2)
    cross = dq[..., :, None] * dℓ[..., None, :]
    d2g = s_n * (
        d2q / ℓ1[..., None]
        - (cross + np.swapaxes(cross, -1, -2)) / (ℓ1**2)[..., None]
        - (q1 / ℓ1**2)[..., None] * d2ℓ
        + (2 * q1 / ℓ1**3)[..., None] * dℓ[..., :, None] * dℓ[..., None, :]
    )
    return s_n * q / ℓ, dg, d2g


def sliding_derivatives(
    r1: np.ndarray, r2: np.ndarray, a: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sliding s = (a r1 + c r2)/√(a² + c²) with gradient and Hessian in (r1, r2, a, c).

    The jump's component along the slave's deformed tangent (the cohesive law's mode II
    jump, :mod:`sandwich.beam.cohesive`).
    """
    ℓ = np.sqrt(a**2 + c**2)
    q = a * r1 + c * r2
    z = np.zeros_like(ℓ)
    dq = np.stack([a, c, r1, r2], axis=-1)
    dℓ = np.stack([z, z, a / ℓ, c / ℓ], axis=-1)
    d2q = np.zeros((*ℓ.shape, 4, 4))
    d2q[..., 0, 2] = d2q[..., 2, 0] = 1.0
    d2q[..., 1, 3] = d2q[..., 3, 1] = 1.0
    d2ℓ = np.zeros((*ℓ.shape, 4, 4))
    d2ℓ[..., 2, 2], d2ℓ[..., 3, 3] = c**2 / ℓ**3, a**2 / ℓ**3
    d2ℓ[..., 2, 3] = d2ℓ[..., 3, 2] = -a * c / ℓ**3
    ℓ1, q1 = ℓ[..., None], q[..., None]
    ds = dq / ℓ1 - q1 * dℓ / ℓ1**2
    cross = dq[..., :, None] * dℓ[..., None, :]
    d2s = (d2q / ℓ1[..., None]
           - (cross + np.swapaxes(cross, -1, -2)) / (ℓ1**2)[..., None]
           - (q1 / ℓ1**2)[..., None] * d2ℓ
           + (2 * q1 / ℓ1**3)[..., None] * dℓ[..., :, None] * dℓ[..., None, :])
    return q / ℓ, ds, d2s


def same_x_sliding(
    pairs: ContactPairs, u_full: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sliding of same-x pairs with its gradient and Hessian on their six DOFs (PAIR_ROLES)."""
    v = u_full[pairs.dofs[:, :6]]
    s, ds, d2s = sliding_derivatives(v[:, 0] - v[:, 2], v[:, 1] - v[:, 3], 1.0 + v[:, 4],
                                     v[:, 5])
    return s, ds @ _D, _D.T @ d2s @ _D


def same_x_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> PairKinematics:
    """Gap of same-x pairs with its derivatives on their six DOFs (PAIR_ROLES), and the sliding."""
    v = u_full[pairs.dofs[:, :6]]  # (m, 6)
    Δu, Δw = v[:, 0] - v[:, 2], v[:, 1] - v[:, 3]
    a, c = 1.0 + v[:, 4], v[:, 5]  # slave tangent (1 + u_c,x, w_c,x)
    gap, dg, d2g = gap_derivatives(Δu, Δw, a, c, NORMAL_SIGN[pairs.interface])
    sliding = (a * Δu + c * Δw) / np.sqrt(a**2 + c**2)
    return PairKinematics(gap, dg @ _D, _D.T @ d2g @ _D, sliding)  # Dᵀ (d²g) D per pair
