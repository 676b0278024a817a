"""Envelope LDLᵀ (sandwich.solver.envelope): inertia against numpy.linalg.eigvalsh, solves against
dense solves, the SuperLU fallback, the reuse of the symbolic part, and the numba cache rules."""

import dataclasses
import os

import numpy as np
import pytest
import scipy.sparse as sp

from sandwich.solver import SingularTangentError, SparseFactorization, envelope, jit
from sandwich.solver.envelope import EnvelopeFactorization, EnvelopeStructure, factorize_envelope
from sandwich.solver.envelope import factorization as envelope_factorization
from sandwich.solver.envelope import structure as envelope_structure
from sandwich.solver.envelope.panels import panel_flops
from sandwich.solver.envelope.patterns import column_last, pattern_union, same_memory


def _variable_band(rng, n, widths):
    """Random symmetric matrix with row i coupled to up to widths[i] earlier columns,
    indefinite (diagonal of both signs)."""
    rows, cols = [], []
    for i in range(n):
        for j in range(max(0, i - widths[i]), i):
            if rng.random() < 0.7:
                rows.append(i)
                cols.append(j)
    L = sp.csr_matrix((rng.normal(size=len(rows)), (rows, cols)), shape=(n, n))
    return (L + L.T + sp.diags(rng.normal(scale=3.0, size=n))).tocsr()


@pytest.mark.parametrize("storage", ["envelope", "columns"])
@pytest.mark.parametrize("seed", range(10))
def test_inertia_and_solve_on_random_indefinite_envelopes(seed, storage, monkeypatch):
    advantage = 0.0 if storage == "envelope" else 1e9  # force the storage
    monkeypatch.setattr(envelope_structure, "COLUMN_ADVANTAGE", advantage)
    rng = np.random.default_rng(seed)
    n = int(rng.integers(8, 80))
    widths = rng.integers(0, 6, size=n)
    widths[rng.integers(0, n, size=3)] = rng.integers(10, 30, size=3)  # a few wide rows
    A = _variable_band(rng, n, widths)
    A.sort_indices()
    eig = np.linalg.eigvalsh(A.toarray())
    fac = factorize_envelope(A)
    assert isinstance(fac, EnvelopeFactorization) and fac.structure.storage == storage
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = rng.normal(size=(n, 3))  # columns in a pair and one alone
    x = fac.solve(b)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ x - b) <= 1e-12 * cond * np.linalg.norm(b)
    for c in range(3):
        assert np.allclose(fac.solve(b[:, c]), x[:, c], rtol=0, atol=1e-14 * np.abs(x).max())


@pytest.mark.parametrize("seed", range(6))
def test_panels_give_the_inertia_and_solves_of_dense_lapack(seed, monkeypatch):
    """The panel kernel (columns longer than PANEL_MIN_WIDTH on average): negative pivots against
    eigvalsh, solves against the dense matrix, on random indefinite bands whose size is not a
    multiple of the panel (a last, narrower panel) and whose widths vary (zero-padded panel
    columns); and the same factors as the column kernel to round-off."""
    rng = np.random.default_rng(100 + seed)
    n = 8 * int(rng.integers(11, 28)) + int(rng.integers(1, 8))  # a last, narrower panel
    widths = rng.integers(40, 70, size=n)
    widths[rng.integers(0, n, size=5)] = rng.integers(0, 5, size=5)  # a few narrow rows
    A = _variable_band(rng, n, widths)
    A.sort_indices()
    monkeypatch.setattr(envelope_structure, "COLUMN_ADVANTAGE", 1e9)  # column storage
    s = EnvelopeStructure.of(A)
    assert s.storage == "columns" and s.panels and s.n % envelope.PANEL
    _check_column_factorisation(A, s, rng)


def _check_column_factorisation(A, s, rng):
    """Factorise ``A`` in the column-storage structure ``s``: negative pivots against eigvalsh,
    two solves against the dense matrix, and the factors' backward error within Higham's
    bound (Thm 10.3 for LDLᵀ without pivoting: |P K Pᵀ − L D Lᵀ| ≤ γ_n |L| |D| |Lᵀ| entry by
    entry, γ_n = n u / (1 − n u))."""
    n = s.n
    eig = np.linalg.eigvalsh(A.toarray())
    fac = factorize_envelope(A, s)
    assert isinstance(fac, EnvelopeFactorization)
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = rng.normal(size=(n, 2))
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ fac.solve(b) - b) <= 1e-12 * cond * np.linalg.norm(b)
    L, D = _column_factors(fac)
    K = A.toarray()[np.ix_(s.order, s.order)]
    gamma = n * np.finfo(float).eps / 2 / (1 - n * np.finfo(float).eps / 2)
    assert np.all(np.abs(K - (L * D) @ L.T) <= gamma * (np.abs(L) * np.abs(D)) @ np.abs(L).T)


def _column_factors(fac):
    """Dense L (unit lower) and D of a column-storage factorisation."""
    s = fac.structure
    L, D = np.eye(s.n), np.empty(s.n)
    for j in range(s.n):
        col = fac.factors[s.colptr[j]:s.colptr[j + 1]]
        D[j] = col[0]
        L[j + 1:s.last[j] + 1, j] = col[1:]
    return L, D


def _node_blocks(rng, sizes):
    """Random symmetric indefinite block-tridiagonal matrix of node blocks of ``sizes``: a
    node's rows coupled to the whole node before it (a beam's nodes), so every column of a
    node ends on the same row — the column kernel's paired update (panels of four within a
    node) — and panels across two nodes take its general one."""
    ends = np.cumsum(sizes)
    starts = ends - sizes
    rows, cols = [], []
    for b, (s0, s1) in enumerate(zip(starts, ends, strict=True)):
        lo = starts[b - 1] if b else s0
        for i in range(s0, s1):
            rows += [i] * (i - lo)
            cols += list(range(lo, i))
    n = int(ends[-1])
    L = sp.csr_matrix((rng.normal(size=len(rows)), (rows, cols)), shape=(n, n))
    return (L + L.T + sp.diags(rng.normal(scale=3.0, size=n))).tocsr()


@pytest.mark.parametrize("seed", range(6))
def test_column_kernel_on_node_blocks_gives_the_inertia_and_small_backward_error(
        seed, monkeypatch):
    """The column kernel (narrow columns) where panels of four end on one row, so trailing
    columns are updated in pairs (`_paired_update`, an odd one alone at the end), mixed with
    panels that do not: negative pivots against eigvalsh, solves against the dense matrix, and
    the factors' backward error within Higham's bound."""
    monkeypatch.setattr(envelope_structure, "COLUMN_ADVANTAGE", 1e9)  # columns, natural order
    rng = np.random.default_rng(200 + seed)
    sizes = rng.choice([4, 8] if seed < 3 else [3, 4, 5, 7], size=int(rng.integers(8, 30)))
    A = _node_blocks(rng, sizes)
    A.sort_indices()
    s = EnvelopeStructure.of(A, ordering="natural")
    assert s.storage == "columns" and not s.panels
    equal = [j for j in range(0, s.n - 3, 4) if s.last[j] == s.last[j + 3]]
    assert equal  # the paired update runs
    _check_column_factorisation(A, s, rng)


@pytest.mark.parametrize("seed", range(4))
def test_panels_on_narrow_bands_too(seed, monkeypatch):
    """Forced onto the small random envelopes (every width, panels wider than the band)."""
    monkeypatch.setattr(envelope_structure, "COLUMN_ADVANTAGE", 1e9)
    monkeypatch.setattr(envelope_structure, "PANEL_MIN_WIDTH", -1)
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 40))
    A = _variable_band(rng, n, rng.integers(0, 12, size=n))
    A.sort_indices()
    fac = factorize_envelope(A)
    assert fac.structure.panels
    eig = np.linalg.eigvalsh(A.toarray())
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = rng.normal(size=n)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ fac.solve(b) - b) <= 1e-12 * cond * np.linalg.norm(b)


def test_explicit_zeros_in_wide_rows_are_skipped_with_the_same_answer(monkeypatch):
    """A pattern wider than its values (a contact pair's unchosen segments): same inertia and
    solution as the dense matrix, at the numerical envelope's operation count."""
    monkeypatch.setattr(envelope_structure, "COLUMN_ADVANTAGE", 0.0)  # the row envelope
    rng = np.random.default_rng(7)
    n = 60
    A = _variable_band(rng, n, np.full(n, 3))
    wide = [20, 21, 40, 41]  # rows that couple 15 columns back in the pattern only
    rows = [i for i in wide for _ in range(12)]
    cols = [j for i in wide for j in range(i - 15, i - 3)]
    Z = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    B = (A + Z + Z.T).tocsr()
    B.sort_indices()
    r = np.repeat(np.arange(n), np.diff(B.indptr))
    B.data[:] = A.toarray()[r, B.indices]  # the pattern of B, the values of A
    assert B.nnz > A.nnz and abs(B - A).max() == 0.0
    s = EnvelopeStructure.of(B)
    fac = factorize_envelope(B, s)
    eig = np.linalg.eigvalsh(A.toarray())
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    assert fac.flops < 0.7 * s.flops  # the explicit zeros are not worked on
    b = rng.normal(size=n)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ fac.solve(b) - b) <= 1e-12 * cond * np.linalg.norm(b)
    # the same structure with the wide couplings non-zero: all of it is worked on again
    C = B.copy()
    C.data = C.data + 0.1 * (Z + Z.T).toarray()[r, C.indices]
    assert s.matches(C)
    full = factorize_envelope(C, s)
    assert full.flops > fac.flops
    eig_c = np.linalg.eigvalsh(C.toarray())
    assert full.negative_pivots == int(np.count_nonzero(eig_c < 0))
    assert np.linalg.norm(C @ full.solve(b) - b) <= 1e-12 * np.abs(eig_c).max() / np.abs(
        eig_c).min() * np.linalg.norm(b)


def test_numeric_structure_widens_when_a_coupling_appears():
    """A structure of the values (explicit zeros left out) is narrower than the pattern's; a
    later matrix of the same pattern with those couplings non-zero is refused by it and
    factorised on a widened structure (same ordering), with the dense answer both times."""
    rng = np.random.default_rng(8)
    n = 70
    A = _variable_band(rng, n, np.full(n, 4))
    wide = [30, 31, 50]
    rows = [i for i in wide for _ in range(10)]
    cols = [j for i in wide for j in range(i - 20, i - 10)]
    Z = (sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)))
    Z = (Z + Z.T).tocsr()
    pattern = (abs(A) + Z).tocsr()
    pattern.sort_indices()
    r = np.repeat(np.arange(n), np.diff(pattern.indptr))

    def on_pattern(M):
        out = pattern.copy()
        out.data = M.toarray()[r, out.indices]
        return out

    B = on_pattern(A)  # the wide couplings stored as explicit zeros
    s = EnvelopeStructure.of(B, numeric=True)
    full = EnvelopeStructure.of(B)
    assert s.matches(B) and s.ordering == full.ordering == "natural"
    assert np.all(s.first >= full.first) and np.all(s.first[wide] > full.first[wide])
    for M, widens in ((B, False), (on_pattern(A + 0.1 * Z), True)):
        fac = factorize_envelope(M, s)
        assert isinstance(fac, EnvelopeFactorization)
        assert (fac.structure is not s) == widens
        if widens:
            assert fac.structure.matches(M) and np.array_equal(fac.structure.order, s.order)
            assert np.all(fac.structure.first[wide] < s.first[wide])
            again = factorize_envelope(M, fac.structure)
            assert again.structure is fac.structure  # no second widening
        eig = np.linalg.eigvalsh(M.toarray())
        assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
        b = rng.normal(size=n)
        cond = np.abs(eig).max() / np.abs(eig).min()
        assert np.linalg.norm(M @ fac.solve(b) - b) <= 1e-12 * cond * np.linalg.norm(b)


def test_a_widening_reorders_where_the_first_matrix_left_dofs_uncoupled():
    """The first matrix of a debond (open contact pairs) couples some DOFs to nothing: RCM
    orders them at one end, so once the pairs close the union in that order spans the whole
    matrix (c3 at core level 3: half-band 9991 of 10116, 1358 Mflop per factorisation). The
    widened structure takes a fresh order of the union when it is clearly narrower — same
    inertia and solution as the dense matrix — and is kept for the next matrices."""
    rng = np.random.default_rng(11)
    n = 90
    lone = np.arange(2, n, 6)  # every 6th DOF: its couplings are zero in the first matrix
    chain = np.setdiff1d(np.arange(n), lone)
    rows, cols = [], []
    for a, i in enumerate(chain):  # a band of half-width 3 along the chain
        for j in chain[max(0, a - 3):a]:
            rows.append(i)
            cols.append(j)
    for i in lone:  # and each lone DOF to its natural neighbours
        for j in (i - 1, i - 2):
            rows.append(i)
            cols.append(j)
    L = sp.csr_matrix((rng.normal(size=len(rows)), (rows, cols)), shape=(n, n))
    full = (L + L.T + sp.diags(rng.normal(scale=3.0, size=n))).tocsr()
    full.sort_indices()
    r = np.repeat(np.arange(n), np.diff(full.indptr))
    off = np.isin(r, lone) | np.isin(full.indices, lone)
    first = full.copy()
    first.data[off & (r != full.indices)] = 0.0  # the pattern kept, the lone couplings zero
    s = EnvelopeStructure.of(first, numeric=True)
    assert s.ordering == "rcm"
    same_order = EnvelopeStructure.of(full, numeric=True,
                                      widen=dataclasses.replace(s, fixed_order=True))
    assert np.array_equal(same_order.order, s.order)  # what the widening did before
    fac = factorize_envelope(full, s)
    assert isinstance(fac, EnvelopeFactorization) and fac.structure is not s
    assert fac.structure.flops < 0.5 * same_order.flops, (fac.structure.flops,
                                                           same_order.flops)
    assert fac.structure.matches(full)
    assert factorize_envelope(full, fac.structure).structure is fac.structure  # kept
    eig = np.linalg.eigvalsh(full.toarray())
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = rng.normal(size=n)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(full @ fac.solve(b) - b) <= 1e-12 * cond * np.linalg.norm(b)


def test_rcm_ordering_recovers_a_scrambled_band():
    rng = np.random.default_rng(1)
    n = 200
    A = _variable_band(rng, n, np.full(n, 3))
    p = rng.permutation(n)
    B = A[p][:, p].tocsr()
    B.sort_indices()
    s = EnvelopeStructure.of(B)
    assert s.ordering == "rcm" and s.half_bandwidth <= 12
    eig = np.linalg.eigvalsh(B.toarray())
    assert factorize_envelope(B, s).negative_pivots == int(np.count_nonzero(eig < 0))


def test_structure_is_reused_only_for_its_pattern():
    rng = np.random.default_rng(2)
    A = _variable_band(rng, 30, np.full(30, 2))
    A.sort_indices()
    s = EnvelopeStructure.of(A)
    B = A.copy()
    B.data = rng.normal(size=B.nnz)
    B = (B + B.T).tocsr()
    B.sort_indices()
    assert s.matches(A)
    assert s.matches(B) == (B.nnz == A.nnz and np.array_equal(B.indices, A.indices))
    C = (A + sp.eye(30, k=7) + sp.eye(30, k=-7)).tocsr()
    assert not s.matches(C)
    eig = np.linalg.eigvalsh(C.toarray())
    assert factorize_envelope(C, s).negative_pivots == int(np.count_nonzero(eig < 0))


def test_zero_pivot_falls_back_to_superlu():
    A = sp.csr_matrix(np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0]]))
    fac = factorize_envelope(A)
    assert isinstance(fac, SparseFactorization)  # the stated fallback
    assert np.allclose(A @ fac.solve(np.array([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0])


def _chain_with_zero_ends(rng, n):
    """A scrambled path graph whose two end rows have a zero diagonal, each end numbered after
    its neighbour: reverse Cuthill-McKee starts at an end (a zero first pivot), the natural
    order eliminates the neighbour first (the end's pivot is then −a²/d ≠ 0)."""
    path = rng.permutation(n)
    for a, b in ((0, 1), (-1, -2)):
        if path[a] < path[b]:
            path[[a, b]] = path[[b, a]]
    off = sp.csr_matrix((rng.uniform(1, 2, n - 1), (path[:-1], path[1:])), shape=(n, n))
    d = rng.choice([-1.0, 1.0], n) * rng.uniform(3, 4, n)
    d[path[[0, -1]]] = 0.0
    A = (off + off.T + sp.diags(d)).tocsr()
    A.sort_indices()
    return A


@pytest.mark.parametrize("seed", range(3))
def test_refused_in_rcm_order_is_factorised_in_the_natural_order(seed, monkeypatch):
    """No SuperLU: the natural-order envelope LDLᵀ, with the inertia of the dense eigenvalues
    and solves to round-off; its structure is built once."""
    A = _chain_with_zero_ends(np.random.default_rng(seed), 40)
    s = EnvelopeStructure.of(A)
    assert s.ordering == "rcm" and A[s.order[0], s.order[0]] == 0.0

    def no_superlu(*args, **kwargs):
        raise AssertionError("SuperLU called")

    monkeypatch.setattr(SparseFactorization, "__init__", no_superlu)
    fac = factorize_envelope(A, s)
    assert isinstance(fac, EnvelopeFactorization) and fac.structure.ordering == "natural"
    eig = np.linalg.eigvalsh(A.toarray())
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))
    b = np.random.default_rng(seed).normal(size=40)
    cond = np.abs(eig).max() / np.abs(eig).min()
    assert np.linalg.norm(A @ fac.solve(b) - b) <= 1e-13 * cond * np.linalg.norm(b)
    assert factorize_envelope(A, s).structure is fac.structure


def _orders_tried(monkeypatch):
    """The orderings :func:`factorize_envelope` tries its LDLᵀ in, recorded as it goes."""
    tried = []
    trusted = envelope_factorization.trusted_ldlt

    def record(A, structure, rtol):
        tried.append(structure.ordering)
        return trusted(A, structure, rtol)

    monkeypatch.setattr(envelope_factorization, "trusted_ldlt", record)
    return tried


def test_the_order_trusted_after_a_refusal_is_tried_first(monkeypatch):
    """After RCM's refusal and the natural order's success, the next tangent of the pattern
    goes to the natural order first (not refused again in RCM), with the same inertia."""
    A = _chain_with_zero_ends(np.random.default_rng(1), 40)
    s = EnvelopeStructure.of(A)
    tried = _orders_tried(monkeypatch)
    first = factorize_envelope(A, s)
    assert tried == ["rcm", "natural"] and s.natural_first
    tried.clear()
    again = factorize_envelope(A * 2.0, s)
    assert tried == ["natural"] and again.structure is first.structure
    assert again.negative_pivots == first.negative_pivots


def test_a_refusal_in_the_preferred_natural_order_hands_the_first_try_back(monkeypatch):
    """A zero first pivot in the natural order (row 0 mid-chain, RCM starts at an end): with
    the natural order preferred, it is tried, refused, and RCM's LDLᵀ is taken and kept first."""
    rng = np.random.default_rng(2)
    n = 30
    path = rng.permutation(n)
    while path[0] == 0 or path[-1] == 0:
        path = rng.permutation(n)
    off = sp.csr_matrix((rng.uniform(1, 2, n - 1), (path[:-1], path[1:])), shape=(n, n))
    d = rng.uniform(5, 6, n)
    A = (off + off.T + sp.diags(d)).tocsr()
    A.sort_indices()
    A.data[A.indptr[0] + np.flatnonzero(A.indices[A.indptr[0]:A.indptr[1]] == 0)] = 0.0
    s = EnvelopeStructure.of(A)
    assert s.ordering == "rcm" and s.order[0] != 0
    s.keep_natural(s.natural_variant(A), preferred=True)
    tried = _orders_tried(monkeypatch)
    fac = factorize_envelope(A, s)
    assert tried == ["natural", "rcm"]
    assert isinstance(fac, EnvelopeFactorization) and fac.structure.ordering == "rcm"
    assert not s.natural_first
    eig = np.linalg.eigvalsh(A.toarray())
    assert fac.negative_pivots == int(np.count_nonzero(eig < 0))


def test_refused_in_the_natural_order_goes_straight_to_the_pivoting_lu(monkeypatch):
    """SuperLU's pivot-free LDLᵀ is the natural order's, under the same tests: not tried again."""

    def no_pivot_free(*args, **kwargs):
        raise AssertionError("the pivot-free LDLᵀ was retried")

    monkeypatch.setattr(SparseFactorization, "_ldlt", staticmethod(no_pivot_free))
    A = sp.csr_matrix(np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0]]))
    fac = factorize_envelope(A)
    assert isinstance(fac, SparseFactorization) and fac.pivoted
    assert fac.negative_pivots is None
    assert np.allclose(A @ fac.solve(np.array([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0])


def test_bad_matrices_are_refused():
    with pytest.raises(SingularTangentError):
        factorize_envelope(sp.csr_matrix(np.array([[1.0, np.nan], [np.nan, 1.0]])))
    for bad in (np.inf, -np.inf, np.nan):  # one value, in a run of the storage
        A = np.diag(np.arange(1.0, 7.0)) + 0.1 * np.eye(6, k=1) + 0.1 * np.eye(6, k=-1)
        A[3, 4] = A[4, 3] = bad
        with pytest.raises(SingularTangentError, match="non-finite"):
            factorize_envelope(sp.csr_matrix(A))
    with pytest.raises(SingularTangentError):
        factorize_envelope(sp.csr_matrix((3, 3)))
    with pytest.raises(SingularTangentError):  # singular: the fallback decides
        factorize_envelope(sp.csr_matrix(np.ones((3, 3))))


def test_cache_directory_rules(tmp_path, monkeypatch):
    """Read-only install: numba's in-tree cache, else the user cache, else a temporary dir."""
    read_only = {tmp_path / "ro", tmp_path / "home"}
    real = jit.writable

    def writable(path):
        return not any(p == path or p in path.parents for p in read_only) and real(path)

    monkeypatch.setattr(jit, "writable", writable)
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert jit.cache_directory((tmp_path / "src",)) == ("in-tree", None)
    assert jit.cache_directory((tmp_path / "ro",)) == ("user", tmp_path / "cache" / "numba")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home" / ".cache"))
    rule, where = jit.cache_directory((tmp_path / "ro",))
    assert rule == "temporary" and real(where)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert jit.cache_directory((tmp_path / "ro",)) == ("NUMBA_CACHE_DIR", tmp_path / "mine")


def test_kernels_run_from_a_read_only_install(tmp_path):
    """A copy of the package in a read-only location, with a read-only home, still runs."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    site = tmp_path / "site"
    for pkg in ("sandwich",):
        shutil.copytree(root / pkg, site / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    code = ("import os, numpy as np, scipy.sparse as sp\n"
            "from sandwich.solver import jit\n"
            "print(jit.cache_directory()[0])\n"
            "from sandwich.solver import envelope\n"
            "f = envelope.factorize_envelope(sp.csr_matrix(np.diag([1.0, -2.0, 3.0])))\n"
            "print(f.negative_pivots, bool(os.listdir(os.environ['NUMBA_CACHE_DIR'])))\n")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=str(site), HOME=str(tmp_path / "nohome"), SANDWICH_KERNELS="jit",
               XDG_CACHE_HOME=str(tmp_path / "nohome" / ".cache"), PYTHONDONTWRITEBYTECODE="1")
    # read-only: without root, chmod; with root (mode bits ignored), a file where the cache dirs
    # would go blocks them just as well
    for d in (site / "sandwich" / "solver", site / "sandwich" / "solver" / "envelope",
              site / "sandwich" / "beam"):
        (d / "__pycache__").write_text("not a directory")
    (tmp_path / "nohome").write_text("not a directory")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["temporary", "1", "True"]


@pytest.mark.parametrize("numeric", [False, True])
def test_structure_of_an_unsymmetric_pattern_is_its_symmetric_closure(numeric):
    """first[i] against a dense brute force: the smallest column coupled to row i in K or Kᵀ
    (non-zero values only when ``numeric``), on a pattern with explicit zeros and rows without
    a diagonal slot; every stored CSR entry maps into the storage or (numeric) is zero."""
    rng = np.random.default_rng(5)
    n = 60
    A = sp.random(n, n, density=0.06, random_state=rng, format="csr")
    A.data[rng.random(A.nnz) < 0.3] = 0.0  # explicit zeros
    A = A.tolil()
    A.setdiag(0.0)
    A = A.tocsr()  # no diagonal slots at all
    A.sort_indices()
    dense = A.toarray()
    coupled = (dense != 0.0) if numeric else (
        sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape).toarray() != 0)
    coupled = coupled | coupled.T | np.eye(n, dtype=bool)
    s = EnvelopeStructure.of(A, numeric=numeric)
    inv = np.empty(n, dtype=int)
    inv[s.order] = np.arange(n)
    P = coupled[np.ix_(s.order, s.order)]  # new numbering
    expected = np.array([np.flatnonzero(P[i, : i + 1])[0] for i in range(n)])
    np.testing.assert_array_equal(s.first, expected)
    rows = np.repeat(np.arange(n), np.diff(A.indptr))
    i, j = inv[rows[s.slots]], inv[A.indices[s.slots]]
    upper = s.storage == "columns"
    assert np.all(j >= i) if upper else np.all(j <= i)
    outside = s.positions < 0
    assert not numeric or np.all(A.data[s.slots[outside]] == 0.0)
    assert numeric or not np.any(outside)


def test_storage_arrays_are_reused_only_when_no_factorisation_holds_them():
    """Factorisations of one structure share its spare storage arrays
    (EnvelopeStructure.storage_array): a live one keeps solving its own matrix; a released
    array is reused, from zero (the fill-in the last factors left where the next matrix has
    no entry would corrupt it)."""
    rng = np.random.default_rng(7)
    n = 120
    A1 = _variable_band(rng, n, rng.integers(0, 30, size=n))
    A1.sort_indices()
    s = EnvelopeStructure.of(A1)

    def on_the_pattern():  # new values, A1's (symmetric) pattern, a dominant diagonal
        A = A1.copy()
        A.data = rng.normal(size=A.data.size)
        A = (A + A.T + sp.diags(np.full(n, 40.0))).tocsr()
        A.sort_indices()
        assert s.matches(A)
        return A

    b = rng.normal(size=n)
    fac1 = factorize_envelope(A1, s)
    x1 = fac1.solve(b)
    for _ in range(4):
        A = on_the_pattern()
        fac = factorize_envelope(A, s)
        assert isinstance(fac, EnvelopeFactorization)
        assert np.allclose(A @ fac.solve(b), b, rtol=0, atol=1e-10 * np.linalg.norm(b))
    assert np.array_equal(fac1.solve(b), x1)  # held all along: never overwritten
    before = set(s.spare_addresses)  # addresses: no extra reference
    del fac  # its array comes free
    A = on_the_pattern()
    fac = factorize_envelope(A, s)
    assert fac.factors.ctypes.data in before  # reused, not new
    assert np.allclose(A @ fac.solve(b), b, rtol=0, atol=1e-10 * np.linalg.norm(b))


def test_panel_flop_count_against_a_panel_by_panel_count():
    """``panel_flops`` (vectorised) against a count written panel by panel from the kernel's
    loops: per column 1 reciprocal + m products + 2 per earlier panel column and row; per
    trailing column of a panel reaching R, a rank-8 update of R − k + 1 rows (16 flops each,
    the padding's zero terms included)."""
    rng = np.random.default_rng(3)
    for n in (1, 7, 8, 9, 100, 203):
        last = column_last(np.maximum(np.arange(n) - rng.integers(0, 30, n), 0))
        count = 0
        for j in range(0, n, envelope.PANEL):
            w = min(envelope.PANEL, n - j)
            for p in range(w):
                m = int(last[j + p]) - (j + p)
                count += 1 + m + 2 * p * (m + 1)
            R = int(last[j + w - 1])
            count += sum(16 * (R - k + 1) for k in range(j + w, R + 1))
        assert panel_flops(last) == count


@pytest.mark.parametrize("seed", range(6))
def test_pattern_union_is_the_rows_set_union(seed):
    # reference: the per-row set union of two random sorted CSR patterns (empty rows, full rows,
    # shared entries; int32 and int64 index arrays as scipy and values_pattern give them)
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 40))

    def pattern(dtype):
        rows = [np.sort(rng.choice(n, size=int(rng.integers(0, n + 1)), replace=False))
                for _ in range(n)]
        ptr = np.concatenate([[0], np.cumsum([r.size for r in rows])]).astype(dtype)
        ind = (np.concatenate(rows) if rows else np.empty(0)).astype(dtype)
        return ptr, ind, rows

    *a, ra = pattern(np.int32)
    *b, rb = pattern(np.int64)
    ptr, ind = pattern_union(n, tuple(a), tuple(b))
    assert ptr.dtype == ind.dtype == np.int64 and ptr[0] == 0 and ptr[-1] == ind.size
    for r in range(n):
        assert ind[ptr[r]:ptr[r + 1]].tolist() == sorted(set(ra[r]) | set(rb[r]))


def test_a_structure_matches_its_pattern_through_new_views_and_copies_only():
    """``EnvelopeStructure.matches``: a CSR matrix built on the structure's index arrays (scipy
    hands it new views of them) matches without a comparison; an equal copy matches by
    comparison; another pattern of the same size, or a view of the same memory with another
    shape, does not."""
    rng = np.random.default_rng(7)
    K = _variable_band(rng, 40, rng.integers(1, 5, size=40))
    s = EnvelopeStructure.of(K)
    on_it = sp.csr_matrix((rng.normal(size=s.indices.size), s.indices, s.indptr), shape=K.shape)
    assert on_it.indices is not s.indices  # the case the memory test is for
    assert same_memory(on_it.indices, s.indices)
    assert s.matches(on_it)
    copied = sp.csr_matrix((on_it.data, s.indices.copy(), s.indptr.copy()), shape=K.shape)
    assert not same_memory(copied.indices, s.indices)
    assert s.matches(copied)
    other = copied.copy()  # the same sizes, one column moved: row 0's last entry one further
    row0 = other.indices[other.indptr[0]:other.indptr[1]]
    assert row0[-1] + 1 < K.shape[0] and row0[-1] + 1 not in row0
    row0[-1] += 1
    assert not np.array_equal(other.indices, s.indices)
    assert not s.matches(other)
    assert not same_memory(s.indices[:-1], s.indices)
    assert not same_memory(s.indices[::2], s.indices[:s.indices.size // 2 + 1])


def test_a_retired_structure_keeps_what_its_factorisations_solve_with_only():
    """``EnvelopeStructure.retire``: a factorisation made on the structure solves as before
    (bit for bit); the pattern-sized maps, the pattern, its spares and its natural-order
    variant are gone; the structure matches nothing, so a matrix of its pattern gets a new
    one, with the same answer."""
    rng = np.random.default_rng(5)
    n = 80
    A = _variable_band(rng, n, rng.integers(0, 12, size=n))
    A.sort_indices()
    s = EnvelopeStructure.of(A, numeric=True)
    natural = s.natural_variant(A)
    fac = factorize_envelope(A, s)
    b = rng.normal(size=n)
    x = fac.solve(b)
    assert s.matches(A) and s.spare_addresses
    s.retire()
    assert np.array_equal(fac.solve(b), x)
    assert all(getattr(s, name) is None for name in (
        "slots", "positions", "indptr", "indices", "values_indptr", "values_indices"))
    assert not s.spare_addresses and s.kept_natural is None and natural.indices is None
    assert not s.matches(A) and s.size == fac.factors.size and s.flops > 0
    again = factorize_envelope(A, s)
    assert again.structure is not s and again.structure.matches(A)
    assert np.array_equal(again.solve(b), x)
