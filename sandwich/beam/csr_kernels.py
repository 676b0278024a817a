"""Compiled kernels of the sparse assembly: CSR patterns, slot maps and scatters.

The reduced tangent Tᵀ K T lives on a CSR pattern of the free DOFs
(:mod:`sandwich.beam.assembly`). These kernels build that pattern from dense blocks, map each
block entry to its CSR slot, add blocks into the CSR values (by slot map or by a binary search
in each row), add local forces into the free DOFs, embed a matrix in a larger pattern and form
|K| |x| without copying K.
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.jit import njit

__all__ = ["abs_matvec", "add_reduced", "block_pattern", "block_slots", "embed_pattern",
           "scatter_blocks", "scatter_compact", "scatter_compact_known"]


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
