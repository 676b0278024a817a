"""Factorisations of a beam model's tangents, with the symbolic parts kept per sparsity pattern.

The envelope LDLᵀ (:mod:`sandwich.solver.envelope`) orders a matrix and lays out the envelope of
its values once per structure; :class:`TangentFactorisations` keeps those structures for the
model's reduced pattern, so that each tangent of a path costs only the numeric factorisation.
SuperLU (:class:`sandwich.solver.sparse.SparseFactorization`) is the fallback when the
pivot-free LDLᵀ is untrustworthy (decided by the envelope), or when numba is not installed.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from sandwich.beam.assembly import ReducedPattern, compiled_kernels
from sandwich.solver.sparse import SparseFactorization

KEPT_STRUCTURES = 4  # envelope structures kept per pattern (the pattern's own first)


def embed_in_pattern(K: sp.csr_matrix, pattern: ReducedPattern) -> sp.csr_matrix | None:
    """``K`` on ``pattern``'s sparsity (explicit zeros added), if its non-zeros lie inside it.

    None where an entry of ``K`` lies outside, or without numba.
    """
    kernels = compiled_kernels()
    if K.shape != (pattern.n, pattern.n) or kernels is None:
        return None
    if not K.has_canonical_format:
        K = K.copy()
        K.sum_duplicates()
    data = np.zeros(pattern.indices.size)
    if not kernels.embed_pattern(pattern.indptr, pattern.indices, K.indptr, K.indices,
                                 np.asarray(K.data, dtype=float), data):
        return None
    return sp.csr_matrix((data, pattern.indices, pattern.indptr), shape=K.shape)


class TangentFactorisations:
    """Envelope LDLᵀ factorisations of the tangents on one reduced pattern, with their inertia.

    The symbolic part (ordering, envelope of the values) is computed once per structure and
    kept (:attr:`structures`, at most :data:`KEPT_STRUCTURES`), widened when a tangent has a
    coupling outside it. The structures belong to one pattern: a matrix factorised for another
    (the compiled path's pattern grew) starts them afresh. A structure dropped (replaced by its
    widening, pushed out, or of the old pattern) is retired
    (:meth:`~sandwich.solver.envelope.EnvelopeStructure.retire`): the factorisations still alive
    on it (the path's last states', the corrector's) keep only what they solve with, not maps
    of the pattern's size each.
    """

    def __init__(self) -> None:
        self.structures: list = []  # the model's pattern's first
        self._pattern: ReducedPattern | None = None

    def factorize(self, K: sp.spmatrix, pattern: ReducedPattern) -> object:
        """Factorisation of ``K`` (``solve``, ``negative_pivots``), for the model's ``pattern``."""
        try:
            from sandwich.solver.envelope import EnvelopeStructure, factorize_envelope
        except ImportError:  # no numba
            return SparseFactorization(K)
        if pattern is not self._pattern:
            _retire(self.structures)
            self.structures, self._pattern = [], pattern
        K = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
        known = self.structures
        structure = next((s for s in known if s.matches(K)), None)
        if structure is None:
            embedded = embed_in_pattern(K, pattern)  # e.g. K0 + linear contact: sums drop zeros
            if embedded is not None:
                K = embedded
                structure = next((s for s in known if s.matches(K)), None)
        if structure is None:
            # the envelope of the values: the pattern's contact couplings to unchosen segments
            # and open pairs are zero; a matrix with a coupling outside it widens it
            structure = EnvelopeStructure.of(K, numeric=True)
            known.insert(1 if known else 0, structure)  # keep the model's own pattern's
            _retire(known[KEPT_STRUCTURES:])
            del known[KEPT_STRUCTURES:]
        fac = factorize_envelope(K, structure)
        widened = getattr(fac, "structure", structure)
        if (widened is not structure and widened.matches(K)
                and widened is not structure.kept_natural):  # not the natural-order retry's
            known[known.index(structure)] = widened
            structure.retire()
        return fac


def _retire(structures: list) -> None:
    """Retire the envelope structures no longer kept (their factorisations still solve)."""
    for structure in structures:
        structure.retire()
