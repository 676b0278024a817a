"""Compiled layer kernels (sandwich.beam.kernels) against the NumPy reference (beam.element).

References: the NumPy path of sandwich.beam.element (force of eq. 19, tangent of eqs. 24-25), kept
as the reference implementation, to round-off; central finite differences of the kernel's own
force for its tangent; and the model's NumPy path (use_kernels = False) for the assembled force
and reduced tangent, with debonds, contact and core levels > 1. Genericity in the layer's DOF
count n and point count G: a synthetic layer with extra DOFs and a non-tensor rule. The averaged
face membrane (sandwich.beam.averaged_kernel) against the same NumPy path, with and without the
face stretch DOF, with the faces' diagonal C and a full symmetric C, and its assembled model
tangent against central finite differences of the model's force.
"""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from beam_scenes import KEVLAR, ROHACELL, Debond, sandwich_scene  # noqa: I001

from sandwich.beam import build_model, element, kernels
from sandwich.beam.constitutive import core_stiffness, face_stiffness
from sandwich.beam.factorisation import embed_in_pattern
from sandwich.beam.layer_operators import build_face_operators, build_layer_operators
from sandwich.beam.quadrature import EXACT_ORDER
from sandwich.solver.envelope import EnvelopeFactorization
from sandwich.solver.sparse import SparseFactorization

LAYERS = [("top", 0.5, face_stiffness(KEVLAR)), ("core", 25.0, core_stiffness(ROHACELL)),
          ("bottom", 0.5, face_stiffness(KEVLAR))]


def _rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


def _assert_kernel_matches_numpy(op, u, lengths):
    """Kernel force and tangent = NumPy path's to 1e-13; tangent symmetric; force-only call the
    same force. Returns the NumPy tangent."""
    f_ref, K_ref = element.layer_response(op, u, lengths, 60.0)
    f, K = kernels.layer_response(op, u, lengths, 60.0)
    assert _rel(f, f_ref) < 1e-13
    assert _rel(K, K_ref) < 1e-13
    assert np.array_equal(K, K.transpose(0, 2, 1))  # symmetric by construction
    f_only, none = kernels.layer_response(op, u, lengths, 60.0, tangent=False)
    assert none is None and np.array_equal(f_only, f)
    return K_ref


@pytest.mark.parametrize("name,h,C", LAYERS)
@pytest.mark.parametrize("gauss", ["exact", (3, 2), (9, 8)])
def test_kernel_matches_numpy_reference(name, h, C, gauss):
    rng = np.random.default_rng(11)
    op = build_layer_operators(name, h, 0.0, C, gauss=EXACT_ORDER[name] if gauss == "exact"
                               else gauss)
    E = 300  # more than one kernel block (CHUNK = 128), last one partial
    u = rng.normal(size=(E, 40)) * 0.5
    lengths = rng.uniform(1.0, 9.0, size=E)
    _assert_kernel_matches_numpy(op, u, lengths)


def _full_symmetric_stiffness(rng):
    """A positive-definite C with every coupling (C_xz, C_xγ, C_zγ) non-zero (MPa)."""
    A = rng.normal(size=(3, 3))
    return 100.0 * (A @ A.T) + 50.0 * np.eye(3)


@pytest.mark.parametrize("name", ["top", "bottom"])
@pytest.mark.parametrize("stretch", [False, True])
@pytest.mark.parametrize("coupled", [False, True])
def test_averaged_membrane_kernel_matches_numpy_reference(name, stretch, coupled):
    rng = np.random.default_rng(17)
    C = face_stiffness(KEVLAR).copy()
    if stretch:  # the stretch faces' σ_z = E ε_z (build_model)
        C[1, 1] = C[0, 0]
    if coupled:  # not a face law: exercises the C_xz, C_xγ terms of the B̄_x update
        C = _full_symmetric_stiffness(rng)
    op = build_face_operators(name, 0.5, 0.0, C, gauss=EXACT_ORDER[name],
                              membrane_average=True, stretch=stretch)
    assert op.membrane_average and kernels.supports(op)
    E = 300  # more than one kernel block (CHUNK = 128), last one partial
    u = rng.normal(size=(E, 42)) * 0.5
    lengths = rng.uniform(1.0, 9.0, size=E)
    K_ref = _assert_kernel_matches_numpy(op, u, lengths)
    # the averaging changes the answer (the test would not see a kernel ignoring it)
    plain = replace(op, membrane_average=False)
    assert _rel(kernels.layer_response(plain, u, lengths, 60.0)[1], K_ref) > 1e-3


def test_averaged_membrane_kernel_on_a_core_rule():
    """A 7×7 rule and the core's coupled C (C_xz ≠ 0) through the same kernel."""
    rng = np.random.default_rng(23)
    op = build_layer_operators("core", 25.0, 0.0, core_stiffness(ROHACELL),
                               gauss=EXACT_ORDER["core"], membrane_average=True)
    u = rng.normal(size=(40, 40)) * 0.5
    lengths = rng.uniform(1.0, 9.0, size=40)
    f_ref, K_ref = element.layer_response(op, u, lengths, 60.0)
    f, K = kernels.layer_response(op, u, lengths, 60.0)
    assert _rel(f, f_ref) < 1e-13
    assert _rel(K, K_ref) < 1e-13


def test_averaged_membrane_falls_back_to_numpy_where_the_kernel_cannot():
    rng = np.random.default_rng(29)
    C = _full_symmetric_stiffness(rng)
    C[0, 2] += 1.0  # not symmetric: the rank-2 update of averaged_kernel does not hold
    op = build_layer_operators("top", 0.5, 0.0, C, gauss=EXACT_ORDER["top"],
                               membrane_average=True)
    assert not kernels.supports(op)
    with pytest.raises(ValueError, match="not evaluated by the kernels"):
        kernels.layer_response(op, np.zeros((2, 40)), np.ones(2), 60.0)


def _enlarged(op, rng, extra=7, points=61):
    """The layer with ``extra`` more DOFs (random polynomial-like rows) and a random rule.

    Stands for the core hierarchy's extended layers: more DOFs per element, composite rules.
    """
    G = points
    eta, xi = rng.uniform(-1, 1, size=G), rng.uniform(-1, 1, size=G)
    base = op.at(eta, xi)
    n0 = op.dofs.size
    is_u = rng.random(extra) < 0.5

    def cols(kind):
        new = rng.normal(size=(G, extra)) * (1 + eta[:, None] ** 2) * (1 - 0.3 * xi[:, None])
        mask = is_u if kind == "N" else ~is_u
        return new * mask[None, :]

    rows = {key: np.concatenate([getattr(base, key), cols(key[0])], axis=1)
            for key in ("N", "M", "N_eta", "N_xi", "M_eta", "M_xi")}
    big = replace(base, dofs=np.concatenate([op.dofs, 40 + np.arange(extra)]),
                  weight=rng.uniform(0.01, 0.1, size=G),
                  x_slope=np.concatenate([op.x_slope, rng.random(extra) < 0.5]),
                  u_mask=np.concatenate([op.u_columns, is_u]), **rows)
    assert big.dofs.size == n0 + extra
    return big


@pytest.mark.parametrize("name,h,C", LAYERS)
def test_kernel_is_generic_in_dof_and_point_count(name, h, C):
    rng = np.random.default_rng(5)
    op = _enlarged(build_layer_operators(name, h, 0.0, C, gauss=EXACT_ORDER[name]), rng)
    E = 20
    u = rng.normal(size=(E, 40 + 7)) * 0.3
    lengths = rng.uniform(1.0, 9.0, size=E)
    f_ref, K_ref = element.layer_response(op, u, lengths, 60.0)
    f, K = kernels.layer_response(op, u, lengths, 60.0)
    assert _rel(f, f_ref) < 1e-13
    assert _rel(K, K_ref) < 1e-13


@pytest.mark.parametrize("name,h,C", LAYERS)
def test_kernel_tangent_matches_finite_differences(name, h, C):
    rng = np.random.default_rng(2)
    op = build_layer_operators(name, h, 0.0, C, gauss=EXACT_ORDER[name])
    lengths = np.array([4.0, 9.0, 2.5])
    u = rng.normal(size=(3, 40)) * 0.5  # gradients of order 0.1 - 0.3
    _, K = kernels.layer_response(op, u, lengths, 60.0)
    step = 1e-6
    for a, d in enumerate(op.dofs):
        du = np.zeros_like(u)
        du[:, d] = step
        fp = kernels.layer_response(op, u + du, lengths, 60.0, tangent=False)[0]
        fm = kernels.layer_response(op, u - du, lengths, 60.0, tangent=False)[0]
        fd = (fp - fm) / (2 * step)
        assert np.max(np.abs(K[:, :, a] - fd)) < 1e-6 * np.max(np.abs(K))


@pytest.mark.parametrize("stretch", [False, True])
def test_averaged_model_tangent_matches_finite_differences(stretch):
    """Assembled reduced tangent (kernels, averaged faces, contact active) vs central FD."""
    scene = sandwich_scene(length=60.0, elements=8, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene, face_membrane="averaged", face_stretch=stretch)
    assert all(kernels.supports(model.layers[n]) and model.layers[n].membrane_average
               for n in ("top", "bottom"))
    u = _contact_state(model, np.random.default_rng(31))
    K = model.tangent(u).toarray()
    step = 1e-6
    worst = 0.0
    for j in range(model.size):
        du = np.zeros(model.size)
        du[j] = step
        fd = (model.internal_force(u + du) - model.internal_force(u - du)) / (2 * step)
        worst = max(worst, np.max(np.abs(K[:, j] - fd)))
    assert worst < 1e-6 * np.max(np.abs(K))


def _contact_state(model, rng):
    """Random state with a bending wave and every contact pair penetrating (as in
    test_beam_tangent)."""
    u = rng.normal(size=model.size) * 0.02
    free = model.dof_map.free
    for pairs in model.pairs:
        sign = 1.0 if pairs.interface == "top" else -1.0
        w_face, w_core = free[pairs.dofs[:, 1]], free[pairs.dofs[:, 3]]
        u[w_face] = u[w_core] - sign * rng.uniform(0.02, 0.05, size=w_face.size)
    return u


@pytest.mark.parametrize("options", [
    {}, {"core_level": 3}, {"core_level": 2, "core_basis": "polynomial"},
    {"face_membrane": "averaged"}, {"contact_search": "closest-point"},
    # several candidate segments per pair, grouped by width: the compiled path assembles each
    # pair on its chosen segment only (contact.compact_response, kernels.scatter_compact)
    {"contact_search": "closest-point", "contact_reach": 9.0, "grading": "graded"},
])
def test_model_compiled_path_matches_numpy_path(options):
    scene = sandwich_scene(length=60.0, elements=16,
                           debonds=(Debond("top", 15.0, 45.0), Debond("bottom", 0.0, 20.0)))
    model = build_model(scene, **options)
    u = _contact_state(model, np.random.default_rng(3))
    assert model.contact_summary(u)["top"].active > 0
    model.use_kernels = False
    f0, K0 = model.internal_force(u), model.tangent(u)
    model.use_kernels = True
    model.forget_evaluations(contact_kinematics=False)
    f1, K1 = model.internal_force(u), model.tangent(u)
    assert np.linalg.norm(f1 - f0) <= 1e-13 * np.linalg.norm(f0)
    assert abs(K1 - K0).max() <= 1e-13 * abs(K0).max()
    # the compiled pattern holds the segments met, the NumPy one every searched segment
    assert K1.nnz <= K0.nnz
    assert K1.nnz == K0.nnz or options.get("contact_search") == "closest-point"
    u_full = model.expand(u)
    g1, b1 = model.full_response(u_full)
    model.use_kernels = False
    g0, b0 = model.full_response(u_full)
    assert np.linalg.norm(g1 - g0) <= 1e-13 * np.linalg.norm(g0)
    for x, y in zip(b1, b0, strict=True):
        assert np.max(np.abs(x - y)) <= 1e-13 * np.max(np.abs(y))


def test_compiled_pattern_grows_to_the_segments_projections_meet():
    """Faces slid by 2-3 segments along the core: their projections leave the segments next to
    their nodes (the compiled pattern's seed), the pattern grows, and force and tangent still
    equal the NumPy path's (every searched segment); at a second such state no new growth."""
    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene, contact_search="closest-point", contact_reach=9.0,
                        grading="graded")
    rng = np.random.default_rng(5)
    u = _contact_state(model, rng)
    free = model.dof_map.free
    pairs = model.pairs[0]
    x = model.mesh.x
    slide = 2.5 * np.diff(x).min() * np.ones(pairs.size)  # ≥ 2 segments for every pair
    u[free[pairs.dofs[:, 0]]] += slide
    before = model.pattern.indices.size
    model.forget_evaluations(contact_kinematics=False)
    f1, K1 = model.internal_force(u), model.tangent(u)
    assert model.pattern_growths >= 1 and model.pattern.indices.size > before
    k = model.contact_summary(u)["top"]
    assert k.active > 0
    model.use_kernels = False
    f0, K0 = model.internal_force(u), model.tangent(u)
    model.use_kernels = True
    assert np.linalg.norm(f1 - f0) <= 1e-13 * np.linalg.norm(f0)
    assert abs(K1 - K0).max() <= 1e-13 * abs(K0).max()
    grown = model.pattern_growths
    model.forget_evaluations(contact_kinematics=False)
    model.internal_force(u + 1e-9)  # the same segments: no growth
    assert model.pattern_growths == grown


def test_pattern_growth_takes_the_neighbouring_segments():
    """A projection that slides one segment on finds its couplings in place: the growth took
    the met segment's neighbours (mutation: growing by the met segments only grows again at
    the second slide), and force and tangent still equal the NumPy path's."""
    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene, contact_search="closest-point", contact_reach=9.0,
                        grading="graded")
    u = _contact_state(model, np.random.default_rng(5))
    pairs = model.pairs[0]
    face_u = model.dof_map.free[pairs.dofs[:, 0]]
    h = np.diff(model.mesh.x).min()
    for slide, growths in ((1.2 * h, 1), (2.2 * h, 1)):
        v = u.copy()
        v[face_u] += slide
        model.forget_evaluations(contact_kinematics=False)
        f1, K1 = model.internal_force(v), model.tangent(v)
        assert model.pattern_growths == growths
        assert model.contact_summary(v)["top"].active > 0
        model.use_kernels = False
        f0, K0 = model.internal_force(v), model.tangent(v)
        model.use_kernels = True
        assert np.linalg.norm(f1 - f0) <= 1e-13 * np.linalg.norm(f0)
        assert abs(K1 - K0).max() <= 1e-13 * abs(K0).max()


def test_compiled_force_carries_its_tangent():
    """One pass: the tangent at the last force's u is not evaluated again."""
    model = build_model(sandwich_scene(length=60.0, elements=8))
    u = np.random.default_rng(0).normal(size=model.size) * 1e-3
    model.internal_force(u)
    K = model.last_evaluation.tangent
    assert K is not None and model.tangent(u) is K
    assert model.residual_roundoff(u) > 0 and model.tangent(u) is K
    # ε ‖ |K| |u| ‖ as scipy forms it (the compiled row sums take the same order)
    assert model.residual_roundoff(u) == float(np.finfo(float).eps
                                               * np.linalg.norm(abs(K) @ np.abs(u)))


def test_contact_summary_reuses_the_evaluation_and_agrees():
    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene)
    u = _contact_state(model, np.random.default_rng(4))
    fresh = model.contact_summary(u)  # nothing evaluated yet at u
    model.internal_force(u)
    assert model.last_evaluation.assembled.contact  # kept by the evaluation
    assert model.contact_summary(u) == fresh
    assert fresh["top"].active > 0


def test_beam_tangent_inertia_matches_superlu_along_a_shift():
    """On a beam tangent with a bifurcation-like shift, both backends count the same."""
    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene)
    K = model.tangent(np.zeros(model.size))
    d = K.diagonal()
    negative = []
    for shift in (0.0, 1e-3, 3e-3):
        A = (K - shift * sp.diags(d)).tocsr()
        A.sort_indices()
        env = model.factorize(A)
        ref = SparseFactorization(A)
        assert isinstance(env, EnvelopeFactorization)
        assert env.negative_pivots == ref.negative_pivots
        negative.append(env.negative_pivots)
        b = np.arange(model.size, dtype=float)
        assert np.allclose(env.solve(b), ref.solve(b), rtol=1e-8, atol=1e-10 * np.abs(
            ref.solve(b)).max())
    assert negative[0] == 0 and negative[-1] > 0


def test_beam_path_imports_no_2d_or_plotting_stack():
    """Solving a beam scene loads neither dolfinx, gmsh, pyvista nor matplotlib.

    Nor scipy.optimize: its import alone is ≈ 50 ms of fig. 5's 0.5-s process (measured with
    ``python -X importtime``; the located extrema's root is found by bisection instead).
    """
    import subprocess
    import sys

    code = ("import sys\n"
            "from beam_scenes import sandwich_scene\n"
            "from sandwich.beam import build_model\n"
            "from sandwich.solver import solve_equilibrium\n"
            "m = build_model(sandwich_scene(length=60.0, elements=8))\n"
            "r = solve_equilibrium(m, 1.0)\n"
            "assert r.converged, r.reason\n"
            "print(sorted(k for k in ('dolfinx', 'gmsh', 'pyvista', 'matplotlib', 'petsc4py',"
            " 'scipy.optimize')"
            " if k in sys.modules))\n")
    here = Path(__file__).resolve().parent
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, cwd=here)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_a_matrix_inside_the_model_pattern_reuses_its_factorisation_structure():
    model = build_model(sandwich_scene(length=60.0, elements=8,
                                       debonds=(Debond("top", 15.0, 45.0),)))
    K = model.tangent(np.zeros(model.size))
    model.factorize(K)
    sub = sp.csr_matrix(K.toarray() * (np.random.default_rng(0).random(K.shape) < 0.5))
    sub = sub + sub.T + sp.diags(K.diagonal())  # symmetric, fewer non-zeros than K
    on = embed_in_pattern(sub.tocsr(), model.pattern)
    assert on is not None and on.nnz == K.nnz
    assert np.array_equal(on.toarray(), sub.toarray())
    fac = model.factorize(sub.tocsr())
    assert len(model.factorisations.structures) == 1  # no new symbolic factorisation
    b = np.ones(model.size)
    assert np.allclose(sub @ fac.solve(b), b, rtol=0, atol=1e-8 * np.abs(b).max())
    outside = sp.csr_matrix(K + sp.eye(model.size, k=model.size - 1) + sp.eye(model.size,
                                                                              k=1 - model.size))
    assert embed_in_pattern(outside.tocsr(), model.pattern) is None


@pytest.mark.parametrize("options", [{}, {"core_level": 2}, {"contact_search": "closest-point"}])
def test_reduced_pattern_is_the_same_with_and_without_the_compiled_builder(options):
    """The compiled pattern builder against the sort of every local entry's key (np.unique),
    and both against the scipy COO → CSR pattern of Tᵀ K T's entries."""
    from sandwich.beam import assembly

    scene = sandwich_scene(length=60.0, elements=12,
                           debonds=(Debond("top", 15.0, 45.0), Debond("bottom", 0.0, 20.0)))
    model = build_model(scene, **options)
    fast = assembly.reduced_pattern(model.block_dofs, model.dof_map)
    slow = assembly.reduced_pattern(model.block_dofs, model.dof_map, compiled=False)  # np.unique
    for key in ("slot", "keep", "weight", "indices", "indptr"):
        a, b = getattr(fast, key), getattr(slow, key)
        assert a.dtype == b.dtype and np.array_equal(a, b), key
    for (sa, wa), (sb, wb) in zip(fast.family_slots, slow.family_slots, strict=True):
        assert sa.dtype == np.int32 and wa.dtype == np.int8
        assert np.array_equal(sa, sb) and np.array_equal(wa, wb)
    rows = np.concatenate([np.repeat(d, d.shape[1], axis=1).reshape(-1)
                           for d in model.block_dofs])
    cols = np.concatenate([np.tile(d, (1, d.shape[1])).reshape(-1) for d in model.block_dofs])
    r, c = model.dof_map.free[rows], model.dof_map.free[cols]
    ok = (r >= 0) & (c >= 0)
    P = sp.csr_matrix((np.ones(ok.sum()), (r[ok], c[ok])), shape=(fast.n, fast.n))
    P.sum_duplicates()
    assert np.array_equal(P.indptr, fast.indptr) and np.array_equal(P.indices, fast.indices)
    # every kept entry's slot holds its (row, column)
    slot_row = np.repeat(np.arange(fast.n), np.diff(fast.indptr))
    assert np.array_equal(slot_row[fast.slot], r[ok]) and np.array_equal(
        fast.indices[fast.slot], c[ok])


def test_remembered_compact_slots_add_the_same_sums_as_the_search():
    """kernels.scatter_compact_known against kernels.scatter_compact (the binary search in each
    row, which it replaces for blocks whose DOFs are unchanged): the same values bit for bit
    and the same misses, over calls where some blocks keep their DOFs, some move to other
    DOFs, some have eliminated DOFs (−1) and some hit entries outside the pattern."""
    rng = np.random.default_rng(11)
    n, B, m = 40, 12, 4
    dense = (rng.random((n, n)) < 0.3) | np.eye(n, dtype=bool)
    dense[:, 35:] = dense[35:, :] = False  # DOFs 35-39 couple to nothing: misses
    np.fill_diagonal(dense, True)
    P = sp.csr_matrix(dense.astype(float))
    P.sort_indices()
    indptr, indices = P.indptr.astype(np.int64), P.indices.astype(np.int64)
    known_free = np.full((B, m), -9, dtype=np.int64)
    known_slots = np.empty((B, m, m), dtype=np.int64)
    free = rng.integers(-1, n, size=(B, m)).astype(np.int64)
    sign = rng.choice(np.array([-1, 1], dtype=np.int8), size=(B, m))
    for call in range(5):
        if call:  # a few blocks move, the others keep their DOFs (and their remembered slots)
            moved = rng.random(B) < 0.3
            free[moved] = rng.integers(-1, n, size=(int(moved.sum()), m))
            free[call, m - 1] = (free[call, m - 1] + 7) % n  # one block: its last DOF only
        K = rng.standard_normal((B, m, m))
        d0, d1 = np.zeros(indices.size), np.zeros(indices.size)
        misses0 = kernels.scatter_compact(free, sign, K, indptr, indices, d0)
        misses1 = kernels.scatter_compact_known(free, sign, K, indptr, indices, d1, known_free,
                                                known_slots)
        assert misses1 == misses0
        assert np.array_equal(d1, d0)
    assert misses0 > 0 and np.any(free < 0)  # both cases were met


def test_forget_evaluations_makes_the_next_evaluation_a_full_one(monkeypatch):
    """What the benchmarks time as one evaluation is one Newton iterate's: after
    ``forget_evaluations`` the closest-point kinematics are computed again (at the same u they
    are otherwise reused: a benchmark repeating one state would skip them), and the tangent
    is the same matrix (the cache only saves work)."""
    from sandwich.beam import contact_projection

    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    model = build_model(scene, contact_search="closest-point")
    u = _contact_state(model, np.random.default_rng(5))
    calls = []
    projected = contact_projection.closest_point_kinematics
    monkeypatch.setattr(contact_projection, "closest_point_kinematics",
                        lambda pairs, u_full: calls.append(1) or projected(pairs, u_full))
    K0 = model.tangent(u).copy()
    assert calls == [1]
    model.forget_evaluations(contact_kinematics=False)  # the kinematics are still reused
    model.tangent(u)
    assert calls == [1]
    model.forget_evaluations()
    K2 = model.tangent(u)
    assert calls == [1, 1]
    assert abs(K2 - K0).max() == 0.0
