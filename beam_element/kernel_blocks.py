"""Gather and unpack steps shared by the packed layer kernels (compiled).

:func:`beam_element.kernels._kernel` and :func:`beam_element.averaged_kernel.averaged_kernel`
work on blocks of elements in the same layout: the layer's DOF values split into u and w
columns (reference slopes: l/2 on x-slope DOFs), the force from the u and w row coefficients,
and the tangent from packed uu / ww (upper triangles) and uw products. These helpers hold those
steps once; each does exactly the arithmetic the kernels did inline (same operations, same order).
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.jit import njit

__all__ = ["emit_block", "gather_block", "scatter_force", "unpack_coupling", "unpack_symmetric"]


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
