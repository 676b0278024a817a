"""The core hierarchy: enrichment functions, rules, level 1 = the paper, tangent, transitions.

References: closed-form spans (piecewise cubics, polynomials), exact integrals of piecewise
polynomials, the level-1 model itself (zero enrichment must reproduce it), central finite
differences of the internal force, and the nested-space identity of Galerkin solutions.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from beam_scenes import sandwich_scene as three_point_bend

from sandwich.beam import build_model
from sandwich.beam.core_basis import MAX_LEVEL, CoreBasis
from sandwich.beam.core_levels import transfer
from sandwich.beam.dofs import NODE_DOFS
from sandwich.beam.shape_functions import x_shape, z_shape
from sandwich.beam.solve import linear_solution
from sandwich.scene import Analysis, Debond


def _hermite_cubic(xi: np.ndarray) -> np.ndarray:
    """The paper's four z functions (H_b, Hbar_b, H_t, Hbar_t) at ``xi``, shape (4, n)."""
    return np.array([z_shape(k, xi)[0] for k in ("H_b", "Hbar_b", "H_t", "Hbar_t")])


def _span_residual(basis: CoreBasis, level: int, target: np.ndarray, xi: np.ndarray) -> float:
    A = np.vstack([_hermite_cubic(xi), *[f(xi)[0][None] for f in
                                          basis.functions[:basis.count(level)]]]).T
    coef, *_ = np.linalg.lstsq(A, target, rcond=None)
    return float(np.max(np.abs(A @ coef - target)) / np.max(np.abs(target)))


@pytest.mark.parametrize("family", ["sublayers", "polynomial"])
def test_enrichment_vanishes_with_its_slope_on_the_core_boundaries(family):
    basis = CoreBasis(family, MAX_LEVEL)
    for f in basis.functions:
        v, d = f(np.array([-1.0, 1.0]))
        assert np.allclose(v, 0.0, atol=1e-14) and np.allclose(d, 0.0, atol=1e-13)
        ξ = np.linspace(-0.999, 0.999, 301)
        h = 1e-6
        fd = (f(ξ + h)[0] - f(ξ - h)[0]) / (2 * h)  # central difference of the value
        assert np.allclose(fd, f(ξ)[1], atol=1e-6)


def test_sublayers_span_every_c1_piecewise_cubic_of_their_partition():
    rng = np.random.default_rng(3)
    basis = CoreBasis("sublayers", 4)
    for level in (2, 3, 4):
        cuts = basis.partition(level)
        values, slopes = rng.normal(size=cuts.size), rng.normal(size=cuts.size)
        ξ = np.linspace(-1, 1, 2001)
        target = np.zeros_like(ξ)
        for i in range(cuts.size - 1):  # Hermite interpolation on each sublayer
            a, b = cuts[i], cuts[i + 1]
            on = (ξ >= a) & (ξ <= b)
            t = 2 * (ξ[on] - a) / (b - a) - 1
            half = (b - a) / 2
            target[on] = (values[i] * x_shape("H", 0, t)[0] + values[i + 1] * x_shape("H", 1, t)[0]
                          + half * slopes[i] * x_shape("Hbar", 0, t)[0]
                          + half * slopes[i + 1] * x_shape("Hbar", 1, t)[0])
        assert _span_residual(basis, level, target, ξ) < 1e-10
        # ...and a partition one level finer is not spanned (the hierarchy adds something).
        finer = CoreBasis("sublayers", level + 1).functions[basis.count(level)]
        assert _span_residual(basis, level, finer(ξ)[0], ξ) > 1e-3


def test_polynomial_levels_span_the_polynomials_of_their_degree():
    rng = np.random.default_rng(4)
    basis = CoreBasis("polynomial", 4)
    ξ = np.linspace(-1, 1, 401)
    for level in (2, 3, 4):
        degree = 3 + 2 * (level - 1)
        p = np.polynomial.Polynomial(rng.normal(size=degree + 1))
        assert _span_residual(basis, level, p(ξ), ξ) < 1e-10
        assert _span_residual(basis, level, ξ ** (degree + 1), ξ) > 1e-4


@pytest.mark.parametrize("family", ["sublayers", "polynomial"])
def test_the_core_rule_integrates_its_level_energy_exactly(family):
    """Sublayers: a random degree-13 polynomial per sublayer; polynomial: degree 4p + 1."""
    rng = np.random.default_rng(5)
    basis = CoreBasis(family, 4)
    for level in (2, 3, 4):
        ξ, w = basis.rule(level)
        cuts = basis.partition(level)
        degree = 13 if family == "sublayers" else 4 * (3 + 2 * (level - 1)) + 1
        exact = approx = 0.0
        for i in range(cuts.size - 1):
            p = np.polynomial.Polynomial(rng.normal(size=degree + 1))
            P = p.integ()
            exact += P(cuts[i + 1]) - P(cuts[i])
            on = (ξ > cuts[i]) & (ξ < cuts[i + 1])
            approx += float(w[on] @ p(ξ[on]))
        assert approx == pytest.approx(exact, rel=1e-12, abs=1e-12)


def _debonded_bend(elements: int = 12):
    s = three_point_bend()
    return dataclasses.replace(s, debonds=(Debond("top", 100.0, 200.0),))


def _random_state(model, rng, scale=0.05):
    u = rng.normal(size=model.size) * scale
    return u


def test_level_1_is_the_paper_element_bit_for_bit():
    scene = _debonded_bend()
    rng = np.random.default_rng(6)
    paper = build_model(scene, elements=12)
    explicit = build_model(scene, elements=12, core_level=1)
    u = _random_state(paper, rng)
    assert explicit.size == paper.size
    assert np.array_equal(explicit.internal_force(u), paper.internal_force(u))
    assert (explicit.tangent(u) != paper.tangent(u)).nnz == 0


@pytest.mark.parametrize("family", ["sublayers", "polynomial"])
def test_zero_enrichment_reproduces_the_paper_element(family):
    """Any levels with all enrichment amplitudes zero: the paper's forces to round-off."""
    scene = _debonded_bend()
    rng = np.random.default_rng(7)
    paper = build_model(scene, elements=12)
    levels = np.array([1, 2, 3, 3, 2, 1, 1, 4, 4, 2, 1, 3])
    rich = build_model(scene, elements=12, core_level=levels, core_basis=family)
    u = _random_state(paper, rng)
    v = transfer(u, paper, rich)
    f_rich = rich.internal_force(v)
    back = transfer(f_rich, rich, paper)  # the paper DOFs' rows (the free numbering differs)
    f_paper = paper.internal_force(u)
    assert np.allclose(back, f_paper, rtol=0, atol=1e-9 * np.abs(f_paper).max())


@pytest.mark.parametrize("family", ["sublayers", "polynomial"])
def test_tangent_matches_finite_differences_at_mixed_levels(family):
    scene = _debonded_bend()
    rng = np.random.default_rng(8)
    levels = np.array([1, 2, 3, 3, 2, 1, 1, 3, 3, 2, 1, 2])
    model = build_model(scene, elements=12, core_level=levels, core_basis=family)
    u = _random_state(model, rng, 0.2)
    K = model.tangent(u)
    for _ in range(3):
        v = rng.normal(size=model.size)
        h = 1e-6
        fd = (model.internal_force(u + h * v) - model.internal_force(u - h * v)) / (2 * h)
        assert np.linalg.norm(K @ v - fd) <= 1e-6 * np.linalg.norm(fd)
    assert abs(K - K.T).max() <= 1e-10 * abs(K).max()


def test_level_transitions_are_conforming():
    """The enrichment of a node shared with a lower-level element is fixed at zero, and the
    core's field at that node is the same seen from both elements."""
    scene = _debonded_bend()
    levels = np.array([1] * 4 + [3] * 4 + [2] * 4)
    model = build_model(scene, elements=12, core_level=levels)
    n = model.mesh.n_nodes
    m = (model.dof_map.n_full - NODE_DOFS * n) // n
    active = (model.dof_map.free[NODE_DOFS * n:].reshape(n, m)[:, model.face_extra:] >= 0
              ).sum(axis=1)  # the core's enrichment (after the faces' stretch DOFs)
    assert active[4] == 0 and active[8] == 4 * CoreBasis("sublayers", 3).count(2)
    assert active[6] == 4 * CoreBasis("sublayers", 3).count(3)
    rng = np.random.default_rng(9)
    u_full = model.expand(rng.normal(size=model.size))
    from sandwich.beam.fields import sample_layer

    ξ = np.linspace(-1, 1, 9)
    left = sample_layer(model, "core", u_full, np.ones(9), ξ)
    right = sample_layer(model, "core", u_full, -np.ones(9), ξ)
    for k in ("u", "w"):
        assert np.allclose(getattr(left, k)[:-1], getattr(right, k)[1:], atol=1e-12)


def test_linear_stiffness_converges_with_the_level():
    """Nested spaces: the linear compliance grows monotonically with the level, and the level
    increments shrink at least geometrically (observed factor ≥ 2 per level)."""
    scene = three_point_bend()
    probe = scene.probes[0].name
    k = []
    for level in (1, 2, 3, 4):
        m = build_model(scene, elements=60, core_level=level)
        u, _ = linear_solution(m, 1.0)
        k.append(-1.0 / float(m.probe_vector(probe) @ u))
    steps = -np.diff(k)
    assert np.all(steps > 0), k
    assert np.all(steps[1:] <= 0.5 * steps[:-1]), k


def test_field_grid_shows_the_sublayers_and_their_levels():
    from sandwich.beam.fields import core_rows, section_fields

    scene = _debonded_bend()
    levels = np.array([1] * 4 + [3] * 4 + [2] * 4)
    model = build_model(scene, elements=12, core_level=levels)
    rows = core_rows(model, 9)
    for cut in CoreBasis("sublayers", 3).partition(3):
        assert np.any(np.isclose(rows, cut))
    f = section_fields(model, np.zeros(model.size), per_element=2)
    core_cells = f.region == 0
    assert set(np.unique(f.core_level[core_cells])) == {1, 2, 3}
    assert np.all(f.core_level[~core_cells] == 0)
    # the cells of element 5 (level 3) carry level 3: columns 10, 11 of every core row
    per_row = 12 * 2
    assert np.all(f.core_level[:core_cells.sum()].reshape(-1, per_row)[:, 10:12] == 3)


def test_linear_active_set_from_another_start_ends_at_the_same_fixed_point():
    """The unilateral linear step minimises a strictly convex energy, so the active-set
    iteration has one fixed point whatever it starts from: every pair open (the default),
    every pair closed, or another level's settled set (what the auto levels hand on) give the
    same set and the same solution, the last in one pass."""
    from sandwich.beam.linear_step import active_set_solution

    scene = _debonded_bend()
    m1 = build_model(scene, elements=24, core_level=1)
    m3 = build_model(scene, elements=24, core_level=3)
    _, _, settled_1 = active_set_solution(m1, 1.0)
    u3, passes_3, settled_3 = active_set_solution(m3, 1.0)
    closed = int(settled_3[0].sum())
    assert passes_3 >= 3 and 0 < closed < settled_3[0].size  # a real active-set problem
    for start in (settled_1, [np.ones_like(a) for a in settled_3]):
        u, passes, settled = active_set_solution(m3, 1.0, start)
        assert all(np.array_equal(a, b) for a, b in zip(settled, settled_3, strict=True))
        assert np.linalg.norm(u - u3) <= 1e-14 * np.linalg.norm(u3)
        assert passes < passes_3
    assert active_set_solution(m3, 1.0, settled_1).passes == 1


def test_the_level_choice_solves_each_model_once(monkeypatch):
    """Nothing computed twice: the floor's linear step that finds the load's sign (an until
    probe) is the level choice's first solve, and each model of the choice is solved once —
    and the choice is the one made with every solve done afresh (each from every pair open)."""
    from sandwich.beam import linear_step
    from sandwich.beam.core_choice import choose_core_levels
    from sandwich.beam.solve import scene_model_options

    base = _debonded_bend()
    scene = dataclasses.replace(base, beam_model=dataclasses.replace(
        base.beam_model, core="auto", elements=24), analysis=Analysis(
        kind="nonlinear", until_probe="w_top_mid", until_value=-4.0))
    options = scene_model_options(scene)
    real = linear_step.active_set_solution
    seen: list[tuple[int, int]] = []

    def counted(model, load_factor, start=None):
        seen.append((id(model), model.size))
        return real(model, load_factor, start)

    monkeypatch.setattr(linear_step, "active_set_solution", counted)
    choice = choose_core_levels(scene, None, options)
    assert len(seen) >= 3  # the floor, its look-ahead, at least one raise
    assert len(set(seen)) == len(seen), seen

    def afresh(model, load_factor, start=None):
        return real(model, load_factor, None)

    monkeypatch.setattr(linear_step, "active_set_solution", afresh)
    again = choose_core_levels(scene, None, options)
    assert np.array_equal(choice.levels, again.levels)
    assert np.any(choice.levels > 1)
    assert [p["estimate"] for p in choice.passes] == pytest.approx(
        [p["estimate"] for p in again.passes], rel=1e-9)


def _linear_run(scene, core):
    """The linear step as the runner solves it: ``run`` with ``[beam_model] core = core``."""
    from sandwich.beam import run

    s = dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model, core=core),
                            analysis=dataclasses.replace(scene.analysis, kind="linear"))
    return run(s)


def test_linear_responses_are_the_runs_linear_steps_with_fewer_passes(monkeypatch):
    """``linear_responses`` (the study's error indicator) against the runner's own linear step
    at each level (reference: ``run``, each solve from every pair open): the probe's value at
    unit load is until / λ of the run, to round-off; the second level's active-set solve starts
    from the first level's set and takes fewer passes than from every pair open."""
    from sandwich.beam import linear_step
    from sandwich.beam.core_choice import linear_responses

    scene = dataclasses.replace(_debonded_bend(), beam_model=dataclasses.replace(
        _debonded_bend().beam_model, elements=24), analysis=Analysis(
        kind="nonlinear", until_probe="w_top_mid", until_value=-4.0))
    real = linear_step.active_set_solution
    passes = []

    def counted(model, load_factor, start=None):
        out = real(model, load_factor, start)
        passes.append((model.size, start is not None, out.passes))
        return out

    monkeypatch.setattr(linear_step, "active_set_solution", counted)
    lo, hi = linear_responses(scene, (1, 3))
    seeded = passes[-1]
    passes.clear()
    for core, r in ((1, lo), (3, hi)):
        sol = _linear_run(scene, core).solution
        assert -4.0 / sol.history[-1].load_factor == pytest.approx(r, rel=1e-12)
    afresh = passes[-1]
    assert seeded[0] == afresh[0] and seeded[1] and not afresh[1]
    assert afresh[2] >= 3 and seeded[2] < afresh[2], (seeded, afresh)
    assert abs(hi / lo - 1) > 1e-3  # level 3 is another answer (the comparison has content)


def test_linear_responses_without_a_probe_are_compliances():
    """A load target: the response is the compliance fᵀu at λ = 1, against the runner's linear
    step at λ = until_load_factor (fᵀu / λ; homogeneous in λ > 0 with unilateral contact)."""
    from sandwich.beam.core_choice import linear_responses

    scene = dataclasses.replace(_debonded_bend(), beam_model=dataclasses.replace(
        _debonded_bend().beam_model, elements=24), analysis=Analysis(
        kind="nonlinear", control="load", until_load_factor=50.0))
    got = linear_responses(scene, (1, 2))
    for core, r in zip((1, 2), got, strict=True):
        run = _linear_run(scene, core)
        u = run.states[-1].u
        assert float(run.model.f_ref @ u) / 50.0 == pytest.approx(r, rel=1e-10)
    assert got[0] > 0 and abs(got[1] / got[0] - 1) > 1e-3


def test_linear_contact_added_on_the_tangents_pattern_is_scipys_sum():
    """The active-set passes add the linearised contact at its slots of K₀'s pattern instead of
    forming scipy's sum (whose pattern drops K₀'s explicit zeros) and embedding it back: every
    entry the same bits as the sum's, and None for an entry outside the pattern."""
    from sandwich.beam.linear_step import linear_contact_matrix, pattern_keys, plus_on_pattern

    model = build_model(_debonded_bend(), elements=24, core_level=2)
    K0 = model.tangent(np.zeros(model.size))
    keys = pattern_keys(model, K0)
    assert keys is not None and np.all(np.diff(keys) > 0)
    rng = np.random.default_rng(3)
    active = [rng.random(p.size) < 0.5 for p in model.pairs]
    C = linear_contact_matrix(model, active)
    assert C.nnz > 0
    got, want = plus_on_pattern(K0, C, keys), (K0 + C).tocsr()
    assert got.indices is K0.indices or np.array_equal(got.indices, K0.indices)
    diff = got - want
    assert diff.count_nonzero() == 0  # the same bits where the sum has entries, zeros elsewhere
    assert np.array_equal(got.toarray(), want.toarray())
    far = sp.csr_matrix(([1.0], ([0], [model.size - 1])), shape=K0.shape)  # no such coupling
    assert plus_on_pattern(K0, far, keys) is None
    assert pattern_keys(model, want) is None  # the sum is not on the pattern


def test_the_linear_step_of_a_long_debond_settles():
    """fig. 5's scene with a 75 mm top debond off centre: the contact zone is far narrower than
    the debond and its edge walks one pair per active-set pass, 55 passes (the old flat cap of
    50 stopped every linear step of it, and with it every ``auto`` run). Reference: the
    iteration's fixed point is unique (a strictly convex energy), so the start from every pair
    closed reaches the same set and solution; the solution's gaps are that set's signs."""
    from pathlib import Path

    from sandwich.beam import run
    from sandwich.beam.contact_search import NORMAL_SIGN
    from sandwich.beam.linear_step import active_set_solution
    from sandwich.scene_file import load_scene

    root = Path(__file__).resolve().parents[2]
    base = load_scene(root / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    scene = dataclasses.replace(base, debonds=(Debond("top", 52.5, 127.5),),
                                beam_model=dataclasses.replace(base.beam_model, core=1),
                                analysis=dataclasses.replace(base.analysis, kind="linear"))
    r = run(scene)
    assert r.solution.converged and r.states[-1].iterations > 50
    model = r.model
    u, passes, active = active_set_solution(model, 1.0)
    closed = [np.ones(p.size, dtype=bool) for p in model.pairs]
    u2, _, active2 = active_set_solution(model, 1.0, closed)
    assert all(np.array_equal(a, b) for a, b in zip(active, active2, strict=True))
    assert np.max(np.abs(u2 - u)) <= 1e-10 * np.max(np.abs(u))
    v = model.expand(u)[model.pairs[0].dofs]
    gap = NORMAL_SIGN[model.pairs[0].interface] * (v[:, 1] - v[:, 3])
    assert np.array_equal(gap < 0, active[0]) and 0 < active[0].sum() < active[0].size // 2
