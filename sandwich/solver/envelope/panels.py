"""Column storage's LDLᵀ by panels of :data:`PANEL` columns and rank-8 updates (wide columns).

Used for column storage whose columns are longer than
:data:`~.structure.PANEL_MIN_WIDTH` on average (:attr:`~.structure.EnvelopeStructure.panels`);
the same factors as :func:`~.columns.column_ldlt` to round-off, solved by
:func:`~.columns.column_solve`.
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.envelope.rows import record_pivot
from sandwich.solver.jit import njit

__all__ = ["PANEL", "panel_flops", "panel_ldlt"]


#: Columns per panel of :func:`panel_ldlt` (its trailing update is a rank-8 update).
PANEL = 8


@njit(reassociate=True)
def panel_ldlt(env, colptr, last, n):  # pragma: no cover - compiled
    """In-place LDLᵀ in column storage (as :func:`column_ldlt`), by panels of PANEL columns.

    Panel j … j + 7 (rows up to R = last[j + 7]): each column is updated by the panel's
    earlier ones (left-looking), scaled by its pivot (l = (L D)/d, one reciprocal per column),
    and copied into P[p] = L[j:R + 1, j + p] and C[p] = (L D)[j:R + 1, j + p], zero outside
    its rows. Then every trailing column k ≤ R loses Σ_p C[p, k − j] · P[p, k − j:] (rows k … R)
    in one pass: a rank-8 update reading and writing each trailing entry once, its eight
    sources in P (one stretch of memory, not the storage that is written, so LLVM vectorises
    it with one overlap check per source; the same loop over the storage's own columns has
    too many to check). The same factorisation as :func:`~.columns.column_ldlt`, the terms summed in
    another order and l = (L D) · (1/d) (round-off). Same returns.
    """
    negative = 0
    finite = True
    dmin = np.inf
    ldmax = 0.0
    lmax = 0.0
    width = 0
    for j in range(n):
        width = last[j] - j if last[j] - j > width else width
    P = np.zeros((PANEL, width + PANEL + 1))
    C = np.zeros((PANEL, width + PANEL + 1))
    j = 0
    while j < n:
        w = PANEL if j + PANEL <= n else n - j
        R = last[j + w - 1]
        span = R - j + 1
        for p in range(w):
            q = j + p
            cq = colptr[q] - q  # env[cq + r] = column q, row r
            lq = last[q]
            dst = env[cq + q:cq + lq + 1]
            for s in range(p):  # the panel's earlier columns (left-looking)
                c = C[s, p]
                if c != 0.0:
                    src = P[s, p:lq - j + 1]
                    for r in range(lq - q + 1):
                        dst[r] -= c * src[r]
            d = dst[0]
            finite, dmin, ldmax, negative = record_pivot(d, finite, dmin, ldmax, negative)
            inv = 1.0 / d
            Pq = P[p]
            Cq = C[p]
            for t in range(p + 1):
                Pq[t] = 0.0
                Cq[t] = 0.0
            for r in range(q + 1, lq + 1):
                a = env[cq + r]
                lr = a * inv
                aa = abs(a)
                ldmax = aa if aa > ldmax else ldmax
                al = abs(lr)
                lmax = al if al > lmax else lmax
                env[cq + r] = lr
                Pq[r - j] = lr
                Cq[r - j] = a
            for t in range(lq - j + 1, span):
                Pq[t] = 0.0
                Cq[t] = 0.0
        for p in range(w, PANEL):  # a last, narrower panel: its missing columns are zero
            for t in range(span):
                P[p, t] = 0.0
                C[p, t] = 0.0
        P0, P1, P2, P3, P4, P5, P6, P7 = P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7]
        for k in range(j + w, R + 1):  # the trailing columns the panel reaches
            t = k - j
            a0, a1, a2, a3 = C[0, t], C[1, t], C[2, t], C[3, t]
            a4, a5, a6, a7 = C[4, t], C[5, t], C[6, t], C[7, t]
            m = R - k + 1
            ck = colptr[k] - k
            dk = env[ck + k:ck + R + 1]
            q0, q1, q2, q3 = P0[t:t + m], P1[t:t + m], P2[t:t + m], P3[t:t + m]
            q4, q5, q6, q7 = P4[t:t + m], P5[t:t + m], P6[t:t + m], P7[t:t + m]
            for r in range(m):
                dk[r] -= (((q0[r] * a0 + q1[r] * a1) + (q2[r] * a2 + q3[r] * a3))
                          + ((q4[r] * a4 + q5[r] * a5) + (q6[r] * a6 + q7[r] * a7)))
        j += w
    if not finite:
        dmin = np.nan
    return negative, dmin, ldmax, lmax


def panel_flops(last: np.ndarray) -> float:
    """Operations of :func:`panel_ldlt`, its zeros included.

    Per column: its reciprocal, m products (l) with m = last[j] − j, and 2 per multiply-add of
    the panel's earlier columns over its rows; per trailing column k of a panel reaching R:
    16 (R − k + 1) (the rank-8 update, its zero terms counted: what runs).
    """
    n = last.size
    j = np.arange(n)
    m = (last - j).astype(float)
    inside = float(np.sum(1 + m) + np.sum(2 * (j % PANEL) * (m + 1)))
    starts = np.arange(0, n, PANEL)
    ends = np.minimum(starts + PANEL, n)  # one past each panel's last column
    c = np.maximum(last[ends - 1] - ends + 1, 0).astype(float)  # its trailing columns
    return inside + float(np.sum(16 * c * (c + 1) / 2))
