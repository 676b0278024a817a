"""Factorise in the envelope, trust the LDLᵀ or fall back (:func:`factorize_envelope`).

The factorisation is the one :class:`sandwich.solver.sparse.SparseFactorization` asks SuperLU
for — symmetric, without pivoting, so ``K = L D Lᵀ`` and, by Sylvester's law of inertia, the
number of negative entries of D is the number of negative eigenvalues of K (what the path
follower needs for bifurcations). It is trusted under the same tests as there: every pivot
finite and above ``singular_rtol · n · max|K|`` and the factors' growth below
:data:`~sandwich.solver.sparse.GROWTH_LIMIT` (:func:`trusted_ldlt`). The pivots depend on the
order: when the tests refuse the LDLᵀ in reverse Cuthill-McKee order, :func:`factorize_envelope`
tries the natural order (the one SuperLU's pivot-free LDLᵀ uses) in its own envelope; when that
is refused too it falls back to SuperLU's pivoting LU
(:class:`~sandwich.solver.sparse.SparseFactorization`, inertia unknown) — not to SuperLU's
pivot-free LDLᵀ, the same factorisation under the same tests. LAPACK has no banded LDLᵀ with
pivoting for indefinite matrices: ``dpbtrf`` (banded Cholesky) fails on every state past the
first bifurcation and ``dgbtrf`` (banded LU with row interchanges) gives only the sign of det K,
not the count of negative eigenvalues (docs/speed.md).

The storage is loaded from the CSR values by runs of consecutive slots
(:attr:`~.structure.EnvelopeStructure.runs`, :func:`load_values`) into an array reused while no
factorisation holds it (:meth:`~.structure.EnvelopeStructure.storage_array`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from sandwich.solver.envelope.columns import column_ldlt, column_solve
from sandwich.solver.envelope.panels import panel_ldlt
from sandwich.solver.envelope.patterns import canonical_csr
from sandwich.solver.envelope.rows import numerical_first, row_flops, row_ldlt, row_solve
from sandwich.solver.envelope.structure import EnvelopeStructure
from sandwich.solver.jit import njit
from sandwich.solver.sparse import GROWTH_LIMIT, SingularTangentError, SparseFactorization

__all__ = ["EnvelopeFactorization", "factorize_envelope", "load_values", "trusted_ldlt"]


class EnvelopeFactorization:
    """Envelope LDLᵀ of a symmetric matrix whose pivot-free factorisation is trustworthy.

    Build with :func:`factorize_envelope` (which falls back to SuperLU when it is not).

    Attributes
    ----------
    structure : EnvelopeStructure
        The symbolic part used.
    factors : numpy.ndarray
        L (unit diagonal not stored) and D in the structure's storage: for ``"columns"``,
        ``factors[colptr[j]]`` = d_j and ``factors[colptr[j] + (i − j)]`` = l_ij
        (j < i ≤ last[j]); for ``"envelope"``, row i from ``rowptr[i]``, columns first[i] … i,
        d_i last (entries before the row's first non-zero value left as loaded: zero).
    """

    pivoted = False
    solves_columns = True  # solve() takes (n, m) right-hand sides, in pairs per sweep

    def __init__(self, env: np.ndarray, structure: EnvelopeStructure, negative: int,
                 lo: np.ndarray | None = None) -> None:
        self.factors = env
        self.structure = structure
        self.size = structure.n
        self._negative = negative
        self._lo = structure.first if lo is None else lo  # "envelope": where rows are non-zero

    @property
    def flops(self) -> float:
        """Operations this factorisation did: the numerical envelope's for ``"envelope"``."""
        if self.structure.storage == "columns":
            return self.structure.flops
        return float(row_flops(self._lo, self.size))  # the same count on the values' rows

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
            column_solve(self.factors, s.colptr, s.last, s.n, s.order, B, x)
        else:
            row_solve(self.factors, s.rowptr, s.first, self._lo, s.n, s.order, B, x)
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
        A = canonical_csr(A)
        structure = EnvelopeStructure.of(A)
    if A.shape[0] == 0:
        return SparseFactorization(A)
    tried_natural = structure.natural_first
    if tried_natural:
        # The last tangent refused in this (RCM) order was trusted in the natural one: the
        # next are tried there first (the path's state changes slowly), not refused again.
        fac = trusted_ldlt(A, structure.natural_variant(A), singular_rtol)
        if fac is not None:
            structure.keep_natural(fac.structure, preferred=True)
            return fac
        structure.keep_natural(structure.natural_variant(A), preferred=False)
    fac = trusted_ldlt(A, structure, singular_rtol)
    if fac is None and structure.ordering != "natural" and not tried_natural:
        # The pivot-free LDLᵀ depends on the order: where reverse Cuthill-McKee's is refused
        # the natural one is often trusted (fig. 5, 3840 elements, a compressed debonded face).
        fac = trusted_ldlt(A, structure.natural_variant(A), singular_rtol)
        if fac is not None:
            structure.keep_natural(fac.structure, preferred=True)
    if fac is None:
        # Refused in the natural order: SuperLU's pivot-free LDLᵀ is that same factorisation
        # under the same tests, so straight to its pivoting LU (inertia unknown).
        return SparseFactorization(A, singular_rtol, pivot_free=False)
    return fac


def trusted_ldlt(
    A: sp.csr_matrix, structure: EnvelopeStructure, singular_rtol: float
) -> EnvelopeFactorization | None:
    """The envelope LDLᵀ of ``A`` in ``structure``, or None when its tests refuse it.

    A numeric structure that meets a coupling outside it is widened once (the factorisation's
    ``structure`` is then the widened one).
    """
    n = A.shape[0]
    env = structure.storage_array()
    kmax, outside = load_values(A.data, structure.runs, structure.outside, env)
    if outside:  # a numeric structure met a coupling its envelope lacks: widen it, once
        structure = EnvelopeStructure.of(A, numeric=True, widen=structure)
        env = structure.storage_array()
        kmax, outside = load_values(A.data, structure.runs, structure.outside, env)
        assert not outside
    if not np.isfinite(kmax):
        raise SingularTangentError("tangent has non-finite entries")
    if kmax == 0.0:
        raise SingularTangentError("tangent is the zero matrix")
    lo = None
    if structure.storage == "columns":
        ldlt = panel_ldlt if structure.panels else column_ldlt
        negative, dmin, ldmax, lmax = ldlt(env, structure.colptr, structure.last, n)
    else:
        lo = numerical_first(env, structure.rowptr, structure.first, n)
        negative, dmin, ldmax, lmax = row_ldlt(env, structure.rowptr, structure.first, lo, n,
                                               np.empty(n))
    growth = max(ldmax / kmax, lmax)
    if (not np.isfinite(dmin) or dmin <= singular_rtol * n * kmax
            or not np.isfinite(growth) or growth > GROWTH_LIMIT):
        return None
    return EnvelopeFactorization(env, structure, int(negative), lo)


@njit(reassociate=True)
def load_values(data, runs, outside, env):  # pragma: no cover - compiled
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
