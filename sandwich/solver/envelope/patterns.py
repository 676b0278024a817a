"""Sparsity patterns of the envelope LDLᵀ: what :class:`~.structure.EnvelopeStructure` is built of.

The pattern of a matrix's non-zero values (:func:`values_pattern`), the envelope rows of a
pattern in an order (:func:`envelope_first`) and the columns they imply (:func:`column_last`),
the map from CSR slots to storage positions (:func:`storage_map`) and its runs
(:func:`slot_runs`), the union of two patterns (:func:`pattern_union`, a widened numeric
envelope), and whether two index arrays are one pattern by their memory (:func:`same_memory`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from sandwich.solver.jit import njit

__all__ = ["canonical_csr", "column_last", "envelope_first", "pattern_union", "same_memory",
           "slot_runs", "storage_map", "values_pattern"]


@njit
def values_pattern(indptr, indices, data):  # pragma: no cover - compiled
    """CSR pattern (indptr, indices) of the non-zero values, with every diagonal entry in.

    Row by row in K's (sorted) column order; a row without a diagonal slot gets it inserted in
    place. NaN counts as non-zero.
    """
    n = indptr.size - 1
    ptr = np.zeros(n + 1, dtype=np.int64)
    out = np.empty(indices.size + n, dtype=np.int64)
    c = 0
    for r in range(n):
        diagonal = False
        for t in range(indptr[r], indptr[r + 1]):
            j = indices[t]
            if not diagonal and j >= r:
                out[c] = r
                c += 1
                diagonal = True
                if j == r:
                    continue
            if data[t] != 0.0:
                out[c] = j
                c += 1
        if not diagonal:
            out[c] = r
            c += 1
        ptr[r + 1] = c
    return ptr, out[:c]


@njit
def envelope_first(indptr, indices, order):  # pragma: no cover - compiled
    """first[r] of the matrix permuted by ``order`` (new → old), from its CSR pattern.

    The smallest new column index in new row r over either triangle: an unsymmetric pattern
    gets the envelope of its symmetric closure (each entry (i, j) bounds rows i and j).
    """
    n = indptr.size - 1
    inv = np.empty(n, dtype=np.int64)
    for k in range(n):
        inv[order[k]] = k
    first = np.arange(n)
    for r in range(n):
        a = inv[r]
        for t in range(indptr[r], indptr[r + 1]):
            b = inv[indices[t]]
            if b < first[a]:
                first[a] = b
            if a < first[b]:
                first[b] = a
    return first


@njit
def storage_map(indptr, indices, order, first, last, rowptr, colptr,
                columns):  # pragma: no cover - compiled
    """CSR slots of the stored triangle's entries (new numbering) and their storage positions.

    Column storage reads the upper triangle (column j = K[j, j:last_j + 1]), the row envelope
    the lower one (row i = K[i, first_i:i + 1]); a pattern entry outside the storage (a
    numeric envelope's): position −1. Slots in CSR order.
    """
    n = indptr.size - 1
    inv = np.empty(n, dtype=np.int64)
    for k in range(n):
        inv[order[k]] = k
    slots = np.empty(indices.size, dtype=np.int64)
    positions = np.empty(indices.size, dtype=np.int64)
    c = 0
    for r in range(n):
        i = inv[r]
        for t in range(indptr[r], indptr[r + 1]):
            j = inv[indices[t]]
            if columns and j >= i:
                slots[c] = t
                positions[c] = colptr[i] + (j - i) if j <= last[i] else -1
                c += 1
            elif not columns and j <= i:
                slots[c] = t
                positions[c] = rowptr[i] + (j - first[i]) if j >= first[i] else -1
                c += 1
    return slots[:c].copy(), positions[:c].copy()


def same_memory(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` and ``b`` are the same array or views of the same memory, alike.

    scipy's CSR constructor hands a matrix built on a pattern's index arrays new *views* of
    them (``prune`` slices ``indices[:nnz]``), so identity misses the common case and the
    entry-by-entry comparison cost fig. 7 c4 ≈ 0.5 s (3710 comparisons of up to 2 million
    indices). The structure keeps its arrays alive, so memory at their address with their
    dtype, shape and strides holds their entries (pattern arrays are never written in place).
    """
    if a is b:
        return True
    ia, ib = a.__array_interface__, b.__array_interface__
    return (ia["data"][0] == ib["data"][0] and a.dtype == b.dtype and a.shape == b.shape
            and a.strides == b.strides)


def pattern_union(n: int, a: tuple[np.ndarray, np.ndarray],
                  b: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """CSR pattern (indptr, indices) of the union of two n × n patterns, sorted.

    Both patterns' rows must be sorted (canonical CSR, :func:`values_pattern`'s, or an earlier
    union): the rows are merged (:func:`_union_rows`), int64 throughout.
    """
    a_ptr, a_ind, b_ptr, b_ind = (np.ascontiguousarray(x, dtype=np.int64)
                                  for x in (a[0], a[1], b[0], b[1]))
    return _union_rows(n, a_ptr, a_ind, b_ptr, b_ind)


@njit
def _union_rows(n, a_ptr, a_ind, b_ptr, b_ind):  # pragma: no cover - compiled
    """Row-by-row merge of two sorted CSR patterns into their sorted union (duplicates once)."""
    ptr = np.zeros(n + 1, dtype=np.int64)
    out = np.empty(a_ind.size + b_ind.size, dtype=np.int64)
    c = 0
    for r in range(n):
        i, i_end = a_ptr[r], a_ptr[r + 1]
        j, j_end = b_ptr[r], b_ptr[r + 1]
        last = -1
        while i < i_end or j < j_end:
            if j >= j_end or (i < i_end and a_ind[i] <= b_ind[j]):
                v = a_ind[i]
                i += 1
            else:
                v = b_ind[j]
                j += 1
            if v != last:
                out[c] = v
                c += 1
                last = v
        ptr[r + 1] = c
    return ptr, out[:c]


def column_last(first: np.ndarray) -> np.ndarray:
    """last[j] = the largest row i with first[i] ≤ j (at least j): non-decreasing in j.

    Every entry (i, k) the factor can fill (first[i] ≤ k ≤ i) lies in column k above
    last[k], and last[k] ≥ last[j] for k > j: the right-looking updates stay in the columns.
    """
    n = first.size
    top = np.full(n, -1, dtype=np.int64)
    np.maximum.at(top, first, np.arange(n))  # n entries: cheap
    return np.maximum(np.maximum.accumulate(top), np.arange(n))


def canonical_csr(K: object) -> sp.csr_matrix:
    """``K`` as a square CSR matrix in canonical format (sorted indices, no duplicates)."""
    A = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"tangent must be square, got shape {A.shape}")
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


@njit
def slot_runs(slots, positions):  # pragma: no cover - compiled
    """Runs (slot, position, length) of consecutive slots at consecutive positions (≥ 0)."""
    out = np.empty((slots.size, 3), dtype=np.int64)
    k = -1
    for t in range(slots.size):
        if positions[t] < 0:
            continue
        if (k >= 0 and slots[t] == out[k, 0] + out[k, 2]
                and positions[t] == out[k, 1] + out[k, 2]):
            out[k, 2] += 1
        else:
            k += 1
            out[k, 0] = slots[t]
            out[k, 1] = positions[t]
            out[k, 2] = 1
    return out[:k + 1].copy()
