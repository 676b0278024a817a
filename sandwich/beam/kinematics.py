"""Displacement gradients, Green-Lagrange strains and their variations (eqs. 2, 14-17).

Arrays are vectorised over elements × points: gradients have shape ``(E, G)``, strain-variation
rows ``(E, G, n)`` on the layer's DOFs. The element DOF vector passed in is the *reference* one
(x-slopes scaled by l/2, see :mod:`sandwich.beam.layer_operators`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.beam.layer_operators import LayerOperators


@dataclass(frozen=True)
class Gradients:
    """u,x  u,z  w,x  w,z at every (element, point), and the chain-rule factors 2/l, 2/h."""

    u_x: np.ndarray
    u_z: np.ndarray
    w_x: np.ndarray
    w_z: np.ndarray
    dx: np.ndarray  # 2/l per element, shape (E, 1): N,x = (2/l) N,η   (eq. 14, corrected)
    dz: float  # 2/h: N,z = (2/h) N,ξ


def gradients(op: LayerOperators, u_ref: np.ndarray, lengths: np.ndarray) -> Gradients:
    """Displacement gradients of eq. (15): N,x u_e, N,z u_e, M,x u_e, M,z u_e."""
    dx = (2.0 / np.asarray(lengths, dtype=float))[:, None]
    dz = 2.0 / op.thickness
    G = op.eta.size
    d = u_ref @ op.reference_rows.T  # (E, 4G): N,η u  N,ξ u  M,η u  M,ξ u in one GEMM
    return Gradients(
        u_x=dx * d[:, :G],
        u_z=dz * d[:, G:2 * G],
        w_x=dx * d[:, 2 * G:3 * G],
        w_z=dz * d[:, 3 * G:],
        dx=dx,
        dz=dz,
    )


def green_lagrange(g: Gradients) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Green-Lagrange strains (ε_x, ε_z, γ), eqs. (2) and (15).

    For a face w,z = 0, so the core formulas reduce to the face ones (its ε_z carries no stress).
    """
    ε_x = g.u_x + 0.5 * (g.u_x**2 + g.w_x**2)  # eq. (15)
    ε_z = g.w_z + 0.5 * (g.u_z**2 + g.w_z**2)  # eq. (15), core
    γ = g.u_z + g.w_x + g.u_x * g.u_z + g.w_x * g.w_z  # eq. (15)
    return ε_x, ε_z, γ


def linear_strains(g: Gradients) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Small-strain part of eq. (15): (u,x, w,z, u,z + w,x)."""
    return g.u_x, g.w_z, g.u_z + g.w_x


def derivative_rows(op: LayerOperators, g: Gradients) -> dict[str, np.ndarray]:
    """N,x  N,z  M,x  M,z per element and point, shape ``(E, G, n)`` (eq. 14, corrected)."""
    dx = g.dx[:, :, None]
    return {
        "N_x": dx * op.N_eta[None],
        "N_z": g.dz * op.N_xi[None],
        "M_x": dx * op.M_eta[None],
        "M_z": g.dz * op.M_xi[None],
    }


def strain_variations(
    op: LayerOperators, g: Gradients
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows N̄, N̂, Ñ with δε_x = N̄ δu_e, δε_z = N̂ δu_e, δγ = Ñ δu_e, eqs. (16-17)."""
    d = derivative_rows(op, g)
    ux, uz, wx, wz = (a[:, :, None] for a in (g.u_x, g.u_z, g.w_x, g.w_z))
    N_bar = d["N_x"] * (1 + ux) + d["M_x"] * wx  # eq. (17)
    N_hat = d["M_z"] * (1 + wz) + d["N_z"] * uz  # eq. (17)
    N_tilde = d["N_z"] * (1 + ux) + d["M_x"] * (1 + wz) + d["N_x"] * uz + d["M_z"] * wx  # eq. (17)
    return N_bar, N_hat, N_tilde


def strain_rows(op: LayerOperators, g: Gradients) -> np.ndarray:
    """The rows of :func:`strain_variations` stacked, shape ``(E, G, 3, n)``, by one batched GEMM.

    Each row of eq. (17) is a pointwise combination of the reference rows
    R = (N,η, N,ξ, M,η, M,ξ): B(e, g) = Φ(e, g) R(g) with Φ of shape (3, 4).
    """
    return strain_coefficients(g) @ op.reference_rows_by_point


def strain_coefficients(g: Gradients) -> np.ndarray:
    """Φ of :func:`strain_rows`, shape ``(E, G, 3, 4)``: B(e, g) = Φ(e, g) R(g)."""
    E, G = g.u_x.shape
    dx = np.broadcast_to(g.dx, (E, G))
    dz = g.dz
    ux, uz, wx, wz = g.u_x, g.u_z, g.w_x, g.w_z
    Φ = np.zeros((E, G, 3, 4))
    Φ[..., 0, 0] = dx * (1 + ux)  # N̄ = N,x (1 + u,x) + M,x w,x
    Φ[..., 0, 2] = dx * wx
    Φ[..., 1, 3] = dz * (1 + wz)  # N̂ = M,z (1 + w,z) + N,z u,z
    Φ[..., 1, 1] = dz * uz
    Φ[..., 2, 0] = dx * uz  # Ñ = N,z (1 + u,x) + M,x (1 + w,z) + N,x u,z + M,z w,x
    Φ[..., 2, 1] = dz * (1 + ux)
    Φ[..., 2, 2] = dx * (1 + wz)
    Φ[..., 2, 3] = dz * wx
    return Φ
