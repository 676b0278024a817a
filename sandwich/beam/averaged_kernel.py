"""Compiled force (eq. 19) and tangent (eqs. 24-25) of a layer with the averaged membrane strain.

The option ``membrane_average`` of :class:`~sandwich.beam.layer_operators.LayerOperators` (not
the paper's element; the faces' default, docs/beam_element.md "face_membrane=averaged") replaces
ε_x at every Gauss point by its Gauss-weighted mean along η at the same ξ. The NumPy reference
is :func:`sandwich.beam.element.layer_state` / :func:`~sandwich.beam.element.layer_tangent`; this
kernel evaluates the same mechanics in one pass over elements × points:

- force: ε̄_x(ξ) = Σ_η w̄_η ε_x(η, ξ) (w̄ the η-weights normalised at each ξ), σ = C (ε̄_x, ε_z, γ);
  δε̄_x is the η-mean of N̄ δu, so the force's σ_x coefficient dV σ_x is replaced by the adjoint
  of the mean, w̄_η Σ_η' dV σ_x(η', ξ) (:func:`sandwich.beam.element._eta_average_adjoint`);
- tangent, material part Σ_g dV B̄ᵀ C B̄ with B̄ = (B̄_x, N̂, Ñ): the (z, γ) × (z, γ) part is
  pointwise and goes through the packed H_kl R_kᵀR_l GEMMs of :mod:`sandwich.beam.kernels`
  (with the x row of Φ left out of H); the parts with B̄_x couple the η points of one ξ and
  are, per ξ, the rank-2 update b zᵀ + z bᵀ with b = B̄_x(ξ) (an n-vector, constant along η),
  y = Σ_η dV (C_xz N̂ + C_xγ Ñ) and z = ½ C_xx (Σ_η dV) b + y (C symmetric, checked by
  :func:`averaging_weights`);
- tangent, geometric part (eq. 25): Σ_η dV σ̄_x P_xx is σ̄_x times the η-mean of the second
  variation of ε_x, i.e. the paper's pointwise term with σ̄_x (weights separable), as in NumPy.

The arrays are those of :class:`sandwich.beam.packed_kernel.KernelOperators` plus the normalised
η-weights; like the packed kernel, everything is generic in the layer's DOF count.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam import kernel_blocks as kb
from sandwich.beam.layer_operators import LayerOperators
from sandwich.solver.jit import njit

__all__ = ["averaged_kernel", "averaging_weights"]

CHUNK = 128  # elements per block, as in sandwich.beam.kernels


def averaging_weights(op: LayerOperators) -> np.ndarray | None:
    """Normalised η-weights ``(n_η, n_ξ)`` the kernel averages with, or None if it cannot.

    The kernel needs what :func:`sandwich.beam.element._eta_average` assumes, checked here: a
    tensor rule with η slowest (the same ξ in every η row, one η per row), weights separable
    (w = w_η w_ξ, so the geometric part is pointwise in σ̄_x), and a symmetric stiffness (the
    rank-2 update of the module docstring). None sends the layer to the NumPy path.
    """
    cached = op.__dict__.get("_averaging_weights", False)
    if cached is not False:
        return cached
    w = None
    xi = np.unique(op.xi)
    G = op.eta.size
    if xi.size and G % xi.size == 0:
        n_eta, n_xi = G // xi.size, xi.size
        eta = op.eta.reshape(n_eta, n_xi)
        W = op.weight.reshape(n_eta, n_xi)
        tensor = (np.all(op.xi.reshape(n_eta, n_xi) == op.xi[None, :n_xi])
                  and np.all(eta == eta[:, :1]) and np.all(W > 0))
        C = np.asarray(op.stiffness, dtype=float)
        if tensor:
            w_eta, w_xi = W[:, 0] / W[0, 0], W[0]
            separable = np.allclose(W, w_eta[:, None] * w_xi[None, :], rtol=1e-14, atol=0)
            if separable and np.array_equal(C, C.T):
                w = np.ascontiguousarray(W / W.sum(axis=0, keepdims=True))
    object.__setattr__(op, "_averaging_weights", w)
    return w


@njit
def averaged_kernel(u_l, lengths, width, NuT, MwT, Nu, Mw, Quu, Qww, Quw, pu, pw, ucols, wcols,
                    x_slope, weight, wbar, C, thickness, f_out, want_k, K_out, slots, signs,
                    data):  # pragma: no cover - compiled
    """:func:`~sandwich.beam.packed_kernel.packed_kernel` with ε_x averaged along η by ``wbar``.

    ``wbar`` is (n_η, n_ξ). Points are ordered η slowest: g = j n_ξ + k for η index j and ξ index k.
    """
    E = u_l.shape[0]
    G = weight.size
    n_eta, n_xi = wbar.shape
    n = x_slope.size
    dz = 2.0 / thickness
    c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
    c11, c12 = C[1, 1], C[1, 2]
    c21, c22 = C[2, 1], C[2, 2]
    ex = np.empty(G)
    ez = np.empty(G)
    gm = np.empty(G)
    sa = np.empty(G)
    exbar = np.empty(n_xi)
    sasum = np.empty(n_xi)
    bx = np.empty((n_xi, n))  # B̄_x(ξ) on the layer's columns (reference DOFs)
    yz = np.empty((n_xi, n))  # Σ_η dV (C_xz N̂ + C_xγ Ñ), then z = ½ C_xx W b + y
    for e0 in range(0, E, CHUNK):
        ec = min(CHUNK, E - e0)
        scale, Du, Dw, Cu, Cw, Huu, Hww, Huw = kb.open_block(u_l, lengths, e0, ec, x_slope, ucols,
                                                          wcols, NuT, MwT, want_k)
        Kx = np.empty((ec if want_k else 0, n_xi, 2, n))  # per element and ξ: b and z
        for i in range(ec):
            dx = 2.0 / lengths[e0 + i]
            dV0 = width * (0.5 * lengths[e0 + i]) * (0.5 * thickness)  # b l h / 4, eq. (19)
            for g in range(G):
                ux, uz, wx, wz = kb.point_gradients(Du, Dw, i, g, dx, dz)  # eq. (15)
                ex[g] = ux + 0.5 * (ux * ux + wx * wx)  # Green-Lagrange, eq. (15)
                ez[g] = wz + 0.5 * (uz * uz + wz * wz)
                gm[g] = uz + wx + ux * uz + wx * wz
            for k in range(n_xi):  # ε̄_x: the Gauss-weighted η-mean at each ξ
                s = 0.0
                for j in range(n_eta):
                    s += wbar[j, k] * ex[j * n_xi + k]
                exbar[k] = s
                sasum[k] = 0.0
            for g in range(G):
                k = g % n_xi
                sa[g] = weight[g] * dV0 * (c00 * exbar[k] + c01 * ez[g] + c02 * gm[g])
                sasum[k] += sa[g]
            if want_k:
                for k in range(n_xi):
                    for a in range(n):
                        bx[k, a] = 0.0
                        yz[k, a] = 0.0
            for g in range(G):
                j = g // n_xi
                k = g % n_xi
                ux, uz, wx, wz = kb.point_gradients(Du, Dw, i, g, dx, dz)
                dV = dV0 * weight[g]
                e_x = exbar[k]
                sb = dV * (C[1, 0] * e_x + c11 * ez[g] + c12 * gm[g])  # dV σ, eq. (3)
                st = dV * (C[2, 0] * e_x + c21 * ez[g] + c22 * gm[g])
                sadj = wbar[j, k] * sasum[k]  # adjoint of the η-mean on dV σ_x
                # eq. (19): Σ_g dV σ·B̄ = Σ_g c·R, σ_x's coefficient moved by the adjoint
                Cu[i, g], Cu[i, G + g], Cw[i, g], Cw[i, G + g] = kb.force_coefficients(
                    dx, dz, sadj, sb, st, ux, uz, wx, wz)
                if not want_k:
                    continue
                # Φ (B = Φ R, eq. 17)
                p00, p02, p11, p13, p20, p21, p22, p23 = kb.strain_factors(dx, dz, ux, uz, wx, wz)
                # (z, γ) rows of CΦ restricted to the (z, γ) rows of Φ: pointwise part of eq. (24)
                a11 = c11 * p11 + c12 * p21
                a12 = c12 * p22
                a13 = c11 * p13 + c12 * p23
                a20 = c22 * p20
                a21 = c21 * p11 + c22 * p21
                a22 = c22 * p22
                a23 = c21 * p13 + c22 * p23
                sx = sa[g] * dx * dx  # eq. (25) with σ̄_x: σ̄_x (N,xᵀN,x + M,xᵀM,x)
                sz = sb * dz * dz
                sxz = st * dx * dz
                Huu[i, g] = dV * (p20 * a20) + sx  # H00
                Huu[i, G + g] = dV * (p11 * a11 + p21 * a21) + sz  # H11
                Huu[i, 2 * G + g] = dV * (p20 * a21) + sxz  # H01
                Hww[i, g] = dV * (p22 * a22) + sx  # H22
                Hww[i, G + g] = dV * (p13 * a13 + p23 * a23) + sz  # H33
                Hww[i, 2 * G + g] = dV * (p22 * a23) + sxz  # H23
                Huw[i, g] = dV * (p20 * a22)  # H02
                Huw[i, G + g] = dV * (p20 * a23)  # H03
                Huw[i, 2 * G + g] = dV * (p11 * a12 + p21 * a22)  # H12
                Huw[i, 3 * G + g] = dV * (p11 * a13 + p21 * a23)  # H13
                # B̄_x(ξ) = Σ_η w̄ (p00 N,η + p02 M,η) and y(ξ) = Σ_η dV (C_xz N̂ + C_xγ Ñ)
                wb = wbar[j, k]
                yn0 = dV * c02 * p20
                yn1 = dV * (c01 * p11 + c02 * p21)
                ym0 = dV * c02 * p22
                ym1 = dV * (c01 * p13 + c02 * p23)
                for a in range(ucols.size):
                    col = ucols[a]
                    bx[k, col] += wb * p00 * Nu[g, a]
                    yz[k, col] += yn0 * Nu[g, a] + yn1 * Nu[G + g, a]
                for b in range(wcols.size):
                    col = wcols[b]
                    bx[k, col] += wb * p02 * Mw[g, b]
                    yz[k, col] += ym0 * Mw[g, b] + ym1 * Mw[G + g, b]
            if want_k:
                for k in range(n_xi):
                    W = 0.0  # Σ_η dV at this ξ
                    for j in range(n_eta):
                        W += dV0 * weight[j * n_xi + k]
                    for a in range(n):
                        Kx[i, k, 0, a] = bx[k, a] * scale[i, a]
                        Kx[i, k, 1, a] = (0.5 * c00 * W * bx[k, a] + yz[k, a]) * scale[i, a]
        kb.scatter_force(np.dot(Cu, Nu), np.dot(Cw, Mw), e0, ucols, wcols, scale, f_out)
        if not want_k:
            continue
        Kuu, Kww, Kuw = kb.packed_tangents(Huu, Hww, Huw, Quu, Qww, Quw)
        Ke = np.empty((n, n))
        for i in range(ec):
            kb.unpack_element(i, Kuu, Kww, Kuw, pu, pw, ucols, wcols, scale, Ke)
            for k in range(n_xi):  # the B̄_x parts of eq. (24): b zᵀ + z bᵀ per ξ
                bk = Kx[i, k, 0]
                zk = Kx[i, k, 1]
                for a in range(n):  # the whole square, rows contiguous (vectorised): entry
                    ba = bk[a]  # (b, a) is b_b z_a + z_b b_a, the same products as (a, b)'s
                    za = zk[a]  # in the other order of one exact sum: the same bits
                    for b in range(n):
                        Ke[a, b] += ba * zk[b] + za * bk[b]
            kb.emit_block(e0 + i, Ke, K_out, slots, signs, data)
