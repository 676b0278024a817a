"""Closest-point (node-to-segment) contact of sandwich.beam.contact_projection (issue #3).

References, test by test:

- the core boundary curve is rebuilt here from the element's own x shape functions
  (``sandwich.beam.shape_functions.x_shape``, eq. 11a), not from ``hermite_basis``;
- known closest points: a face node is put at X(s) + g n(s), n the curve's deformed outward normal
  at a chosen material point s; r = g n is normal to the curve there, so the exact gap is g and
  the exact (material) sliding s − x_i;
- derivatives: central finite differences of the code's own gap, force and energy;
- zero sliding: the same-x gap (eq. 42, its derivatives are checked in test_beam_tangent.py);
- a real scene (fig. 5): the issue's bound, penetration ≤ 1e-3 × face thickness;
- width groups (``contact_pair_groups``): the same pairs in one rectangular group.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import build_model, run
from sandwich.beam.contact import block_rows, pair_kinematics, penalty_response
from sandwich.beam.contact_law import contact_energy
from sandwich.beam.contact_projection import (
    closest_point_kernel,
    closest_point_kinematics,
    closest_point_kinematics_numpy,
    hermite_basis,
)
from sandwich.beam.contact_search import (
    MAX_WINDOW,
    NORMAL_SIGN,
    contact_pair_groups,
    contact_pairs,
    facing_nodes,
    located,
)
from sandwich.beam.dofs import CONTACT_DOFS, NODE_DOFS, global_dof
from sandwich.beam.shape_functions import x_shape
from sandwich.scene_file import load_scene

EPS = 2.24e4  # N/mm³, the default penalty for the paper's Rohacell core
S = 1e-6  # mm, the default regularisation width for 0.5 mm faces
X = np.array([0.0, 2.0, 3.0, 4.5, 5.0, 6.5, 8.0, 10.0])  # graded-like, unequal elements
NODES = np.arange(1, 7)  # untied nodes: all but the ends
FIG5 = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _core_fields(theta, amp, L=X[-1]):
    """Core boundary (u, u', w, w'): a rigid rotation θ about x = 0 plus a smooth wave."""

    def fields(x):
        k = np.pi / L
        u = (np.cos(theta) - 1.0) * x + 0.3 * amp * np.cos(2 * k * x)
        ux = (np.cos(theta) - 1.0) - 0.6 * amp * k * np.sin(2 * k * x)
        w = np.sin(theta) * x + amp * np.sin(k * x)
        wx = np.sin(theta) + amp * k * np.cos(k * x)
        return u, ux, w, wx

    return fields


def _curve(x_nodes, nodal, s):
    """Deformed core boundary at material point s from the element's x_shape (eq. 11a).

    ``nodal`` is (n, 4): u, u_x, w, w_x per node. Returns the point (x + u, w) and the tangent
    (1 + u_x, w_x).
    """
    e = int(np.clip(np.searchsorted(x_nodes, s, side="right") - 1, 0, x_nodes.size - 2))
    l = x_nodes[e + 1] - x_nodes[e]
    η = 2.0 * (s - x_nodes[e]) / l - 1.0
    val = np.zeros(2)
    der = np.zeros(2)
    for a in (0, 1):
        H, dH = x_shape("H", a, η)
        B, dB = x_shape("Hbar", a, η)
        u, ux, w, wx = nodal[e + a]
        val += [H * u + 0.5 * l * B * ux, H * w + 0.5 * l * B * wx]
        der += (2.0 / l) * np.array([dH * u + 0.5 * l * dB * ux, dH * w + 0.5 * l * dB * wx])
    return np.array([s + val[0], val[1]]), np.array([1.0 + der[0], der[1]])


def _state(interface, slide, gap, theta=0.3, amp=0.4, x=X, nodes=NODES):
    """Full DOF vector: core boundary from _core_fields, face node i at X(x_i + d_i) + g_i n."""
    u = np.zeros(NODE_DOFS * x.size)
    names = CONTACT_DOFS[interface]
    nodal = np.stack(_core_fields(theta, amp, x[-1])(x), axis=-1)
    for role, j in (("u_core", 0), ("u_core,x", 1), ("w_core", 2), ("w_core,x", 3)):
        u[global_dof(np.arange(x.size), names[role])] = nodal[:, j]
    s_n = NORMAL_SIGN[interface]
    for i, d, g in zip(nodes, slide, gap, strict=True):
        point, t = _curve(x, nodal, x[i] + d)
        n = s_n * np.array([-t[1], t[0]]) / np.hypot(*t)
        face = point + g * n
        u[global_dof(i, names["u_face"])] = face[0] - x[i]
        u[global_dof(i, names["w_face"])] = face[1]
    return u


def _global(pairs, m, local, u):
    """A pair's block vector (n,) or matrix (n, n) at state ``u`` on the full DOFs (repeated
    DOFs summed): the block of the window located at ``u``."""
    d = block_rows(pairs, u)[m]
    n = NODE_DOFS * X.size
    if local.ndim == 1:
        return np.bincount(d, weights=local, minlength=n)
    out = np.zeros((n, n))
    np.add.at(out, (d[:, None], d[None, :]), local)
    return out


def _pairs(interface, reach=2.0):
    return contact_pairs(interface, NODES, X, 60.0, search="closest-point", reach=reach)


def test_hermite_basis_is_the_element_x_interpolation():
    l = 1.7
    ξ = np.linspace(0.0, 1.0, 7)
    η = 2 * ξ - 1
    N = hermite_basis(ξ, np.full_like(ξ, l))
    ref = [x_shape("H", 0, η), x_shape("Hbar", 0, η), x_shape("H", 1, η), x_shape("Hbar", 1, η)]
    scale = [1.0, l / 2, 1.0, l / 2]  # the slope functions multiply (l/2) u,x (reference length 2)
    for k in range(4):
        assert np.allclose(N[0][:, k], scale[k] * ref[k][0], atol=1e-14)
        assert np.allclose(N[1][:, k], 2 * scale[k] * ref[k][1], atol=1e-14)  # d/dξ = 2 d/dη
    # second and third derivatives: central differences of the first
    h = 1e-6
    Np, Nm = hermite_basis(ξ + h, np.full_like(ξ, l)), hermite_basis(ξ - h, np.full_like(ξ, l))
    assert np.allclose(N[2], (Np[1] - Nm[1]) / (2 * h), atol=1e-7)
    assert np.allclose(N[3], (Np[2] - Nm[2]) / (2 * h), atol=1e-7)


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_known_closest_point_including_crossing_into_next_segments(interface):
    # slides as fractions of the local elements; node 3 (x = 4.5) slides past node 4 (x = 5)
    # into the segment [5, 6.5], node 4 back past node 3 into [3, 4.5]
    slide = np.array([0.6, -0.45, 0.8, -0.9, 0.0, 1.3])
    gap = np.array([-2e-3, -1e-4, -3e-2, 5e-3, -1e-3, -1e-2])
    pairs = _pairs(interface)
    u = _state(interface, slide, gap)
    k = pair_kinematics(pairs, u)
    assert not k.outside.any()
    assert np.allclose(k.gap, gap, rtol=0, atol=1e-12)
    assert np.allclose(k.sliding, slide, rtol=0, atol=1e-11)
    # the chosen segment holds the material point x_i + d_i
    seg_nodes = located(pairs, u).core_nodes[np.arange(pairs.size), k.segment]
    left = X[seg_nodes]
    target = X[NODES] + slide
    assert np.all((left <= target + 1e-12) & (target <= X[seg_nodes + 1] + 1e-12))
    assert np.allclose(left + k.xi * (X[seg_nodes + 1] - left), target, atol=1e-11)
    # crossings: node 3 ends in [5, 6.5] (two segments to the right), node 4 in [3, 4.5]
    assert list(X[seg_nodes[2:4]]) == [5.0, 3.0]


def test_gap_and_force_continuous_when_the_projection_crosses_a_node():
    # node 2 (x = 3) slides through node 3 (x = 4.5): the segment switches at d = 1.5
    pairs = _pairs("top")
    forces, segs = [], []
    for d in (1.5 - 1e-9, 1.5 + 1e-9):
        slide = np.array([0.0, d, 0.0, 0.0, 0.0, 0.0])
        u = _state("top", slide, np.full(6, -1e-3))
        f, _, _, k = penalty_response(pairs, u, EPS, S)
        forces.append(_global(pairs, 1, f[1], u))
        segs.append(int(located(pairs, u).core_nodes[1, k.segment[1]]))
    assert segs == [2, 3]  # [3, 4.5] then [4.5, 5]
    assert np.linalg.norm(forces[1] - forces[0]) < 1e-6 * np.linalg.norm(forces[0])


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_zero_sliding_gives_the_same_x_gap(interface):
    gap = np.array([-2e-3, -1e-4, 3e-2, -5e-3, -1e-3, 0.2])
    u = _state(interface, np.zeros(6), gap, theta=-0.2, amp=0.7)
    closest, same_x = _pairs(interface), contact_pairs(interface, NODES, X, 60.0)
    kc, ks = pair_kinematics(closest, u), pair_kinematics(same_x, u)
    assert np.allclose(ks.gap, gap, atol=1e-12)  # the construction, seen by the same-x gap
    assert np.allclose(kc.gap, ks.gap, rtol=0, atol=1e-13)
    assert np.allclose(kc.sliding, 0.0, atol=1e-12) and np.allclose(ks.sliding, 0.0, atol=1e-12)
    for m in range(closest.size):
        gc = _global(closest, m, kc.grad[m], u)
        gs = np.bincount(same_x.dofs[m], weights=ks.grad[m], minlength=u.size)
        assert np.allclose(gc, gs, rtol=0, atol=1e-12)


def _fixed_point_gap(interface, u, i, s):
    """Gap to the curve point at fixed material coordinate s (no projection): for contrast."""
    names = CONTACT_DOFS[interface]
    nodal = np.stack([u[global_dof(np.arange(X.size), names[r])]
                      for r in ("u_core", "u_core,x", "w_core", "w_core,x")], axis=-1)
    point, t = _curve(X, nodal, s)
    face = np.array([X[i] + u[global_dof(i, names["u_face"])], u[global_dof(i, names["w_face"])]])
    n = NORMAL_SIGN[interface] * np.array([-t[1], t[0]]) / np.hypot(*t)
    return n @ (face - point)


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_consistent_tangent_with_sliding_and_rotation(interface):
    # rotation 0.3 rad, a bending wave, slides 0.3-0.45 of an element (both directions, one past
    # a node), penetrations deep enough that the geometric term p A ∂²g matters
    slide = np.array([0.7, -0.35, 0.6, -0.2, 0.5, -0.6])
    gap = np.array([-2e-2, -1e-2, -3e-2, -1.5e-2, -2.5e-2, -1e-2])
    pairs = _pairs(interface)
    u = _state(interface, slide, gap)
    f, K, p, k = penalty_response(pairs, u, EPS, S)
    assert np.all(p > 0) and not k.outside.any()
    h = 1e-6
    for m in range(pairs.size):
        dofs = np.unique(block_rows(pairs, u)[m])
        G, H = _global(pairs, m, k.grad[m], u), _global(pairs, m, k.hess[m], u)
        F, KK = _global(pairs, m, f[m], u), _global(pairs, m, K[m], u)
        fd_g, fd_G, fd_F, fd_W = (np.zeros(u.size), np.zeros((u.size, u.size)),
                                  np.zeros((u.size, u.size)), np.zeros(u.size))
        for j in dofs:
            du = np.zeros_like(u)
            du[j] = h
            fp, _, _, kp = penalty_response(pairs, u + du, EPS, S)
            fm, _, _, km = penalty_response(pairs, u - du, EPS, S)
            fd_g[j] = (kp.gap[m] - km.gap[m]) / (2 * h)
            fd_G[:, j] = (_global(pairs, m, kp.grad[m], u + du)
                          - _global(pairs, m, km.grad[m], u - du)) / (2 * h)
            fd_F[:, j] = (_global(pairs, m, fp[m], u + du)
                          - _global(pairs, m, fm[m], u - du)) / (2 * h)
            fd_W[j] = pairs.area[m] * (contact_energy(kp.gap[m], EPS, S)
                                       - contact_energy(km.gap[m], EPS, S)) / (2 * h)
        assert np.allclose(G, fd_g, rtol=0, atol=1e-8 * np.abs(G).max())
        assert np.allclose(H, fd_G, rtol=0, atol=1e-6 * np.abs(H).max())
        assert np.allclose(F, fd_W, rtol=0, atol=1e-6 * np.abs(F).max())  # f = ∂W/∂u
        assert np.allclose(KK, fd_F, rtol=0, atol=1e-6 * np.abs(KK).max())
        assert np.max(np.abs(KK - KK.T)) < 1e-10 * np.abs(KK).max()
        # contrast: the Hessian of the gap at a frozen curve point differs by far more than the
        # tolerance above, so the check sees the dependence of ξ on the displacements
        i, s = NODES[m], X[NODES[m]] + k.sliding[m]
        sub = dofs
        Hf = np.zeros((sub.size, sub.size))
        hh = 1e-4
        for a, ja in enumerate(sub):
            for b, jb in enumerate(sub):
                e_a, e_b = np.zeros_like(u), np.zeros_like(u)
                e_a[ja], e_b[jb] = hh, hh
                Hf[a, b] = (_fixed_point_gap(interface, u + e_a + e_b, i, s)
                            - _fixed_point_gap(interface, u + e_a - e_b, i, s)
                            - _fixed_point_gap(interface, u - e_a + e_b, i, s)
                            + _fixed_point_gap(interface, u - e_a - e_b, i, s)) / (4 * hh**2)
        assert np.abs(Hf - H[np.ix_(sub, sub)]).max() > 1e-3 * np.abs(H).max()


def test_contact_search_option_and_its_validation():
    scene = load_scene(FIG5)
    closest = build_model(scene, elements=40)  # the default since 2026-12-02 (scene key)
    same = build_model(scene, elements=40, contact_search="same-x")
    assert [p.search for p in same.pairs] == ["same-x"]
    assert [p.search for p in closest.pairs] == ["closest-point"]
    assert np.array_equal(same.pairs[0].nodes, closest.pairs[0].nodes)
    assert same.pairs[0].block_dofs.shape[1] == 6
    with pytest.raises(ValueError, match="contact search"):
        build_model(scene, elements=40, contact_search="nearest")


def test_fig5_converged_states_respect_the_penetration_bound():
    scene = load_scene(FIG5)
    scene = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                    until_value=-4.0))
    result = run(scene, elements=60,
                 model_options={"contact_search": "closest-point", "core_level": 1})
    model = result.model
    assert result.solution.converged, result.solution.message
    assert [p.search for p in model.pairs] == ["closest-point"]
    bound = model.penetration_bound()
    assert bound == pytest.approx(5e-4)  # 1e-3 × 0.5 mm faces
    summaries = [model.contact_summary(s.u)["top"] for s in result.states[1:]]
    assert max(c.max_penetration for c in summaries) <= bound
    assert summaries[-1].active > 0 and summaries[-1].max_sliding > 0
    assert all(c.outside_reach == 0 for c in summaries)
    k = pair_kinematics(model.pairs[0], model.expand(result.states[-1].u))
    assert not k.outside.any()


def test_consistent_tangent_with_sliding_inside_the_smoothing_band():
    # gaps where the regularised stiffness changes most (g ≈ −c s, contact_law tests the law);
    # the pairs slide 0.2-0.7 of an element, so the projection moves with the step as well
    slide = np.array([0.7, -0.35, 0.6, -0.2, 0.5, -0.6])
    gap = -25.0 * S * np.array([0.6, 0.9, 1.0, 1.1, 1.2, 1.4])
    pairs = _pairs("top")
    u = _state("top", slide, gap)
    f, K, _, k = penalty_response(pairs, u, EPS, S)
    assert np.allclose(k.gap, gap, rtol=0, atol=1e-12)
    # step 1e-3 s: the positions here are ~3 mm (rotation), so the gap carries a round-off of
    # ~1e-15 mm and smaller steps lose digits (1e-4 s: 4e-6 of max|K|); the law varies over ~s
    h = 1e-3 * S
    for m in range(pairs.size):
        dofs = np.unique(block_rows(pairs, u)[m])
        KK = _global(pairs, m, K[m], u)
        for j in dofs:
            du = np.zeros_like(u)
            du[j] = h
            fd = (_global(pairs, m, penalty_response(pairs, u + du, EPS, S)[0][m], u + du)
                  - _global(pairs, m, penalty_response(pairs, u - du, EPS, S)[0][m], u - du)
                  ) / (2 * h)
            assert np.allclose(KK[:, j], fd, rtol=1e-5, atol=1e-6 * np.abs(KK).max())


def test_groups_by_search_width_give_the_ungrouped_force_and_tangent():
    # graded nodes (0.2 - 3 mm): with a 1 mm reach the search half-width varies from 1 to 5
    # segments, so contact_pair_groups makes groups of two widths; reference: one rectangular group
    x = np.concatenate([[0.0], np.cumsum([3, 2, 1, 0.5, 0.3, 0.2, 0.2, 0.3, 0.5, 1, 2, 3.0])])
    nodes = np.arange(1, x.size - 1)
    rng = np.random.default_rng(5)
    slide = rng.uniform(-0.15, 0.15, nodes.size)
    gap = -rng.uniform(1e-4, 1e-2, nodes.size)
    u = _state("bottom", slide, gap, x=x, nodes=nodes)
    groups = contact_pair_groups("bottom", nodes, x, 60.0, search="closest-point", reach=1.0)
    single = contact_pairs("bottom", nodes, x, 60.0, search="closest-point", reach=1.0)
    assert len(groups) >= 2
    assert sorted(np.concatenate([g.nodes for g in groups])) == list(nodes)
    assert max(g.block_dofs.shape[1] for g in groups) == single.block_dofs.shape[1]
    n = u.size

    def assemble(pair_list):
        F, K, gaps = np.zeros(n), np.zeros((n, n)), {}
        for p in pair_list:
            f, k_blocks, _, kin = penalty_response(p, u, EPS, S)
            d = block_rows(p, u)
            np.add.at(F, d, f)
            np.add.at(K, (d[:, :, None], d[:, None, :]), k_blocks)
            gaps.update(zip(p.nodes.tolist(), kin.gap, strict=True))
        return F, K, gaps

    F1, K1, g1 = assemble(groups)
    F2, K2, g2 = assemble([single])
    assert g1 == pytest.approx(g2, abs=1e-15) and np.allclose(list(g2.values()), gap, atol=1e-12)
    assert np.allclose(F1, F2, rtol=0, atol=1e-12 * np.abs(F2).max())
    assert np.allclose(K1, K2, rtol=0, atol=1e-12 * np.abs(K2).max())


@pytest.mark.parametrize("reach", [0.0, 0.4, 1.0, 2.5])
def test_groups_hold_each_node_at_its_own_search_width(reach):
    """Each node lands in the group of its own half-width (the single-node search of
    contact_pairs), rounded up to a power of two; every node once; mesh ends included."""
    x = np.concatenate([[0.0], np.cumsum([3, 2, 1, 0.5, 0.3, 0.2, 0.2, 0.3, 0.5, 1, 2, 3.0])])
    nodes = np.arange(x.size)
    groups = contact_pair_groups("top", nodes, x, 60.0, search="closest-point", reach=reach)
    assert sorted(np.concatenate([g.nodes for g in groups]).tolist()) == nodes.tolist()
    for g in groups:
        for node in g.nodes:
            own = contact_pairs("top", np.array([node]), x, 60.0, search="closest-point",
                                reach=reach).core_nodes.shape[1] // 2
            assert g.core_nodes.shape[1] // 2 <= 2 ** int(np.ceil(np.log2(own)))
        widths = [contact_pairs("top", np.array([m]), x, 60.0, search="closest-point",
                                reach=reach).core_nodes.shape[1] // 2 for m in g.nodes]
        assert len({2 ** int(np.ceil(np.log2(w))) for w in widths}) == 1


# A uniform mesh of 0.25 mm elements: a 1 mm reach spans four segments on each side of a node,
# and a sliding of 2 mm takes the projection well beyond them (fig. 7 c3 at 240 elements: the
# core's bottom boundary slides ~1.3 mm along the debonded face at the clamp).
XU = np.linspace(0.0, 12.0, 49)
NODE_U = 24  # x = 6: searches the core over [5, 7]


def _sliding_state(interface, d, gap):
    """Node NODE_U at X(x_i + d) + gap n on a rotated, wavy core; the other nodes untouched."""
    nodes = np.arange(1, XU.size - 1)
    slide, gaps = np.zeros(nodes.size), np.full(nodes.size, 0.1)
    slide[NODE_U - 1], gaps[NODE_U - 1] = d, gap
    return _state(interface, slide, gaps, x=XU, nodes=nodes)


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_the_search_window_follows_the_sliding(interface):
    # a face node slid ±2 mm along a rotated, wavy core: eight segments each way, twice its
    # 1 mm reach at rest. Reference: the construction (the node at X(x_i + d) + g0 n: gap g0,
    # sliding d exactly). The window is centred on the node faced, so no pair is ever outside
    pairs = contact_pairs(interface, np.array([NODE_U]), XU, 60.0, search="closest-point",
                          reach=1.0)
    g0 = -1e-3
    ds = np.linspace(-2.0, 2.0, 801)  # steps of 5e-3 mm
    states = [_sliding_state(interface, d, g0) for d in ds]
    ks = [pair_kinematics(pairs, u) for u in states]
    assert not any(bool(k.outside[0]) for k in ks)
    np.testing.assert_allclose([k.gap[0] for k in ks], g0, rtol=0, atol=1e-12)
    np.testing.assert_allclose([k.sliding[0] for k in ks], ds, rtol=0, atol=1e-11)
    faced = np.array([int(facing_nodes(pairs, u)[0]) for u in states])
    assert faced.min() <= NODE_U - 8 and faced.max() >= NODE_U + 8  # the window moved
    # where the window moves the gradient on the full DOFs does not notice (central
    # differences of the gap at the switch: the same gradient)
    moves = np.flatnonzero(np.diff(faced))
    n = NODE_DOFS * XU.size
    for i in moves[:3]:
        grads = []
        for d in (ds[i], ds[i + 1]):
            u = _sliding_state(interface, d, g0)
            k = pair_kinematics(pairs, u)
            grads.append(np.bincount(block_rows(pairs, u)[0], weights=k.grad[0], minlength=n))
        assert np.linalg.norm(grads[1] - grads[0]) < 0.05 * np.linalg.norm(grads[0])


def _held(pairs, u):
    """Kinematics on the windows as they are (not located): the fallback beyond them."""
    return closest_point_kinematics(pairs, u)


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_gap_continuous_when_the_projection_leaves_the_searched_segments(interface):
    # the fallback of a projection beyond its window (a mesh end, or farther than the reach
    # from the node faced), on the windows at rest. Regression: the old fallback extrapolated
    # the "least outside" segment, whose Newton stalled at ξ = 1.5 on several segments alike;
    # the pick among them flipped with round-off and the gap jumped (c3, 240 elements:
    # 0.052 → −0.011 mm, ‖f_int‖ by 2e5 N)
    pairs = contact_pairs(interface, np.array([NODE_U]), XU, 60.0, search="closest-point",
                          reach=1.0)
    g0 = -1e-3
    ds = np.linspace(-2.0, 2.0, 801)  # steps of 5e-3 mm
    ks = [_held(pairs, _sliding_state(interface, d, g0)) for d in ds]
    gaps = np.array([k.gap[0] for k in ks])
    outside = np.array([bool(k.outside[0]) for k in ks])
    within = np.abs(ds) < 1.0 - 1e-9
    assert not outside[within].any() and outside[np.abs(ds) > 1.0 + 1e-9].all()
    assert np.allclose(gaps[within], g0, rtol=0, atol=1e-12)  # exact while searched
    # continuous: beyond the window the gap is the distance to the tangent line at its end,
    # which departs from g0 with the core's curvature (slope ≤ 0.03 here; the old fallback
    # jumped by 0.055 mm at d = 1.125)
    assert np.max(np.abs(np.diff(gaps))) < 0.1 * (ds[1] - ds[0])
    # and C¹ at the exit: the gradient on either side of |d| = reach agrees
    for edge in (-1.0, 1.0):
        grads = []
        for d in (edge - 1e-7, edge + 1e-7):
            k = _held(pairs, _sliding_state(interface, d, g0))
            grads.append(np.bincount(k.dofs[0], weights=k.grad[0],
                                     minlength=NODE_DOFS * XU.size))
        assert np.linalg.norm(grads[1] - grads[0]) < 1e-5 * np.linalg.norm(grads[0])


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_consistent_gap_derivatives_beyond_the_searched_segments(interface):
    # the held fallback's gradient and Hessian (ξ fixed at the window's end) against central
    # differences of its own gap
    pairs = contact_pairs(interface, np.array([NODE_U]), XU, 60.0, search="closest-point",
                          reach=1.0)
    u = _sliding_state(interface, 1.4, -2e-2)
    k = _held(pairs, u)
    assert k.outside[0]
    d = k.dofs[0]
    n = NODE_DOFS * XU.size
    G = np.bincount(d, weights=k.grad[0], minlength=n)
    H = np.zeros((n, n))
    np.add.at(H, (d[:, None], d[None, :]), k.hess[0])
    h = 1e-6
    for j in np.unique(d):
        du = np.zeros_like(u)
        du[j] = h
        kp, km = _held(pairs, u + du), _held(pairs, u - du)
        assert (kp.gap[0] - km.gap[0]) / (2 * h) == pytest.approx(G[j], abs=1e-8 * np.abs(G).max())
        fd = (np.bincount(kp.dofs[0], weights=kp.grad[0], minlength=n)
              - np.bincount(km.dofs[0], weights=km.grad[0], minlength=n)) / (2 * h)
        assert np.allclose(H[:, j], fd, rtol=0, atol=1e-6 * np.abs(H).max())


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_compiled_kinematics_match_the_numpy_reference(interface):
    """sandwich.beam.contact_kernel against closest_point_kinematics_numpy (the equations
    written array-wise): rotated wavy core, slidings inside and beyond the reach, open and
    closed pairs; the same segment, ξ and outside flags, gap and derivatives to round-off."""
    if closest_point_kernel() is None:
        pytest.skip("numba not installed: the NumPy path is the only one")
    rng = np.random.default_rng(11)
    nodes = np.arange(1, XU.size - 1)
    pairs = contact_pairs(interface, nodes, XU, 60.0, search="closest-point", reach=1.0)
    for trial in range(4):
        slide = rng.uniform(-1.5, 1.5, nodes.size) * (0.3 + trial / 3)
        gaps = rng.uniform(-0.05, 0.05, nodes.size)
        u = _state(interface, slide, gaps, theta=0.1 * trial, x=XU, nodes=nodes)
        a = closest_point_kinematics(pairs, u)
        b = closest_point_kinematics_numpy(pairs, u)
        assert b.outside.any() or trial < 2
        np.testing.assert_array_equal(a.segment, b.segment)
        np.testing.assert_array_equal(a.outside, b.outside)
        np.testing.assert_array_equal(a.cols, b.cols)
        np.testing.assert_allclose(a.xi, b.xi, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.gap, b.gap, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.sliding, b.sliding, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.grad, b.grad, rtol=0, atol=1e-10 * np.abs(b.grad).max())
        np.testing.assert_allclose(a.hess, b.hess, rtol=0, atol=1e-9 * np.abs(b.hess).max())


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_compiled_search_breaks_ties_as_the_exhaustive_one(interface):
    """The kernel searches the segments nearest box first and stops at the first box farther
    than its best projection; the NumPy path projects on every segment and takes the argmin.
    Face nodes straight above (below) the core nodes of a flat core project exactly onto the
    shared node of two segments (ξ = 1 on the left one, ξ = 0 on the right one, the same
    distance): both must pick the left (lower) segment, for open pairs at several heights and
    for a face slid by whole elements onto other nodes."""
    if closest_point_kernel() is None:
        pytest.skip("numba not installed: the NumPy path is the only one")
    nodes = np.arange(1, XU.size - 1)
    pairs = contact_pairs(interface, nodes, XU, 60.0, search="closest-point", reach=1.0)
    names = CONTACT_DOFS[interface]
    side = 1.0 if interface == "top" else -1.0
    for shift, lift in ((0, 0.3), (0, 1e-3), (2, 0.05)):
        u = np.zeros(NODE_DOFS * XU.size)
        target = np.clip(nodes + shift, 0, XU.size - 1)  # onto another core node
        u[global_dof(nodes, names["u_face"])] = XU[target] - XU[nodes]
        u[global_dof(nodes, names["w_face"])] = side * lift
        a = closest_point_kinematics(pairs, u)
        b = closest_point_kinematics_numpy(pairs, u)
        inner = (target > 0) & (target < XU.size - 1)
        assert np.all(np.isin(a.xi[inner], (0.0, 1.0)))  # on a shared node: a tie
        np.testing.assert_array_equal(a.segment, b.segment)
        np.testing.assert_array_equal(a.xi, b.xi)
        assert np.all(a.xi[inner] == 1.0)  # the left segment's end: the lower one won
        np.testing.assert_allclose(a.gap, side * 0 + lift, rtol=1e-12)


def test_the_window_is_bounded_in_segments_on_fine_meshes():
    # 0.01 mm elements: the 1 mm reach spans 100 segments, the window MAX_WINDOW on each side
    x = np.linspace(0.0, 10.0, 1001)
    nodes = np.arange(1, x.size - 1)
    pairs = contact_pairs("top", nodes, x, 60.0, search="closest-point", reach=1.0)
    assert pairs.core_nodes.shape[1] == 2 * MAX_WINDOW + 1
    assert pairs.support_dofs.shape[1] == 2 + 4 * (2 * MAX_WINDOW + 1)


def test_c3_cantilever_slides_beyond_the_reach_with_every_pair_in_its_window():
    # fig. 7 c3 to -40 mm at level 1: the core slides > 3 mm along the debonded face at the
    # clamp (three times the 1 mm reach at rest); the window follows, so no pair in contact is
    # held outside it (reference: the property itself, and the sliding the run reports)
    scene = load_scene(FIG5.with_name("paper-fig7-cantilever-c3.toml"))
    scene = dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model, core=1))
    out = run(scene)
    assert out.solution.converged
    sliding = max(h.extra.get("max_sliding", 0.0) for h in out.solution.history)
    assert sliding > 3.0
    summary = out.model.contact_summary(out.states[-1].u)
    assert sum(c.outside_reach for c in summary.values()) == 0


@pytest.mark.parametrize("interface", ["top", "bottom"])
def test_patch_a_face_sliding_several_segments_transmits_its_pressure_exactly(interface):
    # patch test: a flat, rotated (rigid) core; every face node of a stretch slid by 3.3
    # segments along it and pressed in by the same depth. Reference (closed form): each pair
    # carries the law's pressure p(g0) on its tributary area, normal to the core; the face gets
    # Σ p A along the normal, the core the opposite (equilibrium), nothing tangential
    # (frictionless), at every slide across the segments
    theta = 0.2
    nodes = np.arange(12, 37)
    g0 = -30.0 * S
    p0 = contact_energy(np.array([g0 - 1e-9, g0 + 1e-9]), EPS, S)
    p0 = -(p0[1] - p0[0]) / 2e-9  # the law's pressure at g0: −dW/dg
    pairs = contact_pairs(interface, nodes, XU, 60.0, search="closest-point", reach=1.0)
    names = CONTACT_DOFS[interface]
    s_n = NORMAL_SIGN[interface]
    t = np.array([np.cos(theta), np.sin(theta)])
    n = s_n * np.array([-t[1], t[0]])
    for slide in (3.3 * 0.25, 3.3 * 0.25 + 0.11, -2.6 * 0.25):
        u = _state(interface, np.full(nodes.size, slide), np.full(nodes.size, g0), theta=theta,
                   amp=0.0, x=XU, nodes=nodes)
        f, _, p, k = penalty_response(pairs, u, EPS, S)
        assert not k.outside.any()
        np.testing.assert_allclose(k.sliding, slide, rtol=0, atol=1e-12)
        np.testing.assert_allclose(p, p0, rtol=1e-9)
        F = np.zeros(u.size)
        np.add.at(F, block_rows(pairs, u), f)
        face = np.array([F[global_dof(nodes, names["u_face"])],
                         F[global_dof(nodes, names["w_face"])]])  # (2, m)
        total = p0 * pairs.area.sum()
        np.testing.assert_allclose(face.T @ n, -p0 * pairs.area, rtol=1e-9)  # pushed out
        np.testing.assert_allclose(face.T @ t, 0.0, atol=1e-9 * total)  # frictionless
        core = np.array([F[global_dof(np.arange(XU.size), names["u_core"])].sum(),
                         F[global_dof(np.arange(XU.size), names["w_core"])].sum()])
        np.testing.assert_allclose(core, -face.sum(axis=1), rtol=1e-9, atol=1e-9 * total)
