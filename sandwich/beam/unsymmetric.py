"""Tangents that are not symmetric: a damaging cohesive interface under a changing mode mix.

The Benzeggagh–Kenane law's consistent tangent is not symmetric where the damage grows under a
changing mode mix (:mod:`sandwich.cohesive_law`). Newton needs the whole matrix to keep
its quadratic convergence (with the symmetric part alone it converges linearly there, and the
path follower gives up at the load maximum of fig. 5 and c3 given a mixed-mode interface); the
path follower needs an inertia, which a non-symmetric matrix does not have. So the solves are
by a pivoting LU of the matrix itself (SuperLU) and the inertia is that of its symmetric part,
from the model's envelope LDLᵀ: the stability of the state measured by the energy's second
variation along the symmetric part, which is where the structure's own stiffness lives.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from sandwich.solver.sparse import SingularTangentError

#: a matrix whose skew part is below this share of its largest entry is symmetric
SKEW_RTOL = 1e-12


def skew_split(K: sp.csr_matrix) -> sp.csr_matrix | None:
    """The symmetric part ½(K + Kᵀ) of ``K``, or None where ``K`` is symmetric.

    Any matrix (the model's own tangents go through
    :meth:`~sandwich.beam.model.BeamModel.factorize`'s cheaper route from the blocks).
    """
    K = sp.csr_matrix(K)
    skew = abs(K - K.T)
    if skew.nnz and skew.max() > SKEW_RTOL * abs(K).max():
        return ((K + K.T) * 0.5).tocsr()
    return None


class UnsymmetricFactorization:
    """Solves with the LU of ``K``, the inertia of its symmetric part's factorisation ``sym``."""

    def __init__(self, K: sp.csr_matrix, sym: object) -> None:
        self.sym = sym
        try:
            # the model's node-wise numbering keeps the matrix banded: its own order fills
            # less than SuperLU's column orderings (c3 at level 3, 12 065 DOFs: 0.08 s and
            # 2.2 M factor entries against COLAMD's 0.22 s and 3.3 M)
            self.lu = spla.splu(sp.csc_matrix(K), permc_spec="NATURAL")
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            raise SingularTangentError(f"the tangent is singular ({exc})") from exc

    @property
    def negative_pivots(self) -> int | None:
        """Negative eigenvalues of the tangent's symmetric part."""
        return self.sym.negative_pivots

    def solve(self, b: np.ndarray) -> np.ndarray:
        """K⁻¹ b (one or several right-hand sides as columns)."""
        x = self.lu.solve(np.asarray(b, dtype=float))
        if not np.all(np.isfinite(x)):
            raise SingularTangentError("the tangent's LU gave a non-finite solution")
        return x
