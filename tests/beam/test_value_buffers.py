"""The tangent's CSR value arrays are reused between evaluations (``zeroed_values``).

A reused array must never be one a caller still holds (a matrix or a view of its values), and a
reused one must start from zero: the references are copies taken before, and a fresh model's
tangent at the same state (bit for bit: the same sums in the same order).
"""

from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import build_model
from sandwich.beam.solve import linear_solution
from sandwich.scene_file import load_scene

SCENE = Path(__file__).parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


@pytest.fixture(scope="module")
def states():
    scene = load_scene(SCENE)
    model = build_model(scene, elements=40, core_level=2)
    u0, _ = linear_solution(model, 900.0)
    return scene, model, [u0 * s for s in (1.0, 1.1, 1.2, 1.3, 1.4)]


def test_a_held_tangent_or_view_is_never_overwritten(states):
    _, model, us = states
    held = [model.tangent(u) for u in us]  # every array held: none may be reused
    kept = [K.toarray() for K in held]
    for u in us:
        model.tangent(u * 0.95)
    assert all(np.array_equal(K.toarray(), k) for K, k in zip(held, kept, strict=True))
    view = held[0].data[5:50]
    view_kept = view.copy()
    del held
    for u in us:
        model.tangent(u * 0.9)
    assert np.array_equal(view, view_kept)  # the view alone keeps its array out of reuse


def test_a_released_array_is_reused_and_starts_from_zero(states):
    scene, model, us = states
    for u in us:
        model.tangent(u)  # each drops the last matrix: its array comes free for reuse
    before = {b.ctypes.data for b in model.compiled.spare_values}  # addresses: no extra reference
    K = model.tangent(us[0] * 0.9)  # not the cached state: a new evaluation
    assert K.data.base.ctypes.data in before  # an array of the list, not a new one
    fresh = build_model(scene, elements=40, core_level=2).tangent(us[0] * 0.9)
    assert np.array_equal(K.toarray(), fresh.toarray())


def test_the_factorisations_keep_one_structure_and_retire_those_they_drop(states):
    """A structure the model's factorisations drop (widened, of a pattern that grew) is retired
    (its pattern-sized maps go, EnvelopeStructure.retire); a factorisation made on it still
    solves, bit for bit; the model keeps the structures of its present pattern only."""
    from sandwich.solver.envelope import EnvelopeFactorization

    scene, _, us = states
    model = build_model(scene, elements=40, core_level=2)  # its pattern grows below
    assert model.pairs[-1].search == "closest-point"
    fac = model.factorize(model.tangent(us[2]))
    assert isinstance(fac, EnvelopeFactorization)
    first = fac.structure
    b = np.arange(model.size, dtype=float)
    x = fac.solve(b)
    old = model.factorisations.structures
    assert first in old and first.indices is not None
    model.compiled.grow(model.block_dofs[-1][:1, :10])  # the pattern grows: a new one
    fac2 = model.factorize(model.tangent(us[2]))
    assert fac2.structure is not first and first.indices is None  # retired with its pattern
    assert all(s.indices is not None for s in model.factorisations.structures)
    assert np.array_equal(fac.solve(b), x)
    assert np.allclose(fac2.solve(b), x, rtol=1e-9, atol=1e-9 * np.abs(x).max())
