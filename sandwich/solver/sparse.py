"""Factorisation of sparse symmetric tangents, with their inertia.

The solver needs two things from a tangent ``K``: solves ``K⁻¹ b`` and, when it can be had
cheaply, the number of negative eigenvalues of ``K`` (to tell limit points from bifurcations and
to orient the arc-length predictor).

For a symmetric ``K`` factorised *without pivoting* as ``K = L U`` (``L`` unit lower triangular),
``U = D Lᵀ`` with ``D = diag(U)``, so ``K = L D Lᵀ`` and, by Sylvester's law of inertia, ``K`` has
as many negative eigenvalues as ``D`` has negative entries. SuperLU is asked for exactly that
factorisation (natural ordering, no row pivoting, symmetric mode). When it cannot deliver it
(a zero or non-finite pivot forced a row interchange, or the factors grew so much that the signs
cannot be trusted), the matrix is factorised again with an ordinary pivoting LU and the inertia is
reported as unknown (``None``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "SingularTangentError",
    "SparseFactorization",
    "SparseSystemMixin",
    "factorize_symmetric",
]

#: Largest ratio max|factor entry| / max|K entry| for which the signs of a pivot-free LDLᵀ are
#: trusted; beyond it the elimination is numerically unstable and a pivoting LU is used instead.
GROWTH_LIMIT = 1.0e8


class SingularTangentError(ArithmeticError):
    """The tangent matrix is singular (to working precision) and cannot be factorised."""


def _as_csc(K: object) -> sp.csc_matrix:
    """Return ``K`` (sparse matrix or array-like) as a square CSC matrix of floats."""
    A = sp.csc_matrix(K, dtype=float) if not sp.issparse(K) else K.tocsc().astype(float)
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"tangent must be square, got shape {A.shape}")
    return A


class SparseFactorization:
    """LU factorisation of a sparse symmetric matrix that also reports its inertia.

    Parameters
    ----------
    K
        Symmetric matrix (any ``scipy.sparse`` format, or a dense array).
    singular_rtol
        A pivot of the (pivoting) LU with ``|u_ii| <= singular_rtol * n * max|K_ij|`` is treated
        as zero, i.e. ``K`` is declared singular.
    pivot_free
        False: straight to the pivoting LU, for a caller that has already seen the pivot-free
        LDLᵀ in the natural order refused (:func:`sandwich.solver.envelope.factorize_envelope`).

    Attributes
    ----------
    pivoted : bool
        ``True`` when the pivot-free LDLᵀ could not be used and a pivoting LU was computed
        (then :attr:`negative_pivots` is ``None``).

    Raises
    ------
    SingularTangentError
        If ``K`` is singular to working precision, or has non-finite entries.
    """

    def __init__(self, K: object, singular_rtol: float = float(np.finfo(float).eps),
                 pivot_free: bool = True) -> None:
        A = _as_csc(K)
        self.size = A.shape[0]
        if A.nnz and not np.all(np.isfinite(A.data)):
            raise SingularTangentError("tangent has non-finite entries")
        kmax = float(np.max(np.abs(A.data))) if A.nnz else 0.0
        if self.size == 0:
            self._lu = None
            self._negative: int | None = 0
            self.pivoted = False
            return
        if kmax == 0.0:
            raise SingularTangentError("tangent is the zero matrix")
        self._negative = None
        self.pivoted = True
        lu = self._ldlt(A, kmax, singular_rtol) if pivot_free else None
        if lu is not None:
            self._negative = int(np.count_nonzero(lu.U.diagonal() < 0.0))
            self.pivoted = False
        else:
            lu = self._pivoting_lu(A, kmax, singular_rtol)
        self._lu = lu

    @staticmethod
    def _ldlt(A: sp.csc_matrix, kmax: float, singular_rtol: float) -> spla.SuperLU | None:
        """Pivot-free factorisation, or ``None`` when it is unusable for the inertia."""
        try:
            lu = spla.splu(
                A,
                permc_spec="NATURAL",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError:  # exactly zero pivot with nothing to swap: decided by the LU below
            return None
        n = A.shape[0]
        if not np.array_equal(lu.perm_r, np.arange(n)) or not np.array_equal(
            lu.perm_c, np.arange(n)
        ):
            return None  # SuperLU had to interchange rows (zero diagonal pivot)
        d = lu.U.diagonal()
        if not np.all(np.isfinite(d)) or np.min(np.abs(d)) <= singular_rtol * n * kmax:
            return None  # tiny pivot: unstable elimination or singular, the LU below decides
        # U has the units of K, L (unit lower triangular) is dimensionless
        growth = max(np.max(np.abs(lu.U.data)) / kmax, np.max(np.abs(lu.L.data)))
        if not np.isfinite(growth) or growth > GROWTH_LIMIT:
            return None
        return lu

    @staticmethod
    def _pivoting_lu(A: sp.csc_matrix, kmax: float, singular_rtol: float) -> spla.SuperLU:
        """Ordinary fill-reducing LU with partial pivoting; raise if ``A`` is singular."""
        try:
            lu = spla.splu(A)
        except RuntimeError as exc:
            raise SingularTangentError(f"tangent is singular: {exc}") from exc
        d = np.abs(lu.U.diagonal())
        n = A.shape[0]
        if not np.all(np.isfinite(d)) or np.min(d) <= singular_rtol * n * kmax:
            raise SingularTangentError(
                f"tangent is singular to working precision (smallest pivot {np.min(d):.3e}, "
                f"largest entry {kmax:.3e}, n = {n})"
            )
        return lu

    @property
    def negative_pivots(self) -> int | None:
        """Number of negative eigenvalues of ``K``, or ``None`` when a pivoting LU was needed."""
        return self._negative

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return ``K⁻¹ b`` for a vector (or a matrix of right-hand sides)."""
        b = np.asarray(b, dtype=float)
        if self._lu is None:
            return b.copy()
        return self._lu.solve(b)


def factorize_symmetric(K: object) -> SparseFactorization:
    """Factorise a symmetric tangent (sparse or dense), with its inertia when available."""
    return SparseFactorization(K)


class SparseSystemMixin:
    """Give a :class:`~sandwich.solver.system.DiscreteSystem` its ``factorize`` in one line.

    Examples
    --------
    >>> class MyModel(SparseSystemMixin):
    ...     def tangent(self, u):
    ...         ...  # return a scipy.sparse symmetric matrix
    """

    def factorize(self, K: object) -> SparseFactorization:
        """Factorise the symmetric tangent ``K`` (see :class:`SparseFactorization`)."""
        return SparseFactorization(K)
