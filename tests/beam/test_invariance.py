"""Rigid-body motions and Gauss orders.

References: Green-Lagrange strains vanish under any rigid motion (eq. 2), so a rigid translation
gives f_int = 0 exactly. Under a rigid rotation θ the core field u = x(cos θ − 1) − z sin θ,
w = x sin θ + z(cos θ − 1) is represented exactly (strain-free). The paper's faces have w
constant through their thickness (eq. 1b), so their γ = u,z + w,x + u,x u,z misses w,x w,z and
equals (1 − cos θ) sin θ ≈ θ³/2: f_int = O(θ³), i.e. the force ratio when θ halves is 8. With
the faces' stretch DOF (the default, ``[beam_model] faces = "stretch"``) w is linear through a
face and d = t (cos θ − 1) makes the face's rotation exact too: f_int = 0 to round-off at any θ.
Gauss orders: the energy is a polynomial whose degree fixes the exact
rule (quadrature.py); raising the order must change f_int only at round-off.
"""

import numpy as np
from beam_scenes import Debond, sandwich_scene

from sandwich.beam import build_model
from sandwich.beam.dofs import DOF_TABLE, NODE_DOFS, global_dof


def _free_model(face_stretch=False):
    # no supports: rigid motions are free; a debond adds untied nodes and contact pairs
    scene = sandwich_scene(length=40.0, elements=8, supports=(),
                           debonds=(Debond("top", 10.0, 25.0),))
    return build_model(scene, face_stretch=face_stretch)


def _rigid_state(model, translation=(0.0, 0.0), θ=0.0):
    """Full DOF vector of the rigid motion u = (c, s) + (R − I)(x, z) sampled as the DOFs mean."""
    hc = model.layers["core"].thickness
    ht, hb = model.face_thickness["top"], model.face_thickness["bottom"]
    x = model.mesh.x
    c, s = np.cos(θ), np.sin(θ)
    a, b = translation

    def u(z):
        return a + x * (c - 1) - z * s

    def w(z):
        return b + x * s + z * (c - 1)

    values = {
        "u_tt": u(hc / 2 + ht), "u_tb": u(hc / 2), "w_t": w(hc / 2), "w_t,x": s + 0 * x,
        "u_ct": u(hc / 2), "u_ct,x": (c - 1) + 0 * x, "u_ct,z": -s + 0 * x,
        "u_cb": u(-hc / 2), "u_cb,x": (c - 1) + 0 * x, "u_cb,z": -s + 0 * x,
        "w_ct": w(hc / 2), "w_ct,x": s + 0 * x, "w_ct,z": (c - 1) + 0 * x,
        "w_cb": w(-hc / 2), "w_cb,x": s + 0 * x, "w_cb,z": (c - 1) + 0 * x,
        "u_bt": u(-hc / 2), "u_bb": u(-hc / 2 - hb), "w_b": w(-hc / 2), "w_b,x": s + 0 * x,
    }
    assert set(values) == {d.name for d in DOF_TABLE}
    u_full = np.zeros(model.dof_map.n_full)
    for name, v in values.items():
        u_full[global_dof(np.arange(x.size), name)] = v
    if model.face_extra:  # d = w(outer) − w(inner) of each face: (t_top, −t_bottom)(cos θ − 1)
        extra = u_full[NODE_DOFS * x.size:].reshape(x.size, -1)
        extra[:, 0], extra[:, 1] = ht * (c - 1), -hb * (c - 1)
    return u_full


def _force(model, u_full):
    return model.dof_map.reduce(model.full_response(u_full, tangent=False)[0])


def _reference_force_scale(model, amplitude):
    # the force of a generic (strained) state of the same displacement amplitude
    rng = np.random.default_rng(0)
    return np.linalg.norm(model.internal_force(amplitude * rng.normal(size=model.size)))


def test_rigid_translation_gives_zero_internal_force():
    model = _free_model()
    f = _force(model, _rigid_state(model, translation=(3.0, -2.0)))
    assert np.linalg.norm(f) < 1e-12 * _reference_force_scale(model, 3.0)


def test_small_rigid_rotation_gives_force_of_third_order_with_the_papers_faces():
    model = _free_model(face_stretch=False)
    norms = [np.linalg.norm(_force(model, _rigid_state(model, θ=θ))) for θ in (0.02, 0.01, 0.005)]
    ratios = [norms[0] / norms[1], norms[1] / norms[2]]
    assert all(7.5 < r < 8.5 for r in ratios), ratios  # O(θ³): ratio 8
    assert norms[0] < 1e-4 * _reference_force_scale(model, 0.02 * 40.0)


def test_finite_rigid_rotation_is_strain_free_with_the_face_stretch():
    model = _free_model(face_stretch=True)
    for θ in (0.3, 1.0):
        f = _force(model, _rigid_state(model, translation=(1.0, -2.0), θ=θ))
        assert np.linalg.norm(f) < 1e-12 * _reference_force_scale(model, θ * 40.0), θ
    # without the stretch (d = 0) the rotated faces carry a spurious ε_z = sin²θ / 2
    u_full = _rigid_state(model, θ=0.3)
    u_full[NODE_DOFS * model.mesh.n_nodes:] = 0.0
    assert np.linalg.norm(_force(model, u_full)) > 1e-6 * _reference_force_scale(model, 12.0)


def test_rigid_rotation_of_core_alone_is_strain_free():
    # with the faces removed from the sum, the core's force vanishes to round-off for a
    # finite rotation (0.3 rad): the core interpolation represents rigid rotation exactly
    model = _free_model()
    from sandwich.beam.element import layer_response

    u_full = _rigid_state(model, θ=0.3)
    op = model.layers["core"]
    f, _ = layer_response(op, u_full[model.element_dofs], model.mesh.lengths, model.width,
                          tangent=False)
    scale = np.linalg.norm(layer_response(op, 0.3 * u_full[model.element_dofs] ** 2 + u_full[
        model.element_dofs], model.mesh.lengths, model.width, tangent=False)[0])
    assert np.linalg.norm(f) < 1e-12 * scale


def test_raising_gauss_orders_changes_force_and_tangent_only_at_round_off():
    scene = sandwich_scene(length=40.0, elements=8, debonds=(Debond("top", 10.0, 25.0),))
    exact = build_model(scene)
    higher = build_model(scene, gauss={"top": (7, 5), "core": (9, 9), "bottom": (7, 5)})
    lower = build_model(scene, gauss={"top": (4, 2), "core": (4, 4), "bottom": (4, 2)})
    rng = np.random.default_rng(5)
    u = rng.normal(size=exact.size) * 0.3  # strongly nonlinear state
    f0, f1 = exact.internal_force(u), higher.internal_force(u)
    K0, K1 = exact.tangent(u), higher.tangent(u)
    assert np.linalg.norm(f1 - f0) < 1e-12 * np.linalg.norm(f0)
    assert abs(K1 - K0).max() < 1e-12 * abs(K0).max()
    # the check is sensitive: a rule below the exact one visibly changes the answer
    assert np.linalg.norm(lower.internal_force(u) - f0) > 1e-6 * np.linalg.norm(f0)
