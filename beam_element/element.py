"""Internal force (eq. 19) and consistent tangent (eqs. 24-25) of the element, layer by layer.

The three layers of an element share no DOF (they meet only through the interface ties of
:mod:`beam_element.constraints`), so an element's tangent is block diagonal in the layers and each
layer is integrated on its own DOFs. Everything is vectorised over elements × Gauss points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from beam_element.kinematics import gradients, green_lagrange, strain_variations
from beam_element.layer_operators import LayerOperators


@dataclass(frozen=True)
class GeometricProducts:
    """Reference products of eq. (25) at each Gauss point, shape ``(G, n, n)``.

    ``xx = N,ηᵀN,η + M,ηᵀM,η``, ``zz = N,ξᵀN,ξ + M,ξᵀM,ξ`` and
    ``xz = N,ξᵀN,η + N,ηᵀN,ξ + M,ξᵀM,η + M,ηᵀM,ξ``; the physical ones are these times
    (2/l)², (2/h)² and (2/l)(2/h).
    """

    xx: np.ndarray
    zz: np.ndarray
    xz: np.ndarray


def geometric_products(op: LayerOperators) -> GeometricProducts:
    """Precompute the element-independent products of eq. (25) for one layer's rule."""

    def outer(A: np.ndarray, B: np.ndarray) -> np.ndarray:
        return np.einsum("ga,gb->gab", A, B)

    xz = outer(op.N_xi, op.N_eta) + outer(op.M_xi, op.M_eta)
    return GeometricProducts(
        xx=outer(op.N_eta, op.N_eta) + outer(op.M_eta, op.M_eta),
        zz=outer(op.N_xi, op.N_xi) + outer(op.M_xi, op.M_xi),
        xz=xz + xz.transpose(0, 2, 1),
    )


def _eta_average(op: LayerOperators, a: np.ndarray) -> np.ndarray:
    """Gauss-weighted mean along η at each ξ of ``a`` (shape ``(E, G, ...)``), broadcast back.

    The tensor rule orders points with η slowest (:func:`~beam_element.quadrature.tensor_rule`).
    """
    n_xi = np.unique(op.xi).size
    n_eta = op.eta.size // n_xi
    w = op.weight.reshape(n_eta, n_xi)
    w = w / w.sum(axis=0, keepdims=True)
    shape = a.shape
    b = a.reshape(shape[0], n_eta, n_xi, *shape[2:])
    mean = np.einsum("jk,ejk...->ek...", w, b)  # (E, n_xi, ...)
    return np.broadcast_to(mean[:, None], b.shape).reshape(shape)


def layer_response(
    op: LayerOperators,
    u_e: np.ndarray,
    lengths: np.ndarray,
    width: float,
    products: GeometricProducts | None = None,
    tangent: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Internal force and tangent of one layer of E elements.

    Parameters
    ----------
    op
        The layer's rows at its Gauss rule.
    u_e
        Element DOF vectors, shape ``(E, 40)`` (physical slopes).
    lengths
        Element lengths l (mm), shape ``(E,)``.
    width
        Beam width b (mm).
    products
        :func:`geometric_products` of ``op`` (computed if omitted).
    tangent
        Whether to compute the tangent.

    Returns
    -------
    f, K
        Force on the layer's DOFs, shape ``(E, n)`` (N, N·mm), and tangent ``(E, n, n)`` or None.
    """
    scale = op.x_slope_scale(lengths)  # u_ref = scale ⊙ u_e
    u_ref = u_e[:, op.dofs] * scale
    g = gradients(op, u_ref, lengths)
    ε = np.stack(green_lagrange(g), axis=-1)  # (E, G, 3), eq. (15)
    B = np.stack(strain_variations(op, g), axis=2)  # (E, G, 3, n): N̄, N̂, Ñ of eq. (17)
    if op.membrane_average:  # option, not the paper: assumed ε_x = its η-mean (see LayerOperators)
        ε[..., 0] = _eta_average(op, ε[..., 0])
        B[:, :, 0, :] = _eta_average(op, B[:, :, 0, :])
    σ = ε @ op.stiffness.T  # eq. (3): (σ_x, σ_z, τ), second Piola-Kirchhoff
    # b l h / 4 dξ dη of eq. (19), times the Gauss weights.
    dV = width * (0.5 * np.asarray(lengths))[:, None] * (0.5 * op.thickness) * op.weight[None, :]
    f = np.einsum("eg,egi,egia->ea", dV, σ, B)  # eq. (19)
    if not tangent:
        return f * scale, None
    E, G, _, n = B.shape
    CB = np.einsum("ij,egjb->egib", op.stiffness, B)
    # eq. (24), material part: Σ_g dV Bᵀ C B.
    K = np.matmul((B * dV[:, :, None, None]).reshape(E, 3 * G, n).transpose(0, 2, 1),
                  CB.reshape(E, 3 * G, n))
    # eq. (24), geometric part with eq. (25): σ_x N̄' + σ_z N̂' + τ Ñ'. With membrane_average,
    # σ_x is constant along η, so Σ_η dV σ̄_x P.xx is exactly σ̄_x times the η-mean second
    # variation of ε̄_x: the same line serves both.
    P = products if products is not None else geometric_products(op)
    dx, dz = g.dx, g.dz
    K += np.einsum("eg,gab->eab", dV * σ[..., 0] * dx**2, P.xx)
    K += np.einsum("eg,gab->eab", dV * σ[..., 1] * dz**2, P.zz)
    K += np.einsum("eg,gab->eab", dV * σ[..., 2] * dx * dz, P.xz)
    return f * scale, K * scale[:, :, None] * scale[:, None, :]


def layer_energy(
    op: LayerOperators, u_e: np.ndarray, lengths: np.ndarray, width: float
) -> np.ndarray:
    """Strain energy ½ ∫ σ·ε dV of one layer per element (N·mm), shape ``(E,)``."""
    u_ref = u_e[:, op.dofs] * op.x_slope_scale(lengths)
    g = gradients(op, u_ref, lengths)
    ε = np.stack(green_lagrange(g), axis=-1)
    if op.membrane_average:
        ε[..., 0] = _eta_average(op, ε[..., 0])
    σ = ε @ op.stiffness.T
    dV = width * (0.5 * np.asarray(lengths))[:, None] * (0.5 * op.thickness) * op.weight[None, :]
    return 0.5 * np.einsum("eg,egi,egi->e", dV, σ, ε)
