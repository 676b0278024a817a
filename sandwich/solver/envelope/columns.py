"""Column storage's LDLᵀ (right-looking, panels of four columns), its solve and operation count.

Column j holds rows j … last[j] contiguously, last non-decreasing (a band is the special case):
the factorisation runs by contiguous AXPYs that vectorise, its trailing updates rank-4 and two
columns at a time (:func:`column_ldlt`); the solves take the right-hand sides in pairs
(:func:`column_solve`).
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.envelope.rows import record_pivot
from sandwich.solver.jit import njit

__all__ = ["column_flops", "column_ldlt", "column_solve"]


@njit
def _scale_column(env, cj, m, d):  # pragma: no cover - compiled
    """l_ij = (L D)_ij / d_j in place for the m entries below column j's diagonal.

    Returns max |(L D)_ij| and max |l_ij| (the growth tests).
    """
    ldmax = 0.0
    lmax = 0.0
    for k in range(1, m + 1):
        a = abs(env[cj + k])
        if a > ldmax:
            ldmax = a
        env[cj + k] /= d
        a = abs(env[cj + k])
        if a > lmax:
            lmax = a
    return ldmax, lmax


@njit
def _column_update(env, colptr, last, j, q):  # pragma: no cover - compiled
    """Column q (> j, ≤ last[j]) loses l_qj d_j l_(q..last_j) j: one contiguous AXPY."""
    cj = colptr[j]
    c = env[cj + (q - j)] * env[cj]
    dst = env[colptr[q]:colptr[q] + last[j] - q + 1]
    src = env[cj + (q - j):cj + last[j] - j + 1]
    for r in range(last[j] - q + 1):
        dst[r] -= c * src[r]


@njit
def column_ldlt(env, colptr, last, n):  # pragma: no cover - compiled
    """In-place LDLᵀ in column storage, env[colptr[j] + (i − j)] = K[i, j] (right-looking).

    Column j: d_j = K[j, j], l_ij = K[i, j] / d_j, then every later column k ≤ last[j] loses
    l_kj d_j l_(k..last_j) j. Columns go in panels of four: a panel's columns are factorised
    and update each other one by one (AXPYs), then every later column they reach loses the
    four columns' terms in one pass (a rank-4 update: each entry of the trailing column is
    read and written once, not four times; last[j] is non-decreasing, so the rows split into
    stretches reached by 4, 3, 2 and 1 of the panel's columns), two trailing columns at a time
    (:func:`_paired_update`, :func:`_paired_stairs`). The same factorisation as column by
    column, the sums of the four terms in another order (round-off). Same returns as
    :func:`~.rows.row_ldlt`.
    """
    negative = 0
    finite = True
    dmin = np.inf
    ldmax = 0.0
    lmax = 0.0
    j = 0
    while j < n:
        w = 4 if j + 4 <= n else 1
        for p in range(j, j + w):  # the panel's columns, each updating the panel's later ones
            d = env[colptr[p]]
            finite, dmin, ldmax, negative = record_pivot(d, finite, dmin, ldmax, negative)
            a, b = _scale_column(env, colptr[p], last[p] - p, d)
            ldmax = a if a > ldmax else ldmax
            lmax = b if b > lmax else lmax
            reach = last[p] if w == 1 else min(last[p], j + w - 1)
            for q in range(p + 1, reach + 1):
                _column_update(env, colptr, last, p, q)
        if w == 1:
            j += 1
            continue
        a0, a1, a2, a3 = last[j], last[j + 1], last[j + 2], last[j + 3]
        c0_, c1_, c2_, c3_ = colptr[j], colptr[j + 1], colptr[j + 2], colptr[j + 3]
        d0, d1, d2, d3 = env[c0_], env[c1_], env[c2_], env[c3_]
        if a0 == a3:  # the four columns end on one row (two panels in three at level 1)
            _paired_update(env, colptr, j, a3, c0_, c1_, c2_, c3_, d0, d1, d2, d3)
        else:
            _paired_stairs(env, colptr, j, a0, a1, a2, a3, c0_, c1_, c2_, c3_, d0, d1, d2, d3)
        j += 4
    if not finite:
        dmin = np.nan
    return negative, dmin, ldmax, lmax


@njit
def _paired_update(env, colptr, j, A, c0_, c1_, c2_, c3_, d0, d1, d2, d3):  # pragma: no cover
    """:func:`column_ldlt`'s rank-4 update by a panel whose four columns all end on row A.

    The trailing columns j + 4 … A lose the panel's terms (the common case: a node's DOFs
    share their last coupled row; fig. 5 at level 1: two panels in three). Columns k and k + 1
    go together: each source entry (the panel's l_rp, rows k + 1 … A) is read once for both.
    Every entry gets the same operations as one column at a time, so the same values bit for
    bit (fig. 5, 240 elements, level 1: 0.47 → 0.39 ms a factorisation). Kept apart from
    :func:`_paired_stairs`, which covers this case too: one stretch, no branches, 7 % faster.
    """
    o0, o1, o2, o3 = c0_ - j, c1_ - j - 1, c2_ - j - 2, c3_ - j - 3  # env[o_p + r]: row r of p
    k = j + 4
    while k <= A:
        e0, e1 = env[o0 + k] * d0, env[o1 + k] * d1  # column k's coefficients (l_kp d_p)
        e2, e3 = env[o2 + k] * d2, env[o3 + k] * d3
        ck = colptr[k] - k  # env[ck + r] = column k, row r
        env[ck + k] -= e0 * env[o0 + k] + e1 * env[o1 + k] + e2 * env[o2 + k] + e3 * env[o3 + k]
        if k == A:
            break
        f0, f1 = env[o0 + k + 1] * d0, env[o1 + k + 1] * d1  # column k + 1's
        f2, f3 = env[o2 + k + 1] * d2, env[o3 + k + 1] * d3
        ck1 = colptr[k + 1] - k - 1
        dk = env[ck + k + 1:ck + A + 1]
        dk1 = env[ck1 + k + 1:ck1 + A + 1]
        s0 = env[o0 + k + 1:o0 + A + 1]
        s1 = env[o1 + k + 1:o1 + A + 1]
        s2 = env[o2 + k + 1:o2 + A + 1]
        s3 = env[o3 + k + 1:o3 + A + 1]
        for t in range(A - k):
            v0, v1, v2, v3 = s0[t], s1[t], s2[t], s3[t]
            dk[t] -= e0 * v0 + e1 * v1 + e2 * v2 + e3 * v3
            dk1[t] -= f0 * v0 + f1 * v1 + f2 * v2 + f3 * v3
        k += 2


@njit
def _paired_stairs(env, colptr, j, a0, a1, a2, a3, c0_, c1_, c2_, c3_, d0, d1, d2, d3
                   ):  # pragma: no cover - compiled
    """:func:`column_ldlt`'s rank-4 update by a panel whose columns end on rows a0 ≤ … ≤ a3.

    The rows of each trailing column split into stretches reached by 4, 3, 2 and 1 of the
    panel's columns (a_p: column j + p's last row); each stretch loses those columns' terms.
    Columns k and k + 1 go together, as in :func:`_paired_update`: the same operations on every
    entry as one column at a time (the same values bit for bit; fig. 5, 240 elements, level 1,
    with it: 0.400 → 0.366 ms a factorisation).
    """
    o0, o1, o2, o3 = c0_ - j, c1_ - j - 1, c2_ - j - 2, c3_ - j - 3  # env[o_p + r]: row r of p
    k = j + 4
    while k <= a3:
        e0 = env[o0 + k] * d0 if k <= a0 else 0.0  # column k's coefficients (l_kp d_p)
        e1 = env[o1 + k] * d1 if k <= a1 else 0.0
        e2 = env[o2 + k] * d2 if k <= a2 else 0.0
        e3 = env[o3 + k] * d3
        ck = colptr[k] - k  # env[ck + r] = column k, row r
        if k <= a0:  # row k of column k, in the stretch it lies in
            env[ck + k] -= e0 * env[o0 + k] + e1 * env[o1 + k] + e2 * env[o2 + k] + e3 * env[o3 + k]
        elif k <= a1:
            env[ck + k] -= e1 * env[o1 + k] + e2 * env[o2 + k] + e3 * env[o3 + k]
        elif k <= a2:
            env[ck + k] -= e2 * env[o2 + k] + e3 * env[o3 + k]
        else:
            env[ck + k] -= e3 * env[o3 + k]
        if k == a3:
            break
        k1 = k + 1
        f0 = env[o0 + k1] * d0 if k1 <= a0 else 0.0  # column k + 1's
        f1 = env[o1 + k1] * d1 if k1 <= a1 else 0.0
        f2 = env[o2 + k1] * d2 if k1 <= a2 else 0.0
        f3 = env[o3 + k1] * d3
        ck1 = colptr[k1] - k1
        r = k1
        if r <= a0:  # rows reached by all four columns
            m = a0 - r + 1
            dk, dk1 = env[ck + r:ck + r + m], env[ck1 + r:ck1 + r + m]
            s0, s1 = env[o0 + r:o0 + r + m], env[o1 + r:o1 + r + m]
            s2, s3 = env[o2 + r:o2 + r + m], env[o3 + r:o3 + r + m]
            for t in range(m):
                v0, v1, v2, v3 = s0[t], s1[t], s2[t], s3[t]
                dk[t] -= e0 * v0 + e1 * v1 + e2 * v2 + e3 * v3
                dk1[t] -= f0 * v0 + f1 * v1 + f2 * v2 + f3 * v3
            r = a0 + 1
        if r <= a1:
            m = a1 - r + 1
            dk, dk1 = env[ck + r:ck + r + m], env[ck1 + r:ck1 + r + m]
            s1, s2, s3 = env[o1 + r:o1 + r + m], env[o2 + r:o2 + r + m], env[o3 + r:o3 + r + m]
            for t in range(m):
                v1, v2, v3 = s1[t], s2[t], s3[t]
                dk[t] -= e1 * v1 + e2 * v2 + e3 * v3
                dk1[t] -= f1 * v1 + f2 * v2 + f3 * v3
            r = a1 + 1
        if r <= a2:
            m = a2 - r + 1
            dk, dk1 = env[ck + r:ck + r + m], env[ck1 + r:ck1 + r + m]
            s2, s3 = env[o2 + r:o2 + r + m], env[o3 + r:o3 + r + m]
            for t in range(m):
                v2, v3 = s2[t], s3[t]
                dk[t] -= e2 * v2 + e3 * v3
                dk1[t] -= f2 * v2 + f3 * v3
            r = a2 + 1
        m = a3 - r + 1
        dk, dk1 = env[ck + r:ck + r + m], env[ck1 + r:ck1 + r + m]
        s3 = env[o3 + r:o3 + r + m]
        for t in range(m):
            v3 = s3[t]
            dk[t] -= e3 * v3
            dk1[t] -= f3 * v3
        k += 2


@njit(reassociate=True)
def column_solve(env, colptr, last, n, order, rhs, x):  # pragma: no cover - compiled
    """Solve K x = rhs with the factors of :func:`column_ldlt`; rhs, x of shape (n, m).

    Right-hand sides in pairs: each sweep reads a factor column once for both (the corrector's
    two solves, K⁻¹r and K⁻¹f, are one call), on slices that vectorise — fig. 5 at auto
    levels, 9858 DOFs: 2.2 ms for two solves one by one as indexed loops, 0.6 ms as a pair.
    """
    m = rhs.shape[1]
    y0 = np.empty(n)
    y1 = np.empty(n)
    for c in range(0, m, 2):
        if c + 1 == m:  # an odd one out
            _column_solve_one(env, colptr, last, n, order, rhs, x, c, y0)
            break
        for i in range(n):
            y0[i] = rhs[order[i], c]
            y1[i] = rhs[order[i], c + 1]
        for j in range(n):  # L y = P rhs, column by column
            cj = colptr[j]
            k = last[j] - j
            e = env[cj + 1:cj + k + 1]
            t0 = y0[j + 1:j + k + 1]
            t1 = y1[j + 1:j + k + 1]
            a0 = y0[j]
            a1 = y1[j]
            for r in range(k):
                t0[r] -= e[r] * a0
                t1[r] -= e[r] * a1
        for j in range(n):
            y0[j] /= env[colptr[j]]
            y1[j] /= env[colptr[j]]
        for j in range(n - 1, -1, -1):  # Lᵀ x = z
            cj = colptr[j]
            k = last[j] - j
            e = env[cj + 1:cj + k + 1]
            t0 = y0[j + 1:j + k + 1]
            t1 = y1[j + 1:j + k + 1]
            s0 = y0[j]
            s1 = y1[j]
            for r in range(k):
                s0 -= e[r] * t0[r]
                s1 -= e[r] * t1[r]
            y0[j] = s0
            y1[j] = s1
        for i in range(n):
            x[order[i], c] = y0[i]
            x[order[i], c + 1] = y1[i]


@njit(reassociate=True)
def _column_solve_one(env, colptr, last, n, order, rhs, x, c, y):  # pragma: no cover
    """Column ``c`` of :func:`column_solve` alone (``y``: work array of n)."""
    for i in range(n):
        y[i] = rhs[order[i], c]
    for j in range(n):
        cj = colptr[j]
        k = last[j] - j
        e = env[cj + 1:cj + k + 1]
        t = y[j + 1:j + k + 1]
        a = y[j]
        for r in range(k):
            t[r] -= e[r] * a
    for j in range(n):
        y[j] /= env[colptr[j]]
    for j in range(n - 1, -1, -1):
        cj = colptr[j]
        k = last[j] - j
        e = env[cj + 1:cj + k + 1]
        t = y[j + 1:j + k + 1]
        s = y[j]
        for r in range(k):
            s -= e[r] * t[r]
        y[j] = s
    for i in range(n):
        x[order[i], c] = y[i]


def column_flops(last: np.ndarray) -> float:
    """Operations of :func:`column_ldlt`.

    Per column j with m = last[j] − j entries below the diagonal: m divisions, m products and
    m(m + 1)/2 multiply-adds.
    """
    m = (last - np.arange(last.size)).astype(float)
    return float(np.sum(2 * m + m * (m + 1)))
