"""Tangent (eqs. 24-25 + contact) = derivative of the internal force (eq. 19 + contact).

Reference: central finite differences of the internal force, at strongly deformed random states
(displacement gradients of order 0.1-0.3), per element layer and for the assembled model with
bonded and debonded interfaces and contact active. Also: f_int = ∂(strain energy)/∂u.
"""

import numpy as np
import pytest
from beam_scenes import KEVLAR, ROHACELL, Debond, assert_layer_derivatives, sandwich_scene  # noqa: I001

from sandwich.beam import build_model
from sandwich.beam.constitutive import core_stiffness, face_stiffness
from sandwich.beam.contact import pair_kinematics, penalty_response
from sandwich.beam.contact_search import contact_pairs
from sandwich.beam.dofs import global_dof
from sandwich.beam.layer_operators import build_layer_operators
from sandwich.beam.quadrature import EXACT_ORDER

LAYER_CASES = [("top", 0.5, face_stiffness(KEVLAR)), ("core", 25.0, core_stiffness(ROHACELL)),
               ("bottom", 0.5, face_stiffness(KEVLAR))]


def _random_state(rng, E, scale):
    return rng.normal(size=(E, 40)) * scale


@pytest.mark.parametrize("name,h,C", LAYER_CASES)
def test_layer_tangent_matches_finite_differences(name, h, C):
    rng = np.random.default_rng(1)
    op = build_layer_operators(name, h, 0.0, C, gauss=EXACT_ORDER[name])
    lengths = np.array([4.0, 9.0, 2.5])
    u = _random_state(rng, 3, 0.5)  # gradients u/l of order 0.1 - 0.3
    f, K = assert_layer_derivatives(op, u, lengths)
    assert np.max(np.abs(K - K.transpose(0, 2, 1))) < 1e-12 * np.max(np.abs(K))


def test_contact_gap_derivatives_match_finite_differences():
    rng = np.random.default_rng(2)
    for interface in ("top", "bottom"):
        x = np.linspace(0.0, 10.0, 6)
        pairs = contact_pairs(interface, np.arange(1, 5), x, 60.0)
        u = rng.normal(size=20 * 6) * 0.2
        k = pair_kinematics(pairs, u)
        step = 1e-6
        for j in range(6):
            du = np.zeros_like(u)
            du[pairs.dofs[:, j]] = step
            kp, km = pair_kinematics(pairs, u + du), pair_kinematics(pairs, u - du)
            assert np.allclose(k.grad[:, j], (kp.gap - km.gap) / (2 * step), rtol=1e-7, atol=1e-9)
            assert np.allclose(k.hess[:, :, j], (kp.grad - km.grad) / (2 * step), rtol=1e-6,
                               atol=1e-8)


def _debonded_model():
    scene = sandwich_scene(length=60.0, elements=12,
                           debonds=(Debond("top", 15.0, 45.0), Debond("bottom", 0.0, 20.0)))
    return build_model(scene)


def _strongly_deformed_state(model, rng, penetrate):
    """A random state with gradients ~0.1, and (optionally) each contact pair penetrating."""
    x = model.mesh.x
    u_full = np.zeros(model.dof_map.n_full)
    # a smooth large bending wave plus random noise on every DOF
    u_full += rng.normal(size=u_full.size) * 0.05
    for name in ("w_t", "w_ct", "w_cb", "w_b"):
        u_full[global_dof(np.arange(x.size), name)] += 3.0 * np.sin(np.pi * x / x[-1])
    u = model.dof_map.reduce(u_full) / np.maximum(
        1.0, np.bincount(model.dof_map.free[model.dof_map.free >= 0],
                         minlength=model.size))  # average of tied copies
    if penetrate:
        for pairs in model.pairs:
            sign = 1.0 if pairs.interface == "top" else -1.0
            free = model.dof_map.free
            u_face, w_face, u_core, w_core = (free[pairs.dofs[:, j]] for j in range(4))
            u[w_face] = u[w_core] - sign * rng.uniform(0.02, 0.05, size=w_face.size)
            u[u_face] = u[u_core] + rng.normal(size=u_face.size) * 0.005
    return u


@pytest.mark.parametrize("penetrate", [False, True])
def test_assembled_tangent_matches_finite_differences(penetrate):
    rng = np.random.default_rng(3)
    model = _debonded_model()
    u = _strongly_deformed_state(model, rng, penetrate)
    u_full = model.expand(u)
    gaps = np.concatenate([pair_kinematics(p, u_full).gap for p in model.pairs])
    assert np.min(np.abs(gaps)) > 1e-4  # no pair sits on the contact kink
    if penetrate:
        assert np.all(gaps < 0)
        assert sum(model.contact_summary(u)[p.interface].active for p in model.pairs) > 0
    K = model.tangent(u).toarray()
    step = 1e-6
    for _ in range(3):
        v = rng.normal(size=model.size)
        fd = (model.internal_force(u + step * v) - model.internal_force(u - step * v)) / (2 * step)
        assert np.linalg.norm(K @ v - fd) < 1e-6 * np.linalg.norm(fd)
    assert np.max(np.abs(K - K.T)) < 1e-10 * np.max(np.abs(K))


def test_contact_force_is_the_penalty_energy_gradient():
    rng = np.random.default_rng(4)
    x = np.linspace(0.0, 10.0, 6)
    pairs = contact_pairs("top", np.arange(1, 5), x, 60.0)
    u = rng.normal(size=20 * 6) * 0.2
    eps = 50.0

    def energy(v):
        k = pair_kinematics(pairs, v)
        return 0.5 * eps * np.sum(pairs.area * np.minimum(k.gap, 0.0) ** 2)

    f, _, _, _ = penalty_response(pairs, u, eps)
    f_full = np.bincount(pairs.dofs.ravel(), weights=f.ravel(), minlength=u.size)
    step = 1e-6
    for j in pairs.dofs.ravel():
        du = np.zeros_like(u)
        du[j] = step
        assert abs(f_full[j] - (energy(u + du) - energy(u - du)) / (2 * step)) < 1e-6 * (
            1 + np.abs(f_full).max())
