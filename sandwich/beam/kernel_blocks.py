"""Steps shared by the packed layer kernels (compiled): gather, per-point factors, unpack.

:func:`sandwich.beam.packed_kernel.packed_kernel` and
:func:`sandwich.beam.averaged_kernel.averaged_kernel` work on blocks of elements in the same
layout: the layer's DOF values split into u and w columns (reference slopes: l/2 on x-slope
DOFs), the force from the u and w row coefficients, and the tangent from packed uu / ww (upper
triangles) and uw products. These helpers hold those steps once; each does exactly the
arithmetic the kernels did inline (same operations, same order).
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.jit import njit

__all__ = ["emit_block", "force_coefficients", "gather_block", "open_block", "packed_tangents",
           "point_gradients", "scatter_force", "strain_factors", "unpack_element"]


@njit
def force_coefficients(dx, dz, sa, sb, st, ux, uz, wx, wz):  # pragma: no cover - compiled
    """Coefficients of the rows N,η  N,ξ  M,η  M,ξ in a point's force, eq. (19).

    Σ_g dV σ·B = Σ_g c·R with the rows of eq. (17) sorted by R; ``sa, sb, st`` are dV (σ_x,
    σ_z, τ) (σ_x's coefficient as the force sees it: adjoint-averaged with membrane_average).
    """
    return (dx * (sa * (1 + ux) + st * uz), dz * (sb * uz + st * (1 + ux)),
            dx * (sa * wx + st * (1 + wz)), dz * (sb * (1 + wz) + st * wx))


@njit
def strain_factors(dx, dz, ux, uz, wx, wz):  # pragma: no cover - compiled
    """Non-zero entries of Φ (B = Φ R, eq. 17), as in ``kinematics.strain_coefficients``.

    Rows (p00 0 p02 0), (0 p11 0 p13), (p20 p21 p22 p23), returned as
    (p00, p02, p11, p13, p20, p21, p22, p23).
    """
    return (dx * (1 + ux), dx * wx, dz * uz, dz * (1 + wz),
            dx * uz, dz * (1 + ux), dx * (1 + wz), dz * wx)


@njit
def gather_block(u_l, lengths, e0, ec, x_slope, ucols, wcols):  # pragma: no cover - compiled
    """``scale`` (ec, n) and the reference values ``Uu`` (ec, n_u), ``Uw`` (ec, n_w).

    u_ref = scale ⊙ u_e with scale l/2 on x-slope DOFs, 1 elsewhere, for elements e0 … e0+ec−1.
    """
    n = x_slope.size
    scale = np.empty((ec, n))
    Uu = np.empty((ec, ucols.size))
    Uw = np.empty((ec, wcols.size))
    for i in range(ec):
        half = 0.5 * lengths[e0 + i]
        for a in range(n):
            scale[i, a] = half if x_slope[a] else 1.0
        for a in range(ucols.size):
            Uu[i, a] = u_l[e0 + i, ucols[a]] * scale[i, ucols[a]]
        for a in range(wcols.size):
            Uw[i, a] = u_l[e0 + i, wcols[a]] * scale[i, wcols[a]]
    return scale, Uu, Uw


@njit
def open_block(u_l, lengths, e0, ec, x_slope, ucols, wcols, NuT, MwT,
               want_k):  # pragma: no cover - compiled
    """A block's ``scale``, gradients ``Du``, ``Dw`` (reference) and its work arrays.

    ``Du = [N,η u | N,ξ u]``, ``Dw = [M,η w | M,ξ w]`` (ec, 2G), one GEMM each; force
    coefficients ``Cu``, ``Cw`` (ec, 2G) and, if ``want_k``, the point matrices ``Huu``,
    ``Hww`` (ec, 3G) and ``Huw`` (ec, 4G) (else empty).
    """
    scale, Uu, Uw = gather_block(u_l, lengths, e0, ec, x_slope, ucols, wcols)  # u_ref
    G = NuT.shape[1] // 2
    Du = np.dot(Uu, NuT)
    Dw = np.dot(Uw, MwT)
    Cu = np.empty((ec, 2 * G))
    Cw = np.empty((ec, 2 * G))
    if want_k:
        Huu = np.empty((ec, 3 * G))
        Hww = np.empty((ec, 3 * G))
        Huw = np.empty((ec, 4 * G))
    else:
        Huu = np.empty((0, 0))
        Hww = np.empty((0, 0))
        Huw = np.empty((0, 0))
    return scale, Du, Dw, Cu, Cw, Huu, Hww, Huw


@njit
def point_gradients(Du, Dw, i, g, dx, dz):  # pragma: no cover - compiled
    """u,x  u,z  w,x  w,z of element i at point g (eq. 15) from the block's gradients."""
    G = Du.shape[1] // 2
    return dx * Du[i, g], dz * Du[i, G + g], dx * Dw[i, g], dz * Dw[i, G + g]


@njit
def scatter_force(Fu, Fw, e0, ucols, wcols, scale, f_out):  # pragma: no cover - compiled
    """The block's forces ``Fu``, ``Fw`` (reference) into ``f_out`` (physical: scaled)."""
    for i in range(Fu.shape[0]):
        for a in range(ucols.size):
            f_out[e0 + i, ucols[a]] = Fu[i, a] * scale[i, ucols[a]]
        for a in range(wcols.size):
            f_out[e0 + i, wcols[a]] = Fw[i, a] * scale[i, wcols[a]]


@njit
def unpack_symmetric(Kp, i, pairs, cols, scale, Ke):  # pragma: no cover - compiled
    """Element i's packed upper triangle ``Kp[i]`` (pairs (a ≤ b) of ``cols``) into ``Ke``."""
    for p in range(pairs.shape[1]):
        ia = cols[pairs[0, p]]
        ib = cols[pairs[1, p]]
        v = Kp[i, p] * scale[i, ia] * scale[i, ib]
        Ke[ia, ib] = v
        Ke[ib, ia] = v


@njit
def unpack_coupling(Kuw, i, ucols, wcols, scale, Ke):  # pragma: no cover - compiled
    """Element i's uw block ``Kuw[i]`` (row-major n_u × n_w) into ``Ke`` and its transpose."""
    nw = wcols.size
    for a in range(ucols.size):
        ia = ucols[a]
        for b in range(nw):
            ib = wcols[b]
            v = Kuw[i, a * nw + b] * scale[i, ia] * scale[i, ib]
            Ke[ia, ib] = v
            Ke[ib, ia] = v


@njit
def packed_tangents(Huu, Hww, Huw, Quu, Qww, Quw):  # pragma: no cover - compiled
    """The block's packed tangents: ``H · Q`` for uu, ww (upper triangles) and uw, one GEMM each."""
    return np.dot(Huu, Quu), np.dot(Hww, Qww), np.dot(Huw, Quw)


@njit
def unpack_element(i, Kuu, Kww, Kuw, pu, pw, ucols, wcols, scale, Ke):  # pragma: no cover
    """Element i's packed tangents into its dense block ``Ke`` (physical: scaled by l/2)."""
    unpack_symmetric(Kuu, i, pu, ucols, scale, Ke)
    unpack_symmetric(Kww, i, pw, wcols, scale, Ke)
    unpack_coupling(Kuw, i, ucols, wcols, scale, Ke)


@njit
def emit_block(e, Ke, K_out, slots, signs, data):  # pragma: no cover - compiled
    """Element e's block ``Ke`` into ``K_out[e]`` and/or ``data[slots[e]]`` (whichever is given)."""
    if K_out.shape[0] > 0:
        K_out[e] = Ke
    if slots.shape[0] > 0:
        n = Ke.shape[0]
        for a in range(n):
            for b in range(n):
                s = slots[e, a, b]
                if s >= 0:
                    data[s] += signs[e, a, b] * Ke[a, b]
