"""Internal force (eq. 19) and consistent tangent (eqs. 24-25) of the element, layer by layer.

The three layers of an element share no DOF (they meet only through the interface ties of
:mod:`sandwich.beam.constraints`), so an element's tangent is block diagonal in the layers and each
layer is integrated on its own DOFs. Everything is vectorised over elements × Gauss points.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sandwich.beam.kinematics import (
    Gradients,
    gradients,
    green_lagrange,
    strain_coefficients,
    strain_rows,
)
from sandwich.beam.layer_operators import LayerOperators


@dataclass(frozen=True)
class GeometricProducts:
    """Reference products of eq. (25) at each Gauss point, shape ``(G, n, n)``.

    ``xx = N,ηᵀN,η + M,ηᵀM,η``, ``zz = N,ξᵀN,ξ + M,ξᵀM,ξ`` and
    ``xz = N,ξᵀN,η + N,ηᵀN,ξ + M,ξᵀM,η + M,ηᵀM,ξ``; the physical ones are these times
    (2/l)², (2/h)² and (2/l)(2/h). Computed on first use (only the ``membrane_average`` tangent
    needs them; at high core levels they are large: G n² per product).
    """

    op: LayerOperators

    @staticmethod
    def _outer(A: np.ndarray, B: np.ndarray) -> np.ndarray:
        return np.einsum("ga,gb->gab", A, B)

    @cached_property
    def xx(self) -> np.ndarray:
        """N,ηᵀN,η + M,ηᵀM,η."""
        return self._outer(self.op.N_eta, self.op.N_eta) + self._outer(self.op.M_eta, self.op.M_eta)

    @cached_property
    def zz(self) -> np.ndarray:
        """N,ξᵀN,ξ + M,ξᵀM,ξ."""
        return self._outer(self.op.N_xi, self.op.N_xi) + self._outer(self.op.M_xi, self.op.M_xi)

    @cached_property
    def xz(self) -> np.ndarray:
        """N,ξᵀN,η + N,ηᵀN,ξ + M,ξᵀM,η + M,ηᵀM,ξ."""
        xz = self._outer(self.op.N_xi, self.op.N_eta) + self._outer(self.op.M_xi, self.op.M_eta)
        return xz + xz.transpose(0, 2, 1)

    @cached_property
    def stacked(self) -> np.ndarray:
        """``[xx; zz; xz]`` as one ``(3G, n²)`` matrix: the geometric part is one GEMM."""
        G, n, _ = self.xx.shape
        return np.concatenate([self.xx, self.zz, self.xz]).reshape(3 * G, n * n)


def geometric_products(op: LayerOperators) -> GeometricProducts:
    """The element-independent products of eq. (25) for one layer's rule (computed lazily)."""
    return GeometricProducts(op)


def _eta_weights(op: LayerOperators) -> np.ndarray:
    """Normalised η-weights ``(n_η, n_ξ)`` of the tensor rule (η slowest, see tensor_rule)."""
    n_xi = np.unique(op.xi).size
    n_eta = op.eta.size // n_xi
    w = op.weight.reshape(n_eta, n_xi)
    return w / w.sum(axis=0, keepdims=True)


def _eta_average(op: LayerOperators, a: np.ndarray) -> np.ndarray:
    """Gauss-weighted mean along η at each ξ of ``a`` (shape ``(E, G, ...)``), broadcast back.

    The tensor rule orders points with η slowest (:func:`~sandwich.beam.quadrature.tensor_rule`).
    """
    w = _eta_weights(op)
    n_eta, n_xi = w.shape
    shape = a.shape
    b = a.reshape(shape[0], n_eta, n_xi, *shape[2:])
    mean = np.einsum("jk,ejk...->ek...", w, b)  # (E, n_xi, ...)
    return np.broadcast_to(mean[:, None], b.shape).reshape(shape)


def _eta_average_adjoint(op: LayerOperators, c: np.ndarray) -> np.ndarray:
    """Transpose of :func:`_eta_average` on ``(E, G)``: Σ_g c_g (A b)_g = Σ_g (Aᵀc)_g b_g."""
    w = _eta_weights(op)
    n_eta, n_xi = w.shape
    total = c.reshape(c.shape[0], n_eta, n_xi).sum(axis=1)  # (E, n_xi)
    return (w[None] * total[:, None, :]).reshape(c.shape)


@dataclass(frozen=True)
class LayerState:
    """One layer of E elements at one u: what the force gave and the tangent reuses."""

    g: Gradients
    σ: np.ndarray  # (E, G, 3), second Piola-Kirchhoff (ε_x η-averaged with membrane_average)
    dV: np.ndarray  # (E, G): b l h / 4 times the Gauss weights
    scale: np.ndarray  # (E, n): l/2 on x-slope DOFs
    f: np.ndarray  # (E, n): eq. (19), on the physical DOFs


def layer_state(
    op: LayerOperators, u_e: np.ndarray, lengths: np.ndarray, width: float
) -> LayerState:
    """Strains, stresses and internal force (eq. 19) of one layer of E elements.

    The force is assembled without forming the strain variations B: with the reference rows
    R = (N,η, N,ξ, M,η, M,ξ), every row of eq. (17) is a pointwise combination of R, so
    Σ_g dV σ·B = Σ_g c(e, g)·R(g) with c the first-Piola-like coefficients below: one GEMM.
    """
    scale = op.x_slope_scale(lengths)  # u_ref = scale ⊙ u_e
    u_ref = u_e[:, op.dofs] * scale
    g = gradients(op, u_ref, lengths)
    ε = np.stack(green_lagrange(g), axis=-1)  # (E, G, 3), eq. (15)
    if op.membrane_average:  # option, not the paper: assumed ε_x = its η-mean (see LayerOperators)
        ε[..., 0] = _eta_average(op, ε[..., 0])
    σ = ε @ op.stiffness.T  # eq. (3): (σ_x, σ_z, τ), second Piola-Kirchhoff
    # b l h / 4 dξ dη of eq. (19), times the Gauss weights.
    dV = width * (0.5 * np.asarray(lengths))[:, None] * (0.5 * op.thickness) * op.weight[None, :]
    a, b, t = (dV * σ[..., i] for i in range(3))
    if op.membrane_average:  # δε_x is the η-mean of N̄ δu: move the mean onto the coefficient
        a = _eta_average_adjoint(op, a)
    ux, uz, wx, wz = g.u_x, g.u_z, g.w_x, g.w_z
    # Σ_g dV (σ_x N̄ + σ_z N̂ + τ Ñ) of eq. (19) with N̄, N̂, Ñ of eq. (17), sorted by row of R.
    c = np.concatenate([
        g.dx * (a * (1 + ux) + t * uz),  # N,η
        g.dz * (b * uz + t * (1 + ux)),  # N,ξ
        g.dx * (a * wx + t * (1 + wz)),  # M,η
        g.dz * (b * (1 + wz) + t * wx),  # M,ξ
    ], axis=1)
    f = c @ op.reference_rows
    return LayerState(g=g, σ=σ, dV=dV, scale=scale, f=f * scale)


def layer_tangent(
    op: LayerOperators, state: LayerState, products: GeometricProducts | None = None
) -> np.ndarray:
    """Consistent tangent (eqs. 24-25) of one layer at a :func:`layer_state`, ``(E, n, n)``."""
    if not op.membrane_average:
        return _pointwise_tangent(op, state)
    g, σ, dV = state.g, state.σ, state.dV
    E, G = dV.shape
    n = op.dofs.size
    B = strain_rows(op, g)  # (E, G, 3, n): N̄, N̂, Ñ of eq. (17)
    if op.membrane_average:
        B[:, :, 0, :] = _eta_average(op, B[:, :, 0, :])
    CB = op.stiffness @ B
    # eq. (24), material part: Σ_g dV Bᵀ C B.
    K = np.matmul((B * dV[:, :, None, None]).reshape(E, 3 * G, n).transpose(0, 2, 1),
                  CB.reshape(E, 3 * G, n))
    # eq. (24), geometric part with eq. (25): σ_x N̄' + σ_z N̂' + τ Ñ'. With membrane_average,
    # σ_x is constant along η, so Σ_η dV σ̄_x P.xx is exactly σ̄_x times the η-mean second
    # variation of ε̄_x: the same line serves both.
    P = products if products is not None else geometric_products(op)
    dx, dz = g.dx, g.dz
    coef = np.concatenate([dV * σ[..., 0] * dx**2, dV * σ[..., 1] * dz**2,
                           dV * σ[..., 2] * dx * dz], axis=1)  # (E, 3G)
    K += (coef @ P.stacked).reshape(E, n, n)
    scale = state.scale
    return K * scale[:, :, None] * scale[:, None, :]


def _pointwise_tangent(op: LayerOperators, state: LayerState) -> np.ndarray:
    """:func:`layer_tangent` without membrane averaging, by three large GEMMs.

    B = Φ R with R = (N,η, N,ξ, M,η, M,ξ) (:func:`~sandwich.beam.kinematics.strain_rows`), so
    eqs. (24-25) give K = Σ_g Σ_kl H_kl(e, g) R_kᵀ R_l with
    H = dV ΦᵀCΦ (material) plus the stress terms of eq. (25) on the diagonal pairs (geometric).
    N rows live on the u DOFs and M rows on the w DOFs, so the sum splits into uu, ww and uw
    blocks on precomputed products (:attr:`LayerOperators.field_products`).
    """
    g, σ, dV = state.g, state.σ, state.dV
    E, G = dV.shape
    n = op.dofs.size
    Φ = strain_coefficients(g)  # (E, G, 3, 4)
    H = Φ.transpose(0, 1, 3, 2) @ (op.stiffness @ Φ)  # (E, G, 4, 4)
    H *= dV[:, :, None, None]
    sx = dV * σ[..., 0] * g.dx**2  # eq. (25): σ_x (N,xᵀN,x + M,xᵀM,x)
    sz = dV * σ[..., 1] * g.dz**2  # σ_z (N,zᵀN,z + M,zᵀM,z)
    sxz = dV * σ[..., 2] * g.dx * g.dz  # τ (N,zᵀN,x + N,xᵀN,z + M,zᵀM,x + M,xᵀM,z)
    for k in (0, 2):  # N,η-N,ξ and M,η-M,ξ pairs
        H[..., k, k] += sx
        H[..., k + 1, k + 1] += sz
        H[..., k, k + 1] += sxz
        H[..., k + 1, k] += sxz
    Quu, Qww, Quw = op.field_products
    u = np.flatnonzero(op.u_columns)
    w = np.flatnonzero(~op.u_columns)
    K = np.empty((E, n, n))
    K[:, u[:, None], u[None, :]] = (H[:, :, :2, :2].reshape(E, 4 * G) @ Quu).reshape(
        E, u.size, u.size)
    K[:, w[:, None], w[None, :]] = (H[:, :, 2:, 2:].reshape(E, 4 * G) @ Qww).reshape(
        E, w.size, w.size)
    Kuw = (H[:, :, :2, 2:].reshape(E, 4 * G) @ Quw).reshape(E, u.size, w.size)
    K[:, u[:, None], w[None, :]] = Kuw
    K[:, w[:, None], u[None, :]] = Kuw.transpose(0, 2, 1)
    scale = state.scale
    return K * scale[:, :, None] * scale[:, None, :]


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
    state = layer_state(op, u_e, lengths, width)
    return state.f, (layer_tangent(op, state, products) if tangent else None)


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
