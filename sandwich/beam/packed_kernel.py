"""The packed layer kernel: force (eq. 19) and tangent (eqs. 24-25) of a layer in one pass.

The same mechanics as :mod:`sandwich.beam.element` (the NumPy reference, kept and tested
against this file), evaluated by a numba kernel that loops once over elements × Gauss points
and, per point, forms the gradients (eq. 15), the Green-Lagrange strains and the second
Piola-Kirchhoff stresses, adds the point's share of the force and, if asked, of the tangent:

- B = Φ R with R = (N,η, N,ξ, M,η, M,ξ) the reference rows (eq. 17, see
  :func:`sandwich.beam.kinematics.strain_coefficients`), so K = Σ_g Σ_kl H_kl R_kᵀ R_l with the
  4×4 matrix H = dV ΦᵀCΦ (material part, eq. 24) plus the stresses of eq. (25) on its
  (N,η N,η), (N,ξ N,ξ), (N,η N,ξ) pairs and their M twins (geometric part);
- N rows vanish off the layer's u columns and M rows off its w columns
  (:attr:`~sandwich.beam.layer_operators.LayerOperators.u_columns`), so K splits into uu, ww and
  uw blocks; uu and ww are symmetric and only their upper triangles are accumulated.

Everything is generic in the layer's DOF count n and point count G, read from the
:class:`~sandwich.beam.layer_operators.LayerOperators` arrays (rows, ``u_columns``, stiffness,
weights, dofs): a layer with more DOFs or a composite rule needs no change here. The only
per-call memory is the output; per-element work arrays have the size of one element's blocks.
Which kernel evaluates a layer (this one, the averaged faces' or the sum-factorised cores') is
decided by :mod:`sandwich.beam.kernels`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np

from sandwich.beam.kernel_blocks import (
    emit_block,
    force_coefficients,
    open_block,
    packed_tangents,
    point_gradients,
    scatter_force,
    strain_factors,
    unpack_element,
)
from sandwich.beam.layer_operators import LayerOperators
from sandwich.solver.jit import njit

__all__ = ["CHUNK", "KernelOperators", "PackedProducts", "kernel_operators", "packed_kernel",
           "point_flops"]


@dataclass(frozen=True)
class KernelOperators:
    """A layer's rows in the layout of the kernel (computed once per layer).

    With R_k (k = N,η N,ξ M,η M,ξ) the reference rows at point g, H the symmetric 4×4 point
    matrix and the field split, the element tangent is

        K_uu[a ≤ b] = Σ_g H00 N0a N0b + H11 N1a N1b + H01 (N0a N1b + N1a N0b)   (Quu rows)
        K_ww[a ≤ b] = the same with (M, H22, H33, H23)                          (Qww rows)
        K_uw[a, b]  = Σ_g Σ_{k ∈ N, l ∈ M} H_kl N_ka M_lb                       (Quw rows)

    so over a block of elements it is a product (elements × 3G) · (3G × packed pairs): one
    BLAS GEMM per field pair, with Q element-independent.
    """

    NuT: np.ndarray  # (n_u, 2G): [N,η | N,ξ]ᵀ on the u columns (gradients: U @ NuT)
    MwT: np.ndarray  # (n_w, 2G)
    Nu: np.ndarray  # (2G, n_u): force f_u = c @ Nu
    Mw: np.ndarray  # (2G, n_w)
    ucols: np.ndarray  # (n_u,) positions of the u columns in the layer's DOFs
    wcols: np.ndarray  # (n_w,)
    dofs: np.ndarray  # (n,) element-local DOF indices
    x_slope: np.ndarray  # (n,) bool
    weight: np.ndarray  # (G,)
    stiffness: np.ndarray  # (3, 3)
    thickness: float

    @cached_property
    def packed(self) -> PackedProducts:
        """The packed products Q, formed on first use.

        A layer the sum-factorised kernel evaluates (core levels 2-4) never needs them (level 3:
        4.5 MB per layer).
        """
        G = self.weight.size
        N0, N1, M0, M1 = self.Nu[:G], self.Nu[G:], self.Mw[:G], self.Mw[G:]
        (Quu, pu), (Qww, pw) = (_packed_products(N0, N1, N0, N1, True),
                                _packed_products(M0, M1, M0, M1, True))
        return PackedProducts(Quu, Qww, _packed_products(N0, N1, M0, M1, False)[0], pu, pw)


class PackedProducts(NamedTuple):
    """Rows of Q for the three field pairs (:class:`KernelOperators`) and the packed pairs."""

    Quu: np.ndarray  # (3G, n_u (n_u + 1) / 2), rows (00 | 11 | 01) per point
    Qww: np.ndarray  # (3G, n_w (n_w + 1) / 2), rows (22 | 33 | 23)
    Quw: np.ndarray  # (4G, n_u n_w), rows (02 | 03 | 12 | 13)
    pu: np.ndarray  # (2, n_u (n_u + 1) / 2): (a, b) of each packed uu pair, a ≤ b
    pw: np.ndarray  # (2, n_w (n_w + 1) / 2)



def _packed_products(A0, A1, B0, B1, symmetric):
    """Rows of Q for one field pair: per point, the products of the k- and l-rows."""
    if symmetric:
        a, b = np.triu_indices(A0.shape[1])
        q = [A0[:, a] * A0[:, b], A1[:, a] * A1[:, b],
             A0[:, a] * A1[:, b] + A1[:, a] * A0[:, b]]
        return np.ascontiguousarray(np.concatenate(q)), np.array([a, b], dtype=np.int64)
    q = [(X[:, :, None] * Y[:, None, :]).reshape(X.shape[0], -1)
         for X, Y in ((A0, B0), (A0, B1), (A1, B0), (A1, B1))]
    return np.ascontiguousarray(np.concatenate(q)), None


def kernel_operators(op: LayerOperators) -> KernelOperators:
    """The kernel's arrays for ``op``, cached on the operator."""
    cached = op.__dict__.get("_kernel_operators")
    if cached is not None:
        return cached
    u = np.asarray(op.u_columns, dtype=bool)
    ucols, wcols = np.flatnonzero(u), np.flatnonzero(~u)
    # Rows must vanish off their field's columns for the uu/ww/uw split to be exact.
    if np.any(op.N_eta[:, wcols]) or np.any(op.N_xi[:, wcols]) or np.any(
            op.M_eta[:, ucols]) or np.any(op.M_xi[:, ucols]):
        raise ValueError(f"{op.name}: N rows must vanish on w columns and M rows on u columns")
    N0, N1 = op.N_eta[:, ucols], op.N_xi[:, ucols]
    M0, M1 = op.M_eta[:, wcols], op.M_xi[:, wcols]
    Nu = np.ascontiguousarray(np.concatenate([N0, N1]))
    Mw = np.ascontiguousarray(np.concatenate([M0, M1]))
    k = KernelOperators(
        NuT=np.ascontiguousarray(Nu.T), MwT=np.ascontiguousarray(Mw.T), Nu=Nu, Mw=Mw,
        ucols=ucols.astype(np.int64), wcols=wcols.astype(np.int64),
        dofs=np.asarray(op.dofs, dtype=np.int64), x_slope=np.asarray(op.x_slope, dtype=np.bool_),
        weight=np.ascontiguousarray(op.weight, dtype=float),
        stiffness=np.ascontiguousarray(op.stiffness, dtype=float), thickness=float(op.thickness),
    )
    object.__setattr__(op, "_kernel_operators", k)
    return k


def point_flops(op: LayerOperators, tangent: bool = True) -> int:
    """Floating-point operations per Gauss point of the kernel's GEMMs (multiply + add = 2).

    Force: the 4 gradients and the force from the 4 row coefficients, 2·2(n_u + n_w) each.
    Tangent: per point 3 (uu) + 3 (ww) + 4 (uw) rows of Q times their packed pairs. The O(1)
    per-point work (strains, stresses, H: ~150 flops) and the scatter are left out.
    """
    nu = int(np.count_nonzero(op.u_columns))
    nw = int(op.dofs.size - nu)
    f = 2 * 2 * 2 * (nu + nw)
    if not tangent:
        return f
    return f + 2 * (3 * nu * (nu + 1) // 2 + 3 * nw * (nw + 1) // 2 + 4 * nu * nw)


CHUNK = 128  # elements per block: the block's work arrays stay in cache


@njit
def packed_kernel(u_l, lengths, width, NuT, MwT, Nu, Mw, Quu, Qww, Quw, pu, pw, ucols, wcols,
            x_slope, weight, C, thickness, f_out, want_k, K_out, slots, signs,
            data):  # pragma: no cover - compiled
    """Force into ``f_out`` (E, n); tangent into ``K_out`` (E, n, n) or ``data[slots]``.

    ``u_l`` (E, n) holds each element's values of the layer's DOFs (physical slopes).
    """
    E = u_l.shape[0]
    G = weight.size
    n = x_slope.size
    dz = 2.0 / thickness
    c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
    c10, c11, c12 = C[1, 0], C[1, 1], C[1, 2]
    c20, c21, c22 = C[2, 0], C[2, 1], C[2, 2]
    for e0 in range(0, E, CHUNK):
        ec = min(CHUNK, E - e0)
        scale, Du, Dw, Cu, Cw, Huu, Hww, Huw = open_block(u_l, lengths, e0, ec, x_slope, ucols,
                                                          wcols, NuT, MwT, want_k)
        for i in range(ec):
            dx = 2.0 / lengths[e0 + i]
            dV0 = width * (0.5 * lengths[e0 + i]) * (0.5 * thickness)  # b l h / 4, eq. (19)
            for g in range(G):
                ux, uz, wx, wz = point_gradients(Du, Dw, i, g, dx, dz)  # eq. (15)
                ex = ux + 0.5 * (ux * ux + wx * wx)  # Green-Lagrange, eq. (15)
                ez = wz + 0.5 * (uz * uz + wz * wz)
                gm = uz + wx + ux * uz + wx * wz
                dV = dV0 * weight[g]
                sa = dV * (c00 * ex + c01 * ez + c02 * gm)  # dV σ, eq. (3)
                sb = dV * (c10 * ex + c11 * ez + c12 * gm)
                st = dV * (c20 * ex + c21 * ez + c22 * gm)
                # eq. (19): Σ_g dV σ·B = Σ_g c·R, the rows of eq. (17) sorted by R
                Cu[i, g], Cu[i, G + g], Cw[i, g], Cw[i, G + g] = force_coefficients(
                    dx, dz, sa, sb, st, ux, uz, wx, wz)
                if not want_k:
                    continue
                # Φ (B = Φ R, eq. 17)
                p00, p02, p11, p13, p20, p21, p22, p23 = strain_factors(dx, dz, ux, uz, wx, wz)
                a00 = c00 * p00 + c02 * p20  # CΦ
                a01 = c01 * p11 + c02 * p21
                a02 = c00 * p02 + c02 * p22
                a03 = c01 * p13 + c02 * p23
                a11 = c11 * p11 + c12 * p21
                a12 = c10 * p02 + c12 * p22
                a13 = c11 * p13 + c12 * p23
                a20 = c20 * p00 + c22 * p20
                a21 = c21 * p11 + c22 * p21
                a22 = c20 * p02 + c22 * p22
                a23 = c21 * p13 + c22 * p23
                sx = sa * dx * dx  # eq. (25): σ_x (N,xᵀN,x + M,xᵀM,x)
                sz = sb * dz * dz  # σ_z (N,zᵀN,z + M,zᵀM,z)
                sxz = st * dx * dz  # τ (N,zᵀN,x + N,xᵀN,z + M,zᵀM,x + M,xᵀM,z)
                # H = dV Φᵀ C Φ (eq. 24) + the stress terms (eq. 25)
                Huu[i, g] = dV * (p00 * a00 + p20 * a20) + sx  # H00
                Huu[i, G + g] = dV * (p11 * a11 + p21 * a21) + sz  # H11
                Huu[i, 2 * G + g] = dV * (p00 * a01 + p20 * a21) + sxz  # H01
                Hww[i, g] = dV * (p02 * a02 + p22 * a22) + sx  # H22
                Hww[i, G + g] = dV * (p13 * a13 + p23 * a23) + sz  # H33
                Hww[i, 2 * G + g] = dV * (p02 * a03 + p22 * a23) + sxz  # H23
                Huw[i, g] = dV * (p00 * a02 + p20 * a22)  # H02
                Huw[i, G + g] = dV * (p00 * a03 + p20 * a23)  # H03
                Huw[i, 2 * G + g] = dV * (p11 * a12 + p21 * a22)  # H12
                Huw[i, 3 * G + g] = dV * (p11 * a13 + p21 * a23)  # H13
        scatter_force(np.dot(Cu, Nu), np.dot(Cw, Mw), e0, ucols, wcols, scale, f_out)
        if not want_k:
            continue
        Kuu, Kww, Kuw = packed_tangents(Huu, Hww, Huw, Quu, Qww, Quw)
        Ke = np.empty((n, n))
        for i in range(ec):
            # every entry (physical: scaled) into the element's dense block, then out
            unpack_element(i, Kuu, Kww, Kuw, pu, pw, ucols, wcols, scale, Ke)
            emit_block(e0 + i, Ke, K_out, slots, signs, data)
