"""Sum-factorised layer kernel (sandwich.beam.sum_factor) against the packed kernel and NumPy.

The factored kernel integrates the same integrand with the same Gauss points, weights and point
matrices as the packed kernel (sandwich.beam.packed_kernel.packed_kernel) and the NumPy reference
(sandwich.beam.element); only the order of the summation changes (ξ first, then η). So every
force and tangent must agree with both to round-off (references: the NumPy path and the packed
kernel, independent code), on strongly deformed states, at every core level and basis, and in a
model with mixed levels, contact and debonds. Its tangent is checked against central finite
differences of its own force; and the factor detection must refuse rows that do not factor.
"""

from dataclasses import replace

import numpy as np
import pytest
from beam_scenes import KEVLAR, ROHACELL, Debond, sandwich_scene  # noqa: I001

from sandwich.beam import build_model, element, kernels
from sandwich.beam.constitutive import core_stiffness, face_stiffness
from sandwich.beam.core_basis import CoreBasis
from sandwich.beam.layer_operators import build_core_operators, build_layer_operators
from sandwich.beam.quadrature import EXACT_ORDER
from sandwich.beam.sum_factor import CHUNK, factored_operators

TOL = 1e-12  # relative to the largest entry: round-off of sums over ≤ 343 points


def _rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.fixture
def mode():
    """Set kernels.SUM_FACTORISATION for one test, restored after it."""
    saved = kernels.SUM_FACTORISATION
    yield lambda m: setattr(kernels, "SUM_FACTORISATION", m)
    kernels.SUM_FACTORISATION = saved


def _core(basis, level, gauss=(7, 7)):
    return build_core_operators(25.0, -12.5, core_stiffness(ROHACELL), CoreBasis(basis, 4),
                                level, gauss=gauss)


def _state(op, rng, E, amplitude):
    u = rng.normal(size=(E, int(op.dofs.max()) + 1)) * amplitude
    return u, rng.uniform(1.0, 9.0, size=E)


@pytest.mark.parametrize("basis", ["sublayers", "polynomial"])
@pytest.mark.parametrize("level", [1, 2, 3, 4])
def test_factored_kernel_matches_packed_kernel_and_numpy(basis, level, mode):
    op = _core(basis, level)
    assert factored_operators(op) is not None
    rng = np.random.default_rng(level)
    E = 70  # several blocks of sum_factor.CHUNK elements, the last one partial
    u, lengths = _state(op, rng, E, 0.4)  # displacement gradients of order 0.1-0.5
    assert E > 2 * CHUNK and E % CHUNK
    f_ref, K_ref = element.layer_response(op, u, lengths, 60.0)
    mode("never")
    f_packed, K_packed = kernels.layer_response(op, u, lengths, 60.0)
    mode("always")
    f, K = kernels.layer_response(op, u, lengths, 60.0)
    assert _rel(f, f_ref) < TOL and _rel(f, f_packed) < TOL
    assert _rel(K, K_ref) < TOL and _rel(K, K_packed) < TOL
    assert np.array_equal(K, K.transpose(0, 2, 1))  # exactly symmetric, as the packed kernel
    f_only, none = kernels.layer_response(op, u, lengths, 60.0, tangent=False)
    assert none is None and np.array_equal(f_only, f)  # the same force with or without K
    assert np.abs(K - K_packed).max() > 0  # really another summation (not the packed path)


@pytest.mark.parametrize("name,h,C", [("top", 0.5, face_stiffness(KEVLAR)),
                                      ("core", 25.0, core_stiffness(ROHACELL))])
@pytest.mark.parametrize("gauss", ["exact", (3, 2), (9, 8)])
def test_factored_kernel_on_paper_layers_and_other_rules(name, h, C, gauss, mode):
    op = build_layer_operators(name, h, 0.0, C, gauss=EXACT_ORDER[name] if gauss == "exact"
                               else gauss)
    u, lengths = _state(op, np.random.default_rng(7), 40, 0.5)
    f_ref, K_ref = element.layer_response(op, u, lengths, 60.0)
    mode("always")
    f, K = kernels.layer_response(op, u, lengths, 60.0)
    assert kernels.uses_sum_factorisation(op)
    assert _rel(f, f_ref) < TOL and _rel(K, K_ref) < TOL


@pytest.mark.parametrize("level", [2, 4])
def test_factored_tangent_matches_finite_differences(level, mode):
    mode("always")
    op = _core("sublayers", level)
    rng = np.random.default_rng(2)
    u, lengths = _state(op, rng, 2, 0.3)
    _, K = kernels.layer_response(op, u, lengths, 60.0)
    step = 1e-6
    for a in rng.choice(op.dofs.size, size=24, replace=False):
        du = np.zeros_like(u)
        du[:, op.dofs[a]] = step
        fp = kernels.layer_response(op, u + du, lengths, 60.0, tangent=False)[0]
        fm = kernels.layer_response(op, u - du, lengths, 60.0, tangent=False)[0]
        assert np.max(np.abs(K[:, :, a] - (fp - fm) / (2 * step))) < 1e-6 * np.max(np.abs(K))


def test_rows_that_do_not_factor_keep_the_packed_kernel(mode):
    op = _core("sublayers", 2)
    rng = np.random.default_rng(0)
    # a non-tensor rule (random points)
    assert factored_operators(op.at(rng.uniform(-1, 1, 30), rng.uniform(-1, 1, 30))) is None
    # one column that is not a product of an x- and a z-function
    bad = op.N_xi.copy()
    bad[:, 3] += 1e-6 * np.abs(bad).max() * op.eta * op.xi ** 2
    broken = replace(op, N_xi=bad)
    assert factored_operators(broken) is None
    mode("always")
    assert not kernels.uses_sum_factorisation(broken)
    # membrane-averaged faces are not the kernels' at all
    face = build_layer_operators("top", 0.5, 0.0, face_stiffness(KEVLAR), gauss=(5, 3),
                                 membrane_average=True)
    assert factored_operators(face) is None


def _paper_face():
    """The paper's top face (no averaged membrane): its rows factor, at 1.4× fewer flops."""
    return build_layer_operators("top", 0.5, 0.0, face_stiffness(KEVLAR),
                                 gauss=EXACT_ORDER["top"])


def test_auto_takes_the_factored_kernel_for_the_cores_only(mode):
    """The cores (the paper's, 2.2× fewer flops, included) factored; the faces (1.4×) packed."""
    mode("auto")
    faces = [build_layer_operators(n, 0.5, 0.0, face_stiffness(KEVLAR), gauss=EXACT_ORDER[n])
             for n in ("top", "bottom")]
    assert all(factored_operators(op) is not None for op in faces)  # they could be
    assert not any(kernels.uses_sum_factorisation(op) for op in faces)
    for basis in ("sublayers", "polynomial"):
        for level in (1, 2, 3, 4):
            op = _core(basis, level)
            assert kernels.uses_sum_factorisation(op)
            packed = op.eta.size * kernels.point_flops(op)
            assert kernels.layer_flops(op) * kernels.FACTORED_OVERHEAD < packed


def test_the_kept_decision_follows_the_setting(mode):
    """The decision is kept on the layer per setting: a changed setting is obeyed at once."""
    op = _core("sublayers", 2)
    for setting, expected in (("auto", True), ("never", False), ("always", True),
                              ("auto", True)):
        mode(setting)
        assert kernels.uses_sum_factorisation(op) is expected
    face = _paper_face()  # the rows factor, but auto keeps the packed kernel
    for setting, expected in (("auto", False), ("always", True), ("auto", False)):
        mode(setting)
        assert kernels.uses_sum_factorisation(face) is expected


def _contact_state(model, rng):
    """Random state with every contact pair penetrating (as in test_beam_kernels)."""
    u = rng.normal(size=model.size) * 0.02
    free = model.dof_map.free
    for pairs in model.pairs:
        sign = 1.0 if pairs.interface == "top" else -1.0
        w_face, w_core = free[pairs.dofs[:, 1]], free[pairs.dofs[:, 3]]
        u[w_face] = u[w_core] - sign * rng.uniform(0.02, 0.05, size=w_face.size)
    return u


@pytest.mark.parametrize("basis", ["sublayers", "polynomial"])
def test_model_with_mixed_levels_matches_packed_and_numpy_paths(basis, mode):
    scene = sandwich_scene(length=60.0, elements=24,
                           debonds=(Debond("top", 15.0, 45.0), Debond("bottom", 0.0, 20.0)))
    levels = np.tile([1, 2, 3, 4, 4, 3, 2, 1], 3)
    model = build_model(scene, core_level=levels, core_basis=basis)
    assert sorted(g.level for g in model.core) == [1, 2, 3, 4]
    u = _contact_state(model, np.random.default_rng(3))
    results = {}
    for name, compiled, m in (("numpy", False, "auto"), ("packed", True, "never"),
                              ("auto", True, "auto")):
        model.use_kernels = compiled
        mode(m)
        model.forget_evaluations(contact_kinematics=False)
        results[name] = model.internal_force(u), model.tangent(u)
    f0, K0 = results["numpy"]
    for name in ("packed", "auto"):
        f, K = results[name]
        assert np.linalg.norm(f - f0) <= TOL * np.linalg.norm(f0), name
        assert abs(K - K0).max() <= TOL * abs(K0).max(), name
        assert K.nnz == K0.nnz
    assert abs(results["auto"][1] - results["packed"][1]).max() > 0  # the factored path ran
