"""The cohesive law (sandwich.cohesive_law) and its pairs in the beam model.

References: the work of separation under a constant mode mix is the Benzeggagh–Kenane
toughness in closed form (integrated here by the trapezoid rule along a monotonic opening,
independently of the law's own jumps); the tangent against central differences of the
tractions and of the model's internal force (not symmetric where the mode mix changes); a
solve with the model's factorisation of such a tangent against a dense solve.
"""

import dataclasses

import numpy as np
import pytest

from benchmarks.cases.fracture_cases import scene
from sandwich.beam import build_model
from sandwich.beam.cohesive import pair_damage
from sandwich.cohesive_law import CohesiveLaw
from sandwich.scene import Growth, Toughness

LAW = CohesiveLaw(2e3, sigma_c=0.5, tau_c=0.8, GIc=1e-3, GIIc=3e-3, eta=2.0)


def separation_work(law, mix, n=20001):
    """∫ t · dδ along a monotonic jump path at the mode mix ``mix`` (trapezoid rule)."""
    _, df = law.jumps(np.array([mix]))
    delta = np.linspace(0.0, 1.2 * float(df[0]), n)
    g, s = delta * np.sqrt(1.0 - mix), delta * np.sqrt(mix)
    committed = np.zeros(1)
    t = np.zeros((n, 2))
    for k in range(n):  # the damage committed at every step, as along a path
        t[k] = law.tractions(g[k:k + 1], s[k:k + 1], committed).real[0]
        committed = law.damage(g[k:k + 1], s[k:k + 1], committed).real
    power = t[:, 0] * np.gradient(g) + t[:, 1] * np.gradient(s)
    return float(np.sum(0.5 * (power[1:] + power[:-1])))


@pytest.mark.parametrize("mix", [0.0, 0.3, 0.7, 1.0])
def test_work_of_separation_is_the_bk_toughness(mix):
    exact = LAW.GIc + (LAW.GIIc - LAW.GIc) * mix**LAW.eta
    assert separation_work(LAW, mix) == pytest.approx(exact, rel=2e-3)


def test_damage_never_heals_and_unloading_goes_to_the_origin():
    g = np.array([3e-3])
    D = LAW.damage(g, np.zeros(1), np.zeros(1)).real
    assert 0.0 < D[0] < 1.0
    back = LAW.tractions(0.5 * g, np.zeros(1), D).real[0]
    assert back[0] == pytest.approx((1.0 - D[0]) * LAW.stiffness * 0.5 * g[0], rel=1e-12)
    assert LAW.damage(0.5 * g, np.zeros(1), D).real[0] == D[0]  # no more damage below
    assert LAW.damage(g * 0, np.zeros(1), D).real[0] == D[0]  # nor healing at rest


def test_compression_is_not_softened_within_an_increment():
    t = LAW.tractions(np.array([-1e-3]), np.array([5e-3]), np.array([0.2])).real[0]
    assert t[0] == pytest.approx(0.8 * LAW.stiffness * -1e-3, rel=1e-12)


def test_tangent_matches_central_differences_of_the_tractions():
    rng = np.random.default_rng(3)
    g, s = 2e-3 * rng.standard_normal(40), 2e-3 * rng.standard_normal(40)
    committed = 0.3 * LAW.damage(g, s, np.zeros(40)).real
    _, T, _, _ = LAW.response(g, s, committed)
    h = 1e-9
    J = np.stack([(LAW.tractions(g + h, s, committed).real
                   - LAW.tractions(g - h, s, committed).real) / (2 * h),
                  (LAW.tractions(g, s + h, committed).real
                   - LAW.tractions(g, s - h, committed).real) / (2 * h)], axis=-1)
    assert np.max(np.abs(T - J)) < 1e-5 * LAW.stiffness
    assert np.max(np.abs(T - np.swapaxes(T, 1, 2))) > 1e-2 * LAW.stiffness  # not symmetric


def test_a_stiffness_below_the_strengths_floor_is_refused():
    with pytest.raises(ValueError, match="softens before"):
        CohesiveLaw(100.0, sigma_c=1.0, tau_c=1.0, GIc=1e-3, GIIc=1e-3)


def damaging_model(toughness=(1e-3, 3e-3), elements=40, seed=2):
    """A cantilever with a cohesive zone, a state u where most of it damages, and its pairs.

    The committed damage is half of what u gives, so the damage grows at u.
    """
    sc = scene([("top", 0.0, 1.0)], a=40.0, until=0.5, core=1, elements=elements)
    gic, giic = toughness
    d = dataclasses.replace(sc.debonds[0], toughness=Toughness(gic, giic),
                            growth=Growth(method="cohesive", sigma_c=0.5,
                                          tau_c=0.5 * (giic / gic) ** 0.5, zone=30.0,
                                          stiffness=2e3))
    model = build_model(dataclasses.replace(sc, debonds=(d,)))
    pairs = next(p for p in model.pairs if p.cohesive is not None)
    u = 6e-4 * np.random.default_rng(seed).standard_normal(model.size)
    damage = pair_damage(pairs, model.expand(u))
    assert np.count_nonzero(damage.max(axis=1)) > pairs.size // 2  # most pairs damaging at u
    pairs.cohesive.damage[:] = 0.5 * damage
    model.forget_evaluations()
    return model, pairs, u


@pytest.mark.parametrize("toughness", [(1e-3, 1e-3), (1e-3, 3e-3)], ids=["one-mode", "bk"])
def test_model_tangent_against_finite_differences_with_damage_growing(toughness):
    """The beam's reduced tangent against central differences of its force, damage growing.

    With equal toughness and strengths the law is mode-independent; under Benzeggagh–Kenane
    its tangent is not symmetric, and the model's is the whole Jacobian all the same.
    """
    model, pairs, u = damaging_model(toughness, elements=60, seed=0)
    gic, giic = toughness
    K = model.tangent(u).toarray()
    cols = np.unique(model.dof_map.free[pairs.dofs.ravel()])
    cols = cols[cols >= 0]
    h = 1e-9
    J = np.empty((model.size, cols.size))
    for k, j in enumerate(cols):
        e = np.zeros(model.size)
        e[j] = h
        model.forget_evaluations()
        fp = model.internal_force(u + e)
        model.forget_evaluations()
        J[:, k] = (fp - model.internal_force(u - e)) / (2 * h)
    scale = np.abs(K[np.ix_(cols, cols)]).max()
    assert np.abs(K[:, cols] - J).max() < 1e-6 * scale
    skew = np.abs(K[np.ix_(cols, cols)] - K[np.ix_(cols, cols)].T).max()
    assert (skew > 1e-3 * scale) == (gic != giic)


def test_unsymmetric_tangent_is_solved_whole_with_its_symmetric_part_s_inertia():
    from sandwich.beam.unsymmetric import UnsymmetricFactorization

    model, _, u = damaging_model(seed=2)
    K = model.tangent(u)
    fac = model.factorize(K)
    assert isinstance(fac, UnsymmetricFactorization)
    b = np.random.default_rng(3).standard_normal(model.size)
    dense = K.toarray()
    assert np.allclose(dense @ fac.solve(b), b, rtol=0, atol=1e-8 * np.abs(b).max())
    eig = np.linalg.eigvalsh(0.5 * (dense + dense.T))
    assert fac.negative_pivots == int(np.sum(eig < 0))


def test_symmetric_part_from_the_blocks_equals_the_matrix_s():
    from sandwich.beam.unsymmetric import skew_split

    model, _, u = damaging_model(seed=4)
    K = model.tangent(u)
    fast, slow = model._symmetric_part(K), skew_split(K)
    assert fast is not None and slow is not None
    assert np.abs((fast - slow).toarray()).max() < 1e-9 * np.abs(K.data).max()
