"""Compiled internal force (eq. 19) and consistent tangent (eqs. 24-25) of a layer, in one pass.

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

The tangent is either written as blocks ``(E, n, n)`` (:func:`layer_response`, the
:mod:`sandwich.beam.element` interface) or scattered straight into the values of the reduced CSR
matrix through a precomputed slot map (:func:`layer_assemble`, used by the model), which skips
the blocks and their concatenation. Layers with the ``membrane_average`` option (the faces'
default) are evaluated by the kernel of :mod:`sandwich.beam.averaged_kernel` (same arrays, ε_x
averaged along η), or by the NumPy path where its assumptions fail (:func:`supports`).

Layers whose rows factor into x- and z-functions at a tensor rule are evaluated instead by the
sum-factorised kernel of :mod:`sandwich.beam.sum_factor` (same integrand, same points, ξ summed
first) where that saves enough flops (:func:`uses_sum_factorisation`): the cores, the paper's
one included. The faces keep the packed kernel below.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np

from sandwich.beam.averaged_kernel import averaged_kernel, averaging_weights
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
from sandwich.beam.sum_factor import factored_flops, factored_kernel, factored_operators
from sandwich.solver.jit import njit

__all__ = ["KernelOperators", "add_reduced", "block_pattern", "block_slots", "embed_pattern",
           "kernel_operators", "layer_assemble", "layer_blocks", "layer_flops", "layer_response",
           "point_flops", "scatter_blocks", "scatter_compact", "scatter_compact_known",
           "supports", "uses_sum_factorisation"]


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


def supports(op: LayerOperators) -> bool:
    """Whether a kernel evaluates ``op``.

    Every layer without the ``membrane_average`` option; with it, where
    :func:`~sandwich.beam.averaged_kernel.averaging_weights` accepts the rule and stiffness
    (tensor rule with η slowest, separable weights, symmetric C: every layer the model builds).
    """
    return not op.membrane_average or averaging_weights(op) is not None


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
def _kernel(u_l, lengths, width, NuT, MwT, Nu, Mw, Quu, Qww, Quw, pu, pw, ucols, wcols,
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


@njit
def _row_union(r, bptr, bdofs, inc_ptr, inc_block, mark, out, start, write):  # pragma: no cover
    """Columns of row r, the union of its blocks' DOFs: how many (written from ``out[start]``).

    Written only if ``write``; ``mark[j] == r`` flags column j as already seen for this row.
    """
    c = 0
    for t in range(inc_ptr[r], inc_ptr[r + 1]):
        g = inc_block[t]
        for q in range(bptr[g], bptr[g + 1]):
            j = bdofs[q]
            if j >= 0 and mark[j] != r:
                mark[j] = r
                if write:
                    out[start + c] = j
                c += 1
    return c


@njit
def block_pattern(bptr, bdofs, inc_ptr, inc_block, n):  # pragma: no cover - compiled
    """Canonical CSR pattern (indptr, indices) of the union of dense blocks.

    Block g covers the reduced DOFs ``bdofs[bptr[g]:bptr[g + 1]]`` (−1: eliminated); row r
    lies in the blocks ``inc_block[inc_ptr[r]:inc_ptr[r + 1]]``. Row r's columns are the
    union of those blocks' DOFs, sorted.
    """
    mark = np.full(n, -1, dtype=np.int64)
    indptr = np.zeros(n + 1, dtype=np.int64)
    for r in range(n):  # count
        indptr[r + 1] = indptr[r] + _row_union(r, bptr, bdofs, inc_ptr, inc_block, mark,
                                               indptr, indptr[r], False)
    indices = np.empty(indptr[n], dtype=np.int64)
    mark[:] = -1
    for r in range(n):  # fill and sort
        _row_union(r, bptr, bdofs, inc_ptr, inc_block, mark, indices, indptr[r], True)
        indices[indptr[r]:indptr[r + 1]] = np.sort(indices[indptr[r]:indptr[r + 1]])
    return indptr, indices


@njit
def block_slots(free, indptr, indices, n, out):  # pragma: no cover - compiled
    """CSR slot of every entry of dense blocks (B, m) of reduced DOFs ``free`` (−1: none).

    ``out`` (B, m, m) receives the slot of entry (free[b, i], free[b, j]), −1 where either
    DOF is eliminated.
    """
    pos = np.full(n, -1, dtype=np.int64)
    B, m = free.shape
    for b in range(B):
        for i in range(m):
            r = free[b, i]
            if r < 0:
                out[b, i, :] = -1
                continue
            for p in range(indptr[r], indptr[r + 1]):
                pos[indices[p]] = p
            for j in range(m):
                c = free[b, j]
                out[b, i, j] = pos[c] if c >= 0 else -1
            for p in range(indptr[r], indptr[r + 1]):
                pos[indices[p]] = -1


@njit
def scatter_compact(free, sign, K, indptr, indices, data):  # pragma: no cover - compiled
    """Add blocks K (B, m, m) on reduced DOFs ``free`` (B, m) into the CSR values ``data``.

    ``free`` −1: eliminated; ``sign``: each DOF's sign; each slot is found by a binary search
    in its row. Returns how many entries have no slot in the pattern (not added).
    """
    misses = 0
    B, m = free.shape
    for b in range(B):
        for i in range(m):
            r = free[b, i]
            if r < 0:
                continue
            for j in range(m):
                c = free[b, j]
                if c < 0:
                    continue
                slot = _csr_slot(indptr, indices, r, c)
                if slot >= 0:
                    data[slot] += sign[b, i] * sign[b, j] * K[b, i, j]
                else:
                    misses += 1
    return misses


@njit
def _csr_slot(indptr, indices, r, c):  # pragma: no cover - compiled
    """The slot of entry (r, c) in a CSR pattern with sorted rows (binary search), or −1."""
    lo, hi = indptr[r], indptr[r + 1]
    end = hi
    while lo < hi:
        mid = (lo + hi) // 2
        if indices[mid] < c:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < end and indices[lo] == c else -1


@njit
def scatter_compact_known(free, sign, K, indptr, indices, data, known_free,
                          known_slots):  # pragma: no cover - compiled
    """:func:`scatter_compact` with each block's slots remembered between calls.

    ``known_free`` (B, m) and ``known_slots`` (B, m, m) hold the reduced DOFs and the CSR slots
    (−1 eliminated, −2 not in the pattern) of each block at its last call on this pattern: a
    block whose DOFs are unchanged (a contact pair on the same segment: most pairs, most
    iterations) is added without searching its rows; the others are searched and remembered.
    The same sums as :func:`scatter_compact`, in the same order. Returns the misses.
    """
    misses = 0
    B, m = free.shape
    for b in range(B):
        same = True
        for i in range(m):
            if known_free[b, i] != free[b, i]:
                same = False
                break
        if not same:
            for i in range(m):
                r = free[b, i]
                for j in range(m):
                    c = free[b, j]
                    slot = -1
                    if r >= 0 and c >= 0:
                        slot = _csr_slot(indptr, indices, r, c)
                        slot = slot if slot >= 0 else -2
                    known_slots[b, i, j] = slot
            for i in range(m):
                known_free[b, i] = free[b, i]
        for i in range(m):
            for j in range(m):
                slot = known_slots[b, i, j]
                if slot >= 0:
                    data[slot] += sign[b, i] * sign[b, j] * K[b, i, j]
                elif slot == -2:
                    misses += 1
    return misses


@njit
def abs_matvec(indptr, indices, data, x):  # pragma: no cover - compiled
    """|K| |x| for CSR ``K``: row sums in CSR order, as scipy's ``abs(K) @ abs(x)`` (no copy)."""
    n = indptr.size - 1
    y = np.zeros(n)
    for i in range(n):
        s = 0.0
        for t in range(indptr[i], indptr[i + 1]):
            s += abs(data[t]) * abs(x[indices[t]])
        y[i] = s
    return y


@njit
def embed_pattern(indptr, indices, k_indptr, k_indices, k_data, out):  # pragma: no cover
    """Values of a CSR matrix K placed on a larger CSR pattern (both with sorted rows).

    ``out`` (zeros, one per pattern slot) receives K's values; returns False (``out``
    incomplete) if an entry of K is not in the pattern.
    """
    for r in range(indptr.size - 1):
        p = indptr[r]
        p_end = indptr[r + 1]
        for t in range(k_indptr[r], k_indptr[r + 1]):
            c = k_indices[t]
            while p < p_end and indices[p] < c:
                p += 1
            if p == p_end or indices[p] != c:
                return False
            out[p] += k_data[t]
    return True


@njit
def add_reduced(dofs, f, free, sign, out):  # pragma: no cover - compiled
    """``out += Tᵀ`` (the local forces ``f`` (B, n) on full DOFs ``dofs`` (B, n)).

    :func:`sandwich.beam.assembly.scatter_vector` and :meth:`DofMap.reduce
    <sandwich.beam.constraints.DofMap.reduce>` in one pass, without the full vector: a full
    DOF d goes to free row ``free[d]`` (if ≥ 0) with ``sign[d]``.
    """
    for e in range(dofs.shape[0]):
        for a in range(dofs.shape[1]):
            d = dofs[e, a]
            r = free[d]
            if r >= 0:
                out[r] += sign[d] * f[e, a]


@njit
def scatter_blocks(blocks, slots, signs, data):  # pragma: no cover - compiled
    """``data[slots] += signs · blocks`` over all entries with a slot (blocks ``(B, n, n)``)."""
    for e in range(blocks.shape[0]):
        for a in range(blocks.shape[1]):
            for b in range(blocks.shape[2]):
                s = slots[e, a, b]
                if s >= 0:
                    data[s] += signs[e, a, b] * blocks[e, a, b]


_NO_BLOCKS = np.empty((0, 0, 0))
_NO_SLOTS = np.empty((0, 0, 0), dtype=np.int32)
_NO_SIGNS = np.empty((0, 0, 0), dtype=np.int8)
_NO_DATA = np.empty(0)


SUM_FACTORISATION = "auto"  # "auto" (by flops, below), "always" (where the rows factor), "never"
# auto: factored when its flops × this < the packed kernel's. Measured (docs/beam_speed.md,
# machine B, 2026-12-05): the paper's core (2.2× fewer flops) force + tangent 0.79-0.85 against
# 1.0 ms at 240 elements, fig. 5's path 6-10 % faster; the paper's faces (1.4×) slower factored
# (0.19 against 0.145 ms); from level 2 on (3.7× and more) factored is far faster. (3.0 until
# then, from a measurement under load in which the paper's core tied.)
FACTORED_OVERHEAD = 2.0


def uses_sum_factorisation(op: LayerOperators) -> bool:
    """Whether ``op`` is evaluated by the sum-factorised kernel (:mod:`sandwich.beam.sum_factor`).

    Only where the rows factor (tensor rule, every column an x-function times a z-function,
    checked); then by :data:`SUM_FACTORISATION`: ``"auto"`` takes it when its flops
    (:func:`~sandwich.beam.sum_factor.factored_flops`) times :data:`FACTORED_OVERHEAD` are fewer
    than the packed kernel's (:func:`point_flops` × G), i.e. the cores (the paper's one
    included), not the faces. Decided on the tangent's flops, for force-only calls too: a
    force is the same with or without its tangent, bit for bit. Kept on ``op`` for the
    setting it was made under (the flop counts cost ≈ 0.15 ms, and the kernels ask on every
    call); a changed setting is obeyed at once.
    """
    key = (SUM_FACTORISATION, FACTORED_OVERHEAD)  # the decision, kept on ``op`` per setting
    known = op.__dict__.get("_uses_sum_factorisation")
    if known is not None and known[0] == key:
        return known[1]
    if SUM_FACTORISATION == "never":
        use = False
    else:
        fo = factored_operators(op)
        use = fo is not None and (
            SUM_FACTORISATION == "always"
            or FACTORED_OVERHEAD * factored_flops(fo) < op.eta.size * point_flops(op))
    object.__setattr__(op, "_uses_sum_factorisation", (key, use))
    return use


def layer_flops(op: LayerOperators, tangent: bool = True) -> int:
    """Flops per element of whichever kernel evaluates ``op`` (as executed)."""
    if uses_sum_factorisation(op):
        return factored_flops(factored_operators(op), tangent)
    return op.eta.size * point_flops(op, tangent)


def _run(op, u_l, lengths, width, want_k, K_out, slots, signs, data):
    k = kernel_operators(op)
    u_l = np.ascontiguousarray(u_l, dtype=float)
    if u_l.ndim != 2 or u_l.shape[1] != k.dofs.size:
        raise ValueError(f"expected values of the layer's {k.dofs.size} DOFs, got {u_l.shape}")
    lengths = np.ascontiguousarray(lengths, dtype=float)
    if lengths.shape != (u_l.shape[0],):
        raise ValueError(f"expected {u_l.shape[0]} element lengths, got {lengths.shape}")
    f = np.empty((u_l.shape[0], k.dofs.size))
    if op.membrane_average:
        wbar = averaging_weights(op)
        if wbar is None:
            raise ValueError(f"{op.name}: membrane_average needs a tensor rule and symmetric C")
        q = k.packed
        averaged_kernel(u_l, lengths, float(width), k.NuT, k.MwT, k.Nu, k.Mw, q.Quu, q.Qww,
                        q.Quw, q.pu, q.pw, k.ucols, k.wcols, k.x_slope, k.weight, wbar,
                        k.stiffness, k.thickness, f, want_k, K_out, slots, signs, data)
        return f
    if uses_sum_factorisation(op):
        fo = factored_operators(op)
        factored_kernel(u_l, lengths, float(width), fo.Xu, fo.Xdu, fo.ZuT, fo.ZduT, fo.iu,
                        fo.ju, fo.Xw, fo.Xdw, fo.ZwT, fo.ZdwT, fo.iw, fo.jw, fo.Quu, fo.Puu,
                        fo.Qww, fo.Pww, fo.Quw, fo.Puw, fo.entries, k.ucols, k.wcols,
                        k.x_slope, k.weight, k.stiffness, k.thickness, f, want_k, K_out, slots,
                        signs, data)
        return f
    q = k.packed
    _kernel(u_l, lengths, float(width), k.NuT, k.MwT, k.Nu, k.Mw, q.Quu, q.Qww, q.Quw, q.pu,
            q.pw, k.ucols, k.wcols, k.x_slope, k.weight, k.stiffness, k.thickness, f,
            want_k, K_out, slots, signs, data)
    return f


def layer_response(
    op: LayerOperators, u_e: np.ndarray, lengths: np.ndarray, width: float,
    tangent: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Force ``(E, n)`` and tangent blocks ``(E, n, n)`` (or None).

    The compiled twin of :func:`sandwich.beam.element.layer_response`.

    Parameters
    ----------
    op
        The layer (one the kernels evaluate, see :func:`supports`).
    u_e
        Element DOF vectors ``(E, n_element)`` (physical slopes), indexed by ``op.dofs``.
    lengths
        Element lengths (mm), ``(E,)``.
    width
        Beam width (mm).
    tangent
        Whether to compute the tangent.
    """
    if not supports(op):
        raise ValueError(f"{op.name}: not evaluated by the kernels, use sandwich.beam.element")
    E, n = u_e.shape[0], op.dofs.size
    K = np.empty((E, n, n)) if tangent else _NO_BLOCKS
    f = _run(op, np.asarray(u_e)[:, op.dofs], lengths, width, tangent, K, _NO_SLOTS, _NO_SIGNS,
             _NO_DATA)
    return f, (K if tangent else None)


def layer_blocks(
    op: LayerOperators, u_l: np.ndarray, lengths: np.ndarray, width: float,
    tangent: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Force ``(E, n)`` and tangent blocks ``(E, n, n)`` from the layer's DOF values ``u_l``.

    As :func:`layer_response`, with ``u_l = u_e[:, op.dofs]`` already gathered.
    """
    E, n = np.shape(u_l)[0], op.dofs.size
    K = np.empty((E, n, n)) if tangent else _NO_BLOCKS
    f = _run(op, u_l, lengths, width, tangent, K, _NO_SLOTS, _NO_SIGNS, _NO_DATA)
    return f, (K if tangent else None)


def layer_assemble(
    op: LayerOperators, u_l: np.ndarray, lengths: np.ndarray, width: float,
    slots: np.ndarray | None, signs: np.ndarray | None, data: np.ndarray,
) -> np.ndarray:
    """Force ``(E, n)``; with ``slots`` the tangent is added into ``data`` (CSR values) in place.

    ``u_l`` ``(E, n)`` holds the values of the layer's DOFs ``op.dofs`` of each element (physical
    slopes), e.g. ``u_full[family DOFs]``.

    ``slots[e, a, b]`` is the CSR slot of the layer's entry (a, b) of element e in the reduced
    matrix (−1 if it is eliminated) and ``signs`` its sign product
    (:meth:`sandwich.beam.assembly.ReducedPattern.family_slots`).
    """
    if slots is None:
        return _run(op, u_l, lengths, width, False, _NO_BLOCKS, _NO_SLOTS, _NO_SIGNS, _NO_DATA)
    return _run(op, u_l, lengths, width, True, _NO_BLOCKS, slots, signs, data)
