"""The row envelope's LDLᵀ (Crout, row by row), its solve and its operation count.

Row i of the storage holds K[i, first[i]:i + 1] (the envelope exactly). The storage is fixed by
the pattern, but its rows are factorised from where their *values* start
(:func:`numerical_first`, one scan per factorisation): a pattern holds couplings that are zero
in most states — a closest-point contact pair couples its face node to every searched core
segment, its tangent lives on the chosen one only, and an open pair's is zero — and the factor
has no fill before a row's first non-zero (the same L and D, fewer operations: fig. 5 at core
level 1, 240 elements, 3.2 → 1.3 ms per factorisation, docs/speed.md).

:func:`record_pivot` keeps the statistics the trust tests read; the column and panel kernels
(:mod:`.columns`, :mod:`.panels`) keep them with it too.
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.jit import njit

__all__ = ["numerical_first", "record_pivot", "row_flops", "row_ldlt", "row_solve"]


@njit
def record_pivot(d, finite, dmin, ldmax, negative):  # pragma: no cover - compiled
    """Pivot d into the acceptance statistics: all finite, min |d|, max |(L D)|, count of d < 0."""
    ad = abs(d)
    if not (ad <= 1.0e308):  # inf or NaN
        finite = False
    if ad < dmin:
        dmin = ad
    if ad > ldmax:
        ldmax = ad
    if d < 0.0:
        negative += 1
    return finite, dmin, ldmax, negative


@njit
def numerical_first(env, rowptr, first, n):  # pragma: no cover - compiled
    """lo[i]: the column of row i's first non-zero value in the stored envelope (≥ first[i]).

    The diagonal ends each stored row and is not scanned, so lo[i] ≤ i.
    """
    lo = np.empty(n, dtype=np.int64)
    for i in range(n):
        p, end = rowptr[i], rowptr[i + 1] - 1
        while p < end and env[p] == 0.0:
            p += 1
        lo[i] = first[i] + (p - rowptr[i])
    return lo


@njit(reassociate=True)
def row_ldlt(env, rowptr, first, lo, n, w):  # pragma: no cover - compiled
    """In-place envelope LDLᵀ (row-by-row Crout): L below the diagonal, D on it.

    Row i: w_j = a_ij − Σ_k w_k L_jk (k from max(lo_i, lo_j) to j − 1) is (L D)_ij, then
    L_ij = w_j / d_j and d_i = a_ii − Σ_j w_j L_ij. ``first`` places the rows in ``env``;
    ``lo`` ≥ ``first`` (:func:`numerical_first`) is where each row's values start: the
    entries before it are zero in K and stay zero in L (w_ij = 0 for j < lo_i by induction on
    j), so they are skipped. Returns (negative pivots, min |d|, max |L D|, max |L|).
    """
    negative = 0
    finite = True
    dmin = np.inf
    ldmax = 0.0
    lmax = 0.0
    for i in range(n):
        fi = lo[i]
        ri = rowptr[i] - first[i]  # env[ri + j] is entry (i, j)
        for j in range(fi, i):
            fj = lo[j]
            rj = rowptr[j] - first[j]
            k0 = fi if fi > fj else fj
            s = env[ri + j]
            for k in range(k0, j):
                s -= w[k] * env[rj + k]
            w[j] = s
        d = env[ri + i]
        for j in range(fi, i):
            lij = w[j] / env[rowptr[j + 1] - 1]
            d -= w[j] * lij
            env[ri + j] = lij
            aw = abs(w[j])
            if aw > ldmax:
                ldmax = aw
            al = abs(lij)
            if al > lmax:
                lmax = al
        env[ri + i] = d
        finite, dmin, ldmax, negative = record_pivot(d, finite, dmin, ldmax, negative)
    if not finite:
        dmin = np.nan
    return negative, dmin, ldmax, lmax


@njit(reassociate=True)
def row_solve(env, rowptr, first, lo, n, order, b, x):  # pragma: no cover - compiled
    """Solve K x = b with K = Pᵀ L D Lᵀ P; b, x of shape (n, m), m right-hand sides.

    Row i of L is stored from ``first[i]``, non-zero from ``lo[i]`` on (as in :func:`row_ldlt`).
    """
    y = np.empty(n)
    for c in range(b.shape[1]):
        for i in range(n):  # forward: L y = P b
            fi = lo[i]
            ri = rowptr[i] - first[i]
            s = b[order[i], c]
            for k in range(fi, i):
                s -= env[ri + k] * y[k]
            y[i] = s
        for i in range(n):  # D z = y
            y[i] /= env[rowptr[i + 1] - 1]
        for i in range(n - 1, -1, -1):  # backward: Lᵀ x = z, column by column
            fi = lo[i]
            ri = rowptr[i] - first[i]
            xi = y[i]
            for k in range(fi, i):
                y[k] -= env[ri + k] * xi
        for i in range(n):
            x[order[i], c] = y[i]


@njit
def row_flops(first, n):  # pragma: no cover - compiled
    """Operations of :func:`row_ldlt`: 2 per inner multiply-add, 3 per off-diagonal (L, d).

    ``first``: the rows' first columns (a structure's, or the values' ``lo`` of one matrix).
    """
    total = 0
    for i in range(n):
        fi = first[i]
        for j in range(fi, i):
            k0 = fi if fi > first[j] else first[j]
            total += 2 * (j - k0) + 3
    return total
