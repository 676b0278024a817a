"""SparseFactorization: inertia (Sylvester) against numpy.linalg.eigvalsh, fallback, singularity."""

import numpy as np
import pytest
import scipy.sparse as sp

from sandwich.solver import SingularTangentError, SparseFactorization, factorize_symmetric


def _banded_symmetric(rng, n, bandwidth):
    """Random symmetric banded matrix with diagonal entries of both signs (indefinite)."""
    diags = [rng.normal(size=n - k) for k in range(1, bandwidth + 1)]
    A = sp.diags(diags, list(range(1, bandwidth + 1)), shape=(n, n))
    A = A + A.T + sp.diags(rng.normal(scale=3.0, size=n))
    return A.tocsr()


@pytest.mark.parametrize("seed", range(12))
def test_inertia_matches_eigvalsh_on_random_indefinite_banded(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 40))
    A = _banded_symmetric(rng, n, int(rng.integers(1, 4)))
    eig = np.linalg.eigvalsh(A.toarray())
    assert eig.min() < 0 < eig.max()  # really indefinite
    fac = SparseFactorization(A)
    assert fac.negative_pivots is not None
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = rng.normal(size=n)
    x = fac.solve(b)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ x - b) <= 1e-12 * cond * np.linalg.norm(b)


def test_definite_matrix_has_no_negative_pivot_and_negated_has_n():
    rng = np.random.default_rng(7)
    B = rng.normal(size=(6, 6))
    spd = B @ B.T + 6 * np.eye(6)
    assert factorize_symmetric(spd).negative_pivots == 0
    assert factorize_symmetric(-spd).negative_pivots == 6


def test_zero_diagonal_falls_back_to_pivoting_lu_with_unknown_inertia():
    # [[0, 1], [1, 0]] is non-singular (eigenvalues ±1) but has no pivot-free LDLᵀ.
    A = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0]])
    fac = SparseFactorization(sp.csc_matrix(A))
    assert fac.negative_pivots is None and fac.pivoted
    b = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(A @ fac.solve(b), b, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    "K",
    [np.array([[1.0, 1.0], [1.0, 1.0]]), np.zeros((3, 3)), np.array([[1.0, np.nan], [np.nan, 1.0]]),
     np.array([[1.0, 1.0], [1.0, 1.0 + 2.3e-16]])],
    ids=["rank-one", "zero", "nan", "singular-to-precision"],
)
def test_singular_tangent_raises(K):
    with pytest.raises(SingularTangentError):
        SparseFactorization(K)
