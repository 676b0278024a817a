"""The symbolic part of an envelope LDLᵀ: ordering, envelope, storage (:class:`EnvelopeStructure`).

The symbolic work — ordering (natural or reverse Cuthill-McKee, whichever has the smaller
envelope), ``first``, the storage and the map from CSR slots to its positions — is an
:class:`EnvelopeStructure`, computed once per sparsity pattern and reused for every matrix of
that pattern. A symmetric permutation P K Pᵀ is congruent to K: the inertia does not depend on
the ordering. Of the two storages the one with fewer operations is taken, the columns'
counted against :data:`COLUMN_ADVANTAGE` × the row envelope's; column storage longer than
:data:`PANEL_MIN_WIDTH` on average is factorised by panels. Both are module attributes read
when a structure is built: set them here (``sandwich.solver.envelope.structure``) to force a
storage or kernel.

A structure can also be built on the envelope of the values of the first matrix it serves
(``EnvelopeStructure.of(K, numeric=True)``, what the beam model asks for): narrower still, and
with column storage affordable again (fig. 5, 240 elements: level 1 1.3 → 0.9 ms, level 3
19.6 → 11.1 ms per factorisation). Pattern entries outside it must be zero; a matrix with a
non-zero there makes :func:`factorize_envelope` widen the structure and hand the
widened one back with the factorisation (fig. 5 path at level 2: 13 widenings in 138
iterations, as contact pairs close and projections move to new segments). The widened structure
is the union of the patterns in the same ordering, unless a fresh order of the union is clearly
narrower: a first matrix with DOFs coupled to nothing (open contact pairs over a debond) has
them ordered at one end by RCM, and the union in that order spans the matrix (fig. 7 c3 at core
level 3: half-band 9991 of 10116 DOFs, 1358 Mflop per factorisation; reordered, 100 and 55
Mflop).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from sandwich.solver.envelope.columns import column_flops
from sandwich.solver.envelope.panels import panel_flops
from sandwich.solver.envelope.patterns import (
    canonical_csr,
    column_last,
    envelope_first,
    pattern_union,
    same_memory,
    slot_runs,
    storage_map,
    values_pattern,
)
from sandwich.solver.envelope.rows import row_flops
from sandwich.solver.spares import free_array

__all__ = ["COLUMN_ADVANTAGE", "PANEL_MIN_WIDTH", "SPARE_STORAGE", "EnvelopeStructure"]


#: Storage arrays kept for reuse per structure (:meth:`EnvelopeStructure.storage_array`).
SPARE_STORAGE = 3

#: Column storage is used when its operation count is at most this multiple of the envelope's.
COLUMN_ADVANTAGE = 2.5


#: Column storage whose columns hold more than this many entries below the diagonal on
#: average (mean of last[j] − j) is factorised by :func:`~.panels.panel_ldlt`, else by
#: :func:`column_ldlt`. fig. 5's tangents (JIT, best of 20): core level 1, mean 26 — columns
#: faster (240 elements 0.54 against 0.58 ms; 1920 elements, whose contact couplings reach 66
#: rows: 4.70 against 4.96 ms); level 2, mean 49: panels 1.90 against 2.25 ms; level 3, mean
#: 72: 4.46 against 5.60 ms.
PANEL_MIN_WIDTH = 36


@dataclass(frozen=True)
class EnvelopeStructure:
    """Symbolic part of an envelope LDLᵀ for one sparsity pattern (computed once)."""

    n: int
    order: np.ndarray  # (n,) new → old
    first: np.ndarray  # (n,) first column of row i (new numbering) in the envelope
    rowptr: np.ndarray  # (n + 1,) row i is env[rowptr[i]: rowptr[i + 1]], columns first[i]..i
    # slots, positions, indptr, indices and values_*: None once retired (:meth:`retire`)
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
        core level 1, 14 at level 3; about 1 in reverse Cuthill-McKee's):
        :func:`~.factorization.load_values` copies runs, without reading one index per entry.
        """
        return slot_runs(self.slots, self.positions)

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

    @property
    def spare_addresses(self) -> tuple[int, ...]:
        """Data addresses of the storage arrays kept for reuse (no reference to them given)."""
        return tuple(spare.ctypes.data for spare in self.__dict__.get("_spares", ()))

    @cached_property
    def panels(self) -> bool:
        """Whether the factorisation runs by panels (:func:`~.panels.panel_ldlt`): wide columns."""
        return (self.storage == "columns" and self.n > 0
                and float(np.mean(self.last - np.arange(self.n))) > PANEL_MIN_WIDTH)

    @property
    def flops(self) -> float:
        """Floating-point operations of one factorisation (multiply + add = 2), as executed."""
        if self.storage == "columns":
            return panel_flops(self.last) if self.panels else column_flops(self.last)
        return float(row_flops(self.first, self.n))

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
        comparison (:func:`same_memory`); others are compared entry by entry. A retired
        structure (:meth:`retire`) matches nothing.
        """
        return (self.indices is not None
                and K.shape == (self.n, self.n) and K.indptr.size == self.indptr.size
                and K.indices.size == self.indices.size
                and (same_memory(K.indices, self.indices)
                     or np.array_equal(K.indices, self.indices))
                and (same_memory(K.indptr, self.indptr)
                     or np.array_equal(K.indptr, self.indptr)))

    def retire(self) -> None:
        """Drop what loads a matrix into this structure, keep what its factorisations solve with.

        For an owner that will not factorise on this structure again (its pattern grew, or a
        widened structure replaced it) while factorisations made on it live on (the path keeps
        the last converged state's, the corrector its iterate's). Their solves need the order
        and the storage layout (``order``, ``first``, ``rowptr``, ``last``, ``colptr``: a few
        n-vectors); the CSR maps, the pattern and the values' pattern it was built of, the
        storage spares and the natural-order variant (retired too) are of the size of the
        pattern: on the default scene at 16 000 elements, core level 1, 190-290 MB per
        structure against a 55-63 MB factor. A retired structure matches no matrix
        (:meth:`matches`), so it is never loaded again.
        """
        natural = self.__dict__.pop("_natural", None)
        if natural is not None and natural is not self:
            natural.retire()
        for name in ("runs", "outside", "_spares", "_natural_first"):
            self.__dict__.pop(name, None)
        for name in ("slots", "positions", "indptr", "indices", "values_indptr",
                     "values_indices"):
            object.__setattr__(self, name, None)  # frozen: its symbolic fields, dropped once

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
        where this order was refused; a later refusal in it hands the first try back). The
        variant it replaces (of an older pattern, or before a widening) is retired.
        """
        old = self.__dict__.get("_natural")
        if old is not None and old is not natural:
            old.retire()
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

        K = canonical_csr(K)
        n = K.shape[0]
        indptr, indices = K.indptr, K.indices
        p_indptr, p_indices = indptr, indices
        if numeric:  # the non-zero values' pattern, with the diagonal
            p_indptr, p_indices = values_pattern(indptr, indices,
                                                 np.asarray(K.data, dtype=float))
        fixed = ordering == "natural" or (widen is not None and widen.fixed_order)
        if widen is not None and widen.values_indptr is not None:
            p_indptr, p_indices = pattern_union(n, (p_indptr, p_indices),
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
            first = envelope_first(p_indptr, p_indices, np.asarray(order, dtype=np.int64))
            if widen is not None and order is widen.order:
                first = np.minimum(first, widen.first)
            p = np.arange(n) - first
            cost = float(np.sum(p * p))
            if best is None or cost < 0.9 * best[0]:  # natural unless RCM is clearly better
                best = (cost, name, order, first)
        _, name, order, first = best
        rowptr = np.zeros(n + 1, dtype=np.int64)
        rowptr[1:] = np.cumsum(np.arange(n) - first + 1)
        last = column_last(first)
        # Column storage does the zeros between a column's rows too (rows i > j whose first[i]
        # is above j), but as contiguous AXPYs that vectorise (measured ≈ 3× the rate of the
        # row envelope's short dot products): take it while it costs less than
        # COLUMN_ADVANTAGE × the envelope's operations.
        columns = column_flops(last) <= COLUMN_ADVANTAGE * float(row_flops(first, n))
        colptr = np.zeros(n + 1, dtype=np.int64)
        colptr[1:] = np.cumsum(last - np.arange(n) + 1)
        # Each storage is filled from the triangle whose CSR rows it stores contiguously (K is
        # symmetric): column j = K[j, j:last_j + 1] (upper), the envelope's row i
        # = K[i, first_i:i + 1] (lower). Pattern entries outside a numeric envelope: −1.
        slots, positions = storage_map(indptr, indices,
                                       np.asarray(order, dtype=np.int64), first, last,
                                       rowptr, colptr, bool(columns))
        return cls(n=n, order=order, first=first.astype(np.int64), rowptr=rowptr,
                   slots=slots, positions=positions,
                   indptr=indptr, indices=indices, ordering=name,
                   storage="columns" if columns else "envelope",
                   last=last if columns else None, colptr=colptr if columns else None,
                   values_indptr=p_indptr, values_indices=p_indices, fixed_order=fixed)
