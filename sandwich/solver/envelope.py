"""Envelope (variable-band) LDLᵀ of a sparse symmetric tangent, with its inertia.

A 1D model numbered node by node (the beam) has a tangent whose non-zeros hug the diagonal:
row i couples to columns ``first[i] … i`` only, and the LDLᵀ factor of such a matrix fills in
nowhere outside that *envelope*. Factorising inside it costs about Σᵢ (i − first[i])²
operations, against n·b² for a fixed band of half-width b (the wider rows of the contact pairs
or of higher core levels do not widen the whole band), with none of a general sparse LU's
symbolic overhead. Two storages (chosen per pattern by their operation counts,
:data:`COLUMN_ADVANTAGE`): ``"columns"``, column j holding rows j … last[j] with last
non-decreasing (a band is the special case), factorised right-looking by contiguous AXPYs
(:func:`_column_ldlt`) or, longer than :data:`PANEL_MIN_WIDTH` on average, by panels of
eight columns and rank-8 updates (:func:`_panel_ldlt`); ``"envelope"``, the row envelope
exactly, factorised row by row by Crout's dot products (:func:`_ldlt`). The storage is loaded
from the CSR values by runs of consecutive slots (:attr:`EnvelopeStructure.runs`) into an
array reused while no factorisation holds it (:meth:`EnvelopeStructure.storage_array`).

The factorisation is the one :class:`sandwich.solver.sparse.SparseFactorization` asks SuperLU
for — symmetric, without pivoting, so ``K = L D Lᵀ`` and, by Sylvester's law of inertia, the
number of negative entries of D is the number of negative eigenvalues of K (what the path
follower needs for bifurcations). It is trusted under the same tests as there: every pivot
finite and above ``singular_rtol · n · max|K|`` and the factors' growth below
:data:`~sandwich.solver.sparse.GROWTH_LIMIT`. The pivots depend on the order: when the tests
refuse the LDLᵀ in reverse Cuthill-McKee order, :func:`factorize_envelope` tries the natural
order (the one SuperLU's pivot-free LDLᵀ uses) in its own envelope; when that is refused too it
falls back to SuperLU's pivoting LU (:class:`~sandwich.solver.sparse.SparseFactorization`,
inertia unknown) — not to SuperLU's pivot-free LDLᵀ, the same factorisation under the same
tests. LAPACK has no banded LDLᵀ with pivoting for indefinite matrices:
``dpbtrf`` (banded Cholesky) fails on every state past the first bifurcation and ``dgbtrf``
(banded LU with row interchanges) gives only the sign of det K, not the count of negative
eigenvalues (docs/beam_speed.md).

The envelope storage is fixed by the pattern, but its rows are factorised from where their
*values* start (:func:`_numerical_first`, one scan per factorisation): a pattern holds
couplings that are zero in most states — a closest-point contact pair couples its face node to
every searched core segment, its tangent lives on the chosen one only, and an open pair's is
zero — and the factor has no fill before a row's first non-zero (the same L and D, fewer
operations: fig. 5 at core level 1, 240 elements, 3.2 → 1.3 ms per factorisation,
docs/beam_speed.md).

A structure can also be built on the envelope of the values of the first matrix it serves
(``EnvelopeStructure.of(K, numeric=True)``, what the beam model asks for): narrower still, and
with column storage affordable again (fig. 5, 240 elements: level 1 1.3 → 0.9 ms, level 3
19.6 → 11.1 ms per factorisation). Pattern entries outside it must be zero; a matrix with a
non-zero there makes :func:`factorize_envelope` widen the structure and hand the widened one
back with the factorisation (fig. 5 path at level 2: 13 widenings in 138 iterations, as contact
pairs close and projections move to new segments). The widened structure is the union of the
patterns in the same ordering, unless a fresh order of the union is clearly narrower: a first
matrix with DOFs coupled to nothing (open contact pairs over a debond) has them ordered at one
end by RCM, and the union in that order spans the matrix (fig. 7 c3 at core level 3: half-band
9991 of 10116 DOFs, 1358 Mflop per factorisation; reordered, 100 and 55 Mflop).

The symbolic work — ordering (natural or reverse Cuthill-McKee, whichever has the smaller
envelope), ``first``, the storage and the map from CSR slots to its positions — is an
:class:`EnvelopeStructure`, computed once per sparsity pattern and reused for every matrix of
that pattern. A symmetric permutation P K Pᵀ is congruent to K: the inertia does not depend on
the ordering.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from sandwich.solver.jit import njit
from sandwich.solver.spares import free_array
from sandwich.solver.sparse import GROWTH_LIMIT, SingularTangentError, SparseFactorization

__all__ = ["EnvelopeFactorization", "EnvelopeStructure", "factorize_envelope"]


@njit
def _values_pattern(indptr, indices, data):  # pragma: no cover - compiled
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
def _envelope_first(indptr, indices, order):  # pragma: no cover - compiled
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
def _storage_map(indptr, indices, order, first, last, rowptr, colptr,
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


@dataclass(frozen=True)
class EnvelopeStructure:
    """Symbolic part of an envelope LDLᵀ for one sparsity pattern (computed once)."""

    n: int
    order: np.ndarray  # (n,) new → old
    first: np.ndarray  # (n,) first column of row i (new numbering) in the envelope
    rowptr: np.ndarray  # (n + 1,) row i is env[rowptr[i]: rowptr[i + 1]], columns first[i]..i
    slots: np.ndarray  # CSR slots of the stored triangle's entries (new numbering) …
    positions: np.ndarray  # … and their positions in env
    indptr: np.ndarray  # the pattern it was built for
    indices: np.ndarray
    ordering: str  # "natural" or "rcm"
    storage: str = "envelope"  # or "columns": column j holds rows j..last[j], contiguously
    last: np.ndarray | None = None  # (n,) "columns": last row of column j (non-decreasing)
    colptr: np.ndarray | None = None  # (n + 1,) "columns": column j is env[colptr[j]:colptr[j+1]]
    values_indptr: np.ndarray | None = None  # the pattern the envelope is of (old numbering):
    values_indices: np.ndarray | None = None  # K's, or its values' (numeric), or a union
    fixed_order: bool = False  # built for one given order (the natural variant): kept on widening

    @property
    def size(self) -> int:
        """Number of stored entries (diagonal included)."""
        if self.storage == "columns":
            return int(self.colptr[-1])
        return int(self.rowptr[-1])

    @cached_property
    def runs(self) -> np.ndarray:
        """(slot, position, length) of each stretch of CSR slots stored contiguously.

        The slots in ``positions`` order run in step with their positions over a row's
        stretch of the pattern in the natural order (fig. 5, 240 elements: 4 entries per run at
        core level 1, 14 at level 3; about 1 in reverse Cuthill-McKee's): :func:`_load` copies
        runs, without reading one index per entry.
        """
        return _runs(self.slots, self.positions)

    @cached_property
    def outside(self) -> np.ndarray:
        """CSR slots of the pattern's entries outside a numeric envelope (position −1)."""
        return np.ascontiguousarray(self.slots[self.positions < 0], dtype=np.int64)

    def storage_array(self) -> np.ndarray:
        """An array of :attr:`size` for a factorisation's storage (its content arbitrary).

        :func:`sandwich.solver.spares.free_array` over this structure's spares (960 elements
        at core level 3: 28 MB, 6900 page faults per factorisation when new); up to
        :data:`SPARE_STORAGE` are kept (the path follower keeps the last converged state's
        factorisation while the corrector makes new ones).
        """
        return free_array(self.__dict__.setdefault("_spares", []), self.size, SPARE_STORAGE)

    @cached_property
    def panels(self) -> bool:
        """Whether the factorisation runs by panels (:func:`_panel_ldlt`): wide columns."""
        return (self.storage == "columns" and self.n > 0
                and float(np.mean(self.last - np.arange(self.n))) > PANEL_MIN_WIDTH)

    @property
    def flops(self) -> float:
        """Floating-point operations of one factorisation (multiply + add = 2), as executed."""
        if self.storage == "columns":
            return _panel_flops(self.last) if self.panels else _column_flops(self.last)
        return float(_count_flops(self.first, self.n))

    @property
    def solve_flops(self) -> float:
        """Floating-point operations of one solve with one right-hand side."""
        return float(4 * (self.size - self.n) + self.n)

    @cached_property
    def half_bandwidth(self) -> int:
        """Largest i − first[i]."""
        return int(np.max(np.arange(self.n) - self.first)) if self.n else 0

    def matches(self, K: sp.csr_matrix) -> bool:
        """Whether ``K`` (CSR) has the pattern this structure was built for.

        Index arrays over the same memory as the structure's are its pattern without a
        comparison (:func:`_same_memory`); others are compared entry by entry.
        """
        return (K.shape == (self.n, self.n) and K.indptr.size == self.indptr.size
                and K.indices.size == self.indices.size
                and (_same_memory(K.indices, self.indices)
                     or np.array_equal(K.indices, self.indices))
                and (_same_memory(K.indptr, self.indptr)
                     or np.array_equal(K.indptr, self.indptr)))

    def natural_variant(self, K: sp.csr_matrix) -> EnvelopeStructure:
        """The natural-order numeric structure of ``K``'s pattern, built once and kept.

        :func:`factorize_envelope`'s second try when the LDLᵀ in this (RCM) order is refused.
        """
        natural = self.__dict__.get("_natural")
        if natural is None or not natural.matches(K):
            natural = EnvelopeStructure.of(K, numeric=True, ordering="natural")
            self.keep_natural(natural, preferred=False)
        return natural

    def keep_natural(self, natural: EnvelopeStructure, preferred: bool) -> None:
        """Keep ``natural`` as this structure's natural-order variant (widened, if it was).

        ``preferred``: whether the natural order is to be tried first next time (it was trusted
        where this order was refused; a later refusal in it hands the first try back).
        """
        self.__dict__["_natural"] = natural
        self.__dict__["_natural_first"] = preferred

    @property
    def kept_natural(self) -> EnvelopeStructure | None:
        """The natural-order variant kept by :meth:`keep_natural` (None before any)."""
        return self.__dict__.get("_natural")

    @property
    def natural_first(self) -> bool:
        """Whether :func:`factorize_envelope` tries the natural-order variant first."""
        return bool(self.__dict__.get("_natural_first", False))

    @classmethod
    def of(cls, K: sp.spmatrix, *, numeric: bool = False,
           widen: EnvelopeStructure | None = None,
           ordering: str | None = None) -> EnvelopeStructure:
        """Structure for the pattern of ``K`` (CSR, canonical: sorted, no duplicates).

        ``numeric``: the envelope of K's non-zero *values* (its explicit zeros left out; the
        diagonal always in), still mapped from K's whole CSR pattern: a pattern entry outside
        it must be zero when a matrix is loaded, else :func:`factorize_envelope` widens the
        structure (``widen``: the union of K's values with the pattern that structure is of).
        The union keeps ``widen``'s order unless a fresh order of it (natural or RCM) has an
        envelope below 0.9× its own. ``ordering``: ``"natural"`` to take
        that order without comparing it with RCM's (and to keep it when widened).
        """
        from scipy.sparse.csgraph import reverse_cuthill_mckee

        K = _canonical_csr(K)
        n = K.shape[0]
        indptr, indices = K.indptr, K.indices
        p_indptr, p_indices = indptr, indices
        if numeric:  # the non-zero values' pattern, with the diagonal
            p_indptr, p_indices = _values_pattern(indptr, indices,
                                                  np.asarray(K.data, dtype=float))
        fixed = ordering == "natural" or (widen is not None and widen.fixed_order)
        if widen is not None and widen.values_indptr is not None:
            p_indptr, p_indices = _pattern_union(n, (p_indptr, p_indices),
                                                 (widen.values_indptr, widen.values_indices))
        candidates = [("natural", np.arange(n))]
        if widen is not None:
            # the old order first (kept unless clearly beaten: no reordering churn); a fresh
            # one matters where the first matrix left DOFs uncoupled (open contact pairs over
            # a debond: RCM put them at one end, and the union in that order spans the matrix)
            candidates = [(widen.ordering, widen.order)]
            if not fixed:  # (a fresh natural order is the old one if that was natural)
                candidates += [("natural", np.arange(n))] if widen.ordering != "natural" else []
                candidates.append(("rcm", None))
        elif n > 1 and ordering != "natural":
            candidates.append(("rcm", None))
        best = None
        for name, order in candidates:
            if order is None:
                order = np.asarray(reverse_cuthill_mckee(
                    sp.csr_matrix((np.ones(p_indices.size), p_indices, p_indptr),
                                  shape=K.shape), symmetric_mode=True), dtype=np.int64)
            first = _envelope_first(p_indptr, p_indices, np.asarray(order, dtype=np.int64))
            if widen is not None and order is widen.order:
                first = np.minimum(first, widen.first)
            p = np.arange(n) - first
            cost = float(np.sum(p * p))
            if best is None or cost < 0.9 * best[0]:  # natural unless RCM is clearly better
                best = (cost, name, order, first)
        _, name, order, first = best
        rowptr = np.zeros(n + 1, dtype=np.int64)
        rowptr[1:] = np.cumsum(np.arange(n) - first + 1)
        last = _column_last(first)
        # Column storage does the zeros between a column's rows too (rows i > j whose first[i]
        # is above j), but as contiguous AXPYs that vectorise (measured ≈ 3× the rate of the
        # row envelope's short dot products): take it while it costs less than
        # COLUMN_ADVANTAGE × the envelope's operations.
        columns = _column_flops(last) <= COLUMN_ADVANTAGE * float(_count_flops(first, n))
        colptr = np.zeros(n + 1, dtype=np.int64)
        colptr[1:] = np.cumsum(last - np.arange(n) + 1)
        # Each storage is filled from the triangle whose CSR rows it stores contiguously (K is
        # symmetric): column j = K[j, j:last_j + 1] (upper), the envelope's row i
        # = K[i, first_i:i + 1] (lower). Pattern entries outside a numeric envelope: −1.
        slots, positions = _storage_map(indptr, indices,
                                        np.asarray(order, dtype=np.int64), first, last,
                                        rowptr, colptr, bool(columns))
        return cls(n=n, order=order, first=first.astype(np.int64), rowptr=rowptr,
                   slots=slots, positions=positions,
                   indptr=indptr, indices=indices, ordering=name,
                   storage="columns" if columns else "envelope",
                   last=last if columns else None, colptr=colptr if columns else None,
                   values_indptr=p_indptr, values_indices=p_indices, fixed_order=fixed)


def _same_memory(a: np.ndarray, b: np.ndarray) -> bool:
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


def _pattern_union(n: int, a: tuple[np.ndarray, np.ndarray],
                   b: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """CSR pattern (indptr, indices) of the union of two n × n patterns, sorted.

    Both patterns' rows must be sorted (canonical CSR, :func:`_values_pattern`'s, or an earlier
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


#: Storage arrays kept for reuse per structure (:meth:`EnvelopeStructure.storage_array`).
SPARE_STORAGE = 3

#: Column storage is used when its operation count is at most this multiple of the envelope's.
COLUMN_ADVANTAGE = 2.5


def _column_last(first: np.ndarray) -> np.ndarray:
    """last[j] = the largest row i with first[i] ≤ j (at least j): non-decreasing in j.

    Every entry (i, k) the factor can fill (first[i] ≤ k ≤ i) lies in column k above
    last[k], and last[k] ≥ last[j] for k > j: the right-looking updates stay in the columns.
    """
    n = first.size
    top = np.full(n, -1, dtype=np.int64)
    np.maximum.at(top, first, np.arange(n))  # n entries: cheap
    return np.maximum(np.maximum.accumulate(top), np.arange(n))


def _column_flops(last: np.ndarray) -> float:
    """Operations of :func:`_column_ldlt`.

    Per column j with m = last[j] − j entries below the diagonal: m divisions, m products and
    m(m + 1)/2 multiply-adds.
    """
    m = (last - np.arange(last.size)).astype(float)
    return float(np.sum(2 * m + m * (m + 1)))


def _panel_flops(last: np.ndarray) -> float:
    """Operations of :func:`_panel_ldlt`, its zeros included.

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


def _canonical_csr(K: object) -> sp.csr_matrix:
    A = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"tangent must be square, got shape {A.shape}")
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


@njit
def _count_flops(first, n):  # pragma: no cover - compiled
    """Operations of :func:`_ldlt`: 2 per inner multiply-add, 3 per off-diagonal (L, d).

    ``first``: the rows' first columns (a structure's, or the values' ``lo`` of one matrix).
    """
    total = 0
    for i in range(n):
        fi = first[i]
        for j in range(fi, i):
            k0 = fi if fi > first[j] else first[j]
            total += 2 * (j - k0) + 3
    return total


@njit
def _runs(slots, positions):  # pragma: no cover - compiled
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


@njit(reassociate=True)
def _load(data, runs, outside, env):  # pragma: no cover - compiled
    """Storage ``env`` (any content) filled from the stored triangle's CSR values; max |K|.

    ``runs[t] = (slot, position, length)``: CSR values ``data[slot:slot + length]`` go to
    ``env[position:position + length]`` (:attr:`EnvelopeStructure.runs`, contiguous copies);
    ``outside``: the CSR slots of pattern entries a numeric structure has no place for.
    NaN instead of the max if one value is not finite (v · 0 is NaN exactly for inf and NaN);
    K is symmetric, so this is max |K|. Also whether a non-zero value fell outside the storage.
    """
    env[:] = 0.0
    kmax = 0.0
    poison = 0.0
    for t in range(runs.shape[0]):
        s0, p0, m = runs[t, 0], runs[t, 1], runs[t, 2]
        src = data[s0:s0 + m]
        dst = env[p0:p0 + m]
        for r in range(m):
            v = src[r]
            dst[r] = v
            a = abs(v)
            kmax = a if a > kmax else kmax
            poison += v * 0.0
    spilled = False  # a non-zero where a numeric envelope has no place
    for t in range(outside.size):
        v = data[outside[t]]
        spilled |= v != 0.0
        a = abs(v)
        kmax = a if a > kmax else kmax
        poison += v * 0.0
    return (kmax if poison == 0.0 else np.nan), spilled


@njit
def _numerical_first(env, rowptr, first, n):  # pragma: no cover - compiled
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


@njit
def _record_pivot(d, finite, dmin, ldmax, negative):  # pragma: no cover - compiled
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


@njit(reassociate=True)
def _ldlt(env, rowptr, first, lo, n, w):  # pragma: no cover - compiled
    """In-place envelope LDLᵀ (row-by-row Crout): L below the diagonal, D on it.

    Row i: w_j = a_ij − Σ_k w_k L_jk (k from max(lo_i, lo_j) to j − 1) is (L D)_ij, then
    L_ij = w_j / d_j and d_i = a_ii − Σ_j w_j L_ij. ``first`` places the rows in ``env``;
    ``lo`` ≥ ``first`` (:func:`_numerical_first`) is where each row's values start: the
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
        finite, dmin, ldmax, negative = _record_pivot(d, finite, dmin, ldmax, negative)
    if not finite:
        dmin = np.nan
    return negative, dmin, ldmax, lmax


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
def _column_ldlt(env, colptr, last, n):  # pragma: no cover - compiled
    """In-place LDLᵀ in column storage, env[colptr[j] + (i − j)] = K[i, j] (right-looking).

    Column j: d_j = K[j, j], l_ij = K[i, j] / d_j, then every later column k ≤ last[j] loses
    l_kj d_j l_(k..last_j) j. Columns go in panels of four: a panel's columns are factorised
    and update each other one by one (AXPYs), then every later column they reach loses the
    four columns' terms in one pass (a rank-4 update: each entry of the trailing column is
    read and written once, not four times; last[j] is non-decreasing, so the rows split into
    stretches reached by 4, 3, 2 and 1 of the panel's columns), two trailing columns at a time
    (:func:`_paired_update`, :func:`_paired_stairs`). The same factorisation as column by
    column, the sums of the four terms in another order (round-off). Same returns as
    :func:`_ldlt`.
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
            finite, dmin, ldmax, negative = _record_pivot(d, finite, dmin, ldmax, negative)
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
    """:func:`_column_ldlt`'s rank-4 update by a panel whose four columns all end on row A.

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
    """:func:`_column_ldlt`'s rank-4 update by a panel whose columns end on rows a0 ≤ … ≤ a3.

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


#: Columns per panel of :func:`_panel_ldlt` (its trailing update is a rank-8 update).
PANEL = 8
#: Column storage whose columns hold more than this many entries below the diagonal on
#: average (mean of last[j] − j) is factorised by :func:`_panel_ldlt`, else by
#: :func:`_column_ldlt`. fig. 5's tangents (JIT, best of 20): core level 1, mean 26 — columns
#: faster (240 elements 0.54 against 0.58 ms; 1920 elements, whose contact couplings reach 66
#: rows: 4.70 against 4.96 ms); level 2, mean 49: panels 1.90 against 2.25 ms; level 3, mean
#: 72: 4.46 against 5.60 ms.
PANEL_MIN_WIDTH = 36


@njit(reassociate=True)
def _panel_ldlt(env, colptr, last, n):  # pragma: no cover - compiled
    """In-place LDLᵀ in column storage (as :func:`_column_ldlt`), by panels of PANEL columns.

    Panel j … j + 7 (rows up to R = last[j + 7]): each column is updated by the panel's
    earlier ones (left-looking), scaled by its pivot (l = (L D)/d, one reciprocal per column),
    and copied into P[p] = L[j:R + 1, j + p] and C[p] = (L D)[j:R + 1, j + p], zero outside
    its rows. Then every trailing column k ≤ R loses Σ_p C[p, k − j] · P[p, k − j:] (rows k … R)
    in one pass: a rank-8 update reading and writing each trailing entry once, its eight
    sources in P (one stretch of memory, not the storage that is written, so LLVM vectorises
    it with one overlap check per source; the same loop over the storage's own columns has
    too many to check). The same factorisation as :func:`_column_ldlt`, the terms summed in
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
            finite, dmin, ldmax, negative = _record_pivot(d, finite, dmin, ldmax, negative)
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


@njit(reassociate=True)
def _column_solve(env, colptr, last, n, order, rhs, x):  # pragma: no cover - compiled
    """Solve K x = rhs with the factors of :func:`_column_ldlt`; rhs, x of shape (n, m).

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
    """Column ``c`` of :func:`_column_solve` alone (``y``: work array of n)."""
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


@njit(reassociate=True)
def _solve(env, rowptr, first, lo, n, order, b, x):  # pragma: no cover - compiled
    """Solve K x = b with K = Pᵀ L D Lᵀ P; b, x of shape (n, m), m right-hand sides.

    Row i of L is stored from ``first[i]``, non-zero from ``lo[i]`` on (as in :func:`_ldlt`).
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


class EnvelopeFactorization:
    """Envelope LDLᵀ of a symmetric matrix whose pivot-free factorisation is trustworthy.

    Build with :func:`factorize_envelope` (which falls back to SuperLU when it is not).

    Attributes
    ----------
    structure : EnvelopeStructure
        The symbolic part used.
    """

    pivoted = False
    solves_columns = True  # solve() takes (n, m) right-hand sides, in pairs per sweep

    def __init__(self, env: np.ndarray, structure: EnvelopeStructure, negative: int,
                 lo: np.ndarray | None = None) -> None:
        self._env = env
        self.structure = structure
        self.size = structure.n
        self._negative = negative
        self._lo = structure.first if lo is None else lo  # "envelope": where rows are non-zero

    @property
    def flops(self) -> float:
        """Operations this factorisation did: the numerical envelope's for ``"envelope"``."""
        if self.structure.storage == "columns":
            return self.structure.flops
        return float(_count_flops(self._lo, self.size))  # the same count on the values' rows

    @property
    def negative_pivots(self) -> int:
        """Number of negative eigenvalues of ``K`` (Sylvester)."""
        return self._negative

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return ``K⁻¹ b`` for a vector (or a matrix of right-hand sides, one per column)."""
        b = np.asarray(b, dtype=float)
        s = self.structure
        if b.shape[:1] != (s.n,) or b.ndim > 2:
            raise ValueError(f"expected {s.n} rows, got shape {b.shape}")
        B = np.ascontiguousarray(b.reshape(s.n, -1))
        x = np.empty(B.shape)
        if s.storage == "columns":
            _column_solve(self._env, s.colptr, s.last, s.n, s.order, B, x)
        else:
            _solve(self._env, s.rowptr, s.first, self._lo, s.n, s.order, B, x)
        return x.reshape(b.shape)


def factorize_envelope(
    K: object,
    structure: EnvelopeStructure | None = None,
    singular_rtol: float = float(np.finfo(float).eps),
) -> EnvelopeFactorization | SparseFactorization:
    """Factorise the symmetric ``K`` in its envelope, or fall back to SuperLU.

    Parameters
    ----------
    K
        Symmetric matrix (CSR preferred; one triangle is read).
    structure
        Symbolic part for K's pattern (computed if omitted or if it does not match).
    singular_rtol
        As in :class:`~sandwich.solver.sparse.SparseFactorization`.

    Returns
    -------
    EnvelopeFactorization or SparseFactorization
        The latter (SuperLU) when the pivot-free LDLᵀ has a tiny pivot or too much growth.

    Raises
    ------
    SingularTangentError
        Non-finite entries, the zero matrix, or (from the fallback) a singular matrix.
    """
    A = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
    if structure is None or not structure.matches(A):  # a match has canonical indices
        A = _canonical_csr(A)
        structure = EnvelopeStructure.of(A)
    if A.shape[0] == 0:
        return SparseFactorization(A)
    tried_natural = structure.natural_first
    if tried_natural:
        # The last tangent refused in this (RCM) order was trusted in the natural one: the
        # next are tried there first (the path's state changes slowly), not refused again.
        fac = _trusted_ldlt(A, structure.natural_variant(A), singular_rtol)
        if fac is not None:
            structure.keep_natural(fac.structure, preferred=True)
            return fac
        structure.keep_natural(structure.natural_variant(A), preferred=False)
    fac = _trusted_ldlt(A, structure, singular_rtol)
    if fac is None and structure.ordering != "natural" and not tried_natural:
        # The pivot-free LDLᵀ depends on the order: where reverse Cuthill-McKee's is refused
        # the natural one is often trusted (fig. 5, 3840 elements, a compressed debonded face).
        fac = _trusted_ldlt(A, structure.natural_variant(A), singular_rtol)
        if fac is not None:
            structure.keep_natural(fac.structure, preferred=True)
    if fac is None:
        # Refused in the natural order: SuperLU's pivot-free LDLᵀ is that same factorisation
        # under the same tests, so straight to its pivoting LU (inertia unknown).
        return SparseFactorization(A, singular_rtol, pivot_free=False)
    return fac


def _trusted_ldlt(
    A: sp.csr_matrix, structure: EnvelopeStructure, singular_rtol: float
) -> EnvelopeFactorization | None:
    """The envelope LDLᵀ of ``A`` in ``structure``, or None when its tests refuse it.

    A numeric structure that meets a coupling outside it is widened once (the factorisation's
    ``structure`` is then the widened one).
    """
    n = A.shape[0]
    env = structure.storage_array()
    kmax, outside = _load(A.data, structure.runs, structure.outside, env)
    if outside:  # a numeric structure met a coupling its envelope lacks: widen it, once
        structure = EnvelopeStructure.of(A, numeric=True, widen=structure)
        env = structure.storage_array()
        kmax, outside = _load(A.data, structure.runs, structure.outside, env)
        assert not outside
    if not np.isfinite(kmax):
        raise SingularTangentError("tangent has non-finite entries")
    if kmax == 0.0:
        raise SingularTangentError("tangent is the zero matrix")
    lo = None
    if structure.storage == "columns":
        ldlt = _panel_ldlt if structure.panels else _column_ldlt
        negative, dmin, ldmax, lmax = ldlt(env, structure.colptr, structure.last, n)
    else:
        lo = _numerical_first(env, structure.rowptr, structure.first, n)
        negative, dmin, ldmax, lmax = _ldlt(env, structure.rowptr, structure.first, lo, n,
                                            np.empty(n))
    growth = max(ldmax / kmax, lmax)
    if (not np.isfinite(dmin) or dmin <= singular_rtol * n * kmax
            or not np.isfinite(growth) or growth > GROWTH_LIMIT):
        return None
    return EnvelopeFactorization(env, structure, int(negative), lo)
