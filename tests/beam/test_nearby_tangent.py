"""The beam's evaluation for iterates within a converged increment (``internal_force_nearby``).

References: the model's own full evaluation (force: bit for bit; it is the same sum), the
block path's separate layer and contact blocks (the tangent kept is the layers' at the last
u plus the contact law's at the new u, assembled independently here), and the same path solved
without the nearby evaluation (same converged states to the corrector's tolerance).
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import build_model, run
from sandwich.beam.solve import linear_solution
from sandwich.scene_file import load_scene

SCENE = Path(__file__).parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


@pytest.fixture(scope="module")
def fig5():
    return load_scene(SCENE)


def _states(scene, level):
    """A model of fig. 5 and two states with the debonded face pressed on the core."""
    model = build_model(scene, elements=60, core_level=level)
    u0, _ = linear_solution(model, 900.0)
    rng = np.random.default_rng(1)
    u1 = u0 * (1.0 + 1e-3 * rng.standard_normal(u0.size))
    return model, u0, u1


@pytest.mark.parametrize("level", [1, 2])
def test_nearby_force_is_the_full_force_bit_for_bit(fig5, level):
    model, u0, u1 = _states(fig5, level)
    model.internal_force(u0)
    f_nearby = model.internal_force_nearby(u1)
    fresh = build_model(fig5, elements=60, core_level=level)
    assert np.array_equal(f_nearby, fresh.internal_force(u1))


@pytest.mark.parametrize("level", [1, 2])
def test_nearby_tangent_is_the_last_layers_and_the_new_contact(fig5, level):
    model, u0, u1 = _states(fig5, level)
    model.internal_force(u0)
    model.internal_force_nearby(u1)
    model.internal_force_nearby(u1 + 1e-4 * (u1 - u0))  # chained: the terms swap again
    u2 = u1 + 1e-4 * (u1 - u0)
    K = model.tangent(u2).toarray()
    # independent assembly (block path, ReducedPattern.assemble): layers at u0, contact at u2
    ref = build_model(fig5, elements=60, core_level=level)
    n_layers = len(ref.block_dofs) - len(ref.pairs)
    _, blocks0 = ref.full_response(ref.expand(u0))
    _, blocks2 = ref.full_response(ref.expand(u2))
    assert any(np.any(b) for b in blocks2[n_layers:]), "no contact: the test would not test it"
    expected = ref.full_pattern.assemble(blocks0[:n_layers] + blocks2[n_layers:]).toarray()
    scale = np.abs(expected).max()
    assert np.abs(K - expected).max() <= 1e-11 * scale
    # and it is not the exact tangent at u2 (the layers did change: the test can fail)
    exact = build_model(fig5, elements=60, core_level=level).tangent(u2).toarray()
    assert np.abs(exact - expected).max() > 1e3 * 1e-11 * scale


def test_a_path_with_and_without_the_nearby_evaluation(fig5):
    """fig. 5 to −5 mm at 60 elements: the same converged states to the corrector's tolerance
    (1e-8) and the same steps; with it, fewer layer tangents are computed."""
    scene = dataclasses.replace(fig5, analysis=dataclasses.replace(fig5.analysis,
                                                                   until_value=-5.0))
    import sandwich.beam.model as model_module

    calls = {"nearby": 0}
    original = model_module.BeamModel.internal_force_nearby

    def counted(self, u):
        calls["nearby"] += 1
        return original(self, u)

    try:
        model_module.BeamModel.internal_force_nearby = counted
        with_nearby = run(scene, elements=60, model_options={"core_level": 1}).solution
        del model_module.BeamModel.internal_force_nearby
        without = run(scene, elements=60, model_options={"core_level": 1}).solution
    finally:
        model_module.BeamModel.internal_force_nearby = original
    assert calls["nearby"] > 0
    assert with_nearby.converged and without.converged
    assert len(with_nearby.history) == len(without.history)
    for a, b in zip(with_nearby.history, without.history, strict=True):
        assert a.load_factor == pytest.approx(b.load_factor, rel=1e-7, abs=1e-9)
        for name, value in a.probes.items():
            assert value == pytest.approx(b.probes[name], rel=1e-7, abs=1e-9)


@pytest.mark.parametrize("level", [1, 2])
def test_force_only_is_the_full_force_bit_for_bit_and_leaves_the_cache(fig5, level):
    """``internal_force_only`` (the line search's halved trials): the same force as a full
    evaluation of a fresh model, contact pressed; the last full evaluation stays cached."""
    model, u0, u1 = _states(fig5, level)
    K0 = model.tangent(u0)
    f_only = model.internal_force_only(u1)
    fresh = build_model(fig5, elements=60, core_level=level)
    assert np.array_equal(f_only, fresh.internal_force(u1))
    assert model.tangent(u0) is K0  # the cache still holds u0's evaluation
    assert np.array_equal(model.tangent(u1).toarray(), fresh.tangent(u1).toarray())
