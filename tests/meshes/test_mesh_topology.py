"""Layers, lips, tips, bonded interfaces, groups and cell orientation of the built meshes."""

import numpy as np
import pytest

from sandwich.meshes.layered_mesh import LAYER_TAGS
from sandwich.meshes.q9 import NODES, cell_areas, gauss_points, jacobian_determinants


def test_every_shipped_scene_meshes_at_coarse(coarse_meshes):
    assert len(coarse_meshes) >= 10
    for name, (_, m) in coarse_meshes.items():
        assert m.cells.shape[1] == 9, name
        assert 100 < m.n_cells < 5000, (name, m.n_cells)  # cheap enough for a CI 2D solve


def test_layer_areas(coarse_meshes):
    for name, (s, m) in coarse_meshes.items():
        a = cell_areas(m.points, m.cells)
        assert a.sum() == pytest.approx(s.length * s.total_height, rel=1e-12), name
        for layer in ("bottom", "core", "top"):
            key = "core" if layer == "core" else f"{layer}_face"
            got = a[m.cell_layer == LAYER_TAGS[key]].sum()
            assert got == pytest.approx(s.length * s.layer(layer).thickness, rel=1e-12), name


def test_jacobians_positive_at_nodes_and_gauss_points(coarse_meshes):
    for name, (_, m) in coarse_meshes.items():
        assert jacobian_determinants(m.points, m.cells, NODES).min() > 0, name
        assert jacobian_determinants(m.points, m.cells, gauss_points()[0]).min() > 0, name


def test_every_node_is_used_and_numbered_contiguously(coarse_meshes):
    for name, (_, m) in coarse_meshes.items():
        used = np.unique(m.cells)
        assert np.array_equal(used, np.arange(len(m.points))), name


def test_lip_nodes_have_one_partner_at_the_same_place(coarse_meshes):
    seen = 0
    for name, (s, m) in coarse_meshes.items():
        assert set(m.lip_pairs) == {i for i, d in enumerate(s.debonds) if d.length > 0}, name
        for i, pairs in m.lip_pairs.items():
            face_nodes = np.unique(m.facets_of(f"debond{i}_face_lip"))
            core_nodes = np.unique(m.facets_of(f"debond{i}_core_lip"))
            tips = list(m.tip_nodes[i])
            assert len(pairs) > 0
            assert np.all(pairs[:, 0] != pairs[:, 1])
            assert len(np.unique(pairs[:, 0])) == len(pairs)  # exactly one partner each
            assert len(np.unique(pairs[:, 1])) == len(pairs)
            assert np.array_equal(np.sort(pairs[:, 0]), np.setdiff1d(face_nodes, tips))
            assert np.array_equal(np.sort(pairs[:, 1]), np.setdiff1d(core_nodes, tips))
            assert np.array_equal(m.points[pairs[:, 0]], m.points[pairs[:, 1]])
            # face-lip nodes belong to face cells only, core-lip nodes to core cells only
            d = s.debonds[i]
            face_tag = LAYER_TAGS[f"{d.interface}_face"]
            assert set(m.cell_layer[np.isin(m.cells, pairs[:, 0]).any(axis=1)]) == {face_tag}
            assert set(m.cell_layer[np.isin(m.cells, pairs[:, 1]).any(axis=1)]) == {2}
            seen += 1
    assert seen > 20


def test_tip_nodes_are_shared_by_face_and_core_cells(coarse_meshes):
    for name, (s, m) in coarse_meshes.items():
        for i, tips in m.tip_nodes.items():
            d = s.debonds[i]
            expected = sum(0 < x < s.length for x in (d.start, d.end))
            assert len(tips) == expected, name
            for t in tips:
                layers = set(m.cell_layer[(m.cells == t).any(axis=1)])
                assert layers == {LAYER_TAGS[f"{d.interface}_face"], 2}, (name, i)


def test_no_duplicate_coordinates_outside_lips(coarse_meshes):
    """Bonded interfaces share their nodes: the only coincident nodes are lip partners."""
    for name, (_, m) in coarse_meshes.items():
        _, inverse, counts = np.unique(np.round(m.points, 9), axis=0, return_inverse=True,
                                       return_counts=True)
        dup = np.flatnonzero(counts[inverse.ravel()] > 1)
        lips = np.concatenate([p.ravel() for p in m.lip_pairs.values()] or [np.zeros(0, int)])
        assert np.array_equal(np.sort(dup), np.sort(lips)), name


def test_bonded_interface_nodes_shared_by_face_and_core(fig5, fig5_mesh):
    m, s = fig5_mesh, fig5
    hc2 = 0.5 * s.core.thickness
    for z, face in ((hc2, "top_face"), (-hc2, "bottom_face")):
        on = np.flatnonzero(np.isclose(m.points[:, 1], z))
        x = m.points[on, 0]
        itf = "top" if z > 0 else "bottom"
        bonded = on[[not any(d.start < xi < d.end for d in s.debonds_on(itf)) for xi in x]]
        assert len(bonded) > 100
        in_face = np.isin(bonded, m.cells_of(face))
        in_core = np.isin(bonded, m.cells_of("core"))
        assert in_face.all() and in_core.all()


def test_every_group_is_non_empty(coarse_meshes):
    for name, (s, m) in coarse_meshes.items():
        assert {"top_face", "core", "bottom_face"} <= set(m.groups)
        for g, (dim, tag) in m.groups.items():
            if dim == 2:
                assert np.any(m.cell_layer == tag), (name, g)
            elif dim == 1:
                assert np.any(m.facet_tag == tag), (name, g)
            else:
                assert 0 <= m.point_nodes[g] < len(m.points), (name, g)
        for i in range(len(s.supports)):
            assert f"support{i}" in m.groups
        for i in range(len(s.loads)):
            assert f"load{i}" in m.groups or f"load{i}" in m.point_nodes
        for p in s.probes:
            assert f"probe_{p.name}" in m.point_nodes


def test_support_load_and_probe_geometry(fig5, fig5_mesh):
    m, s = fig5_mesh, fig5
    hc2, h = 0.5 * s.core.thickness, s.bottom.thickness
    for i, sup in enumerate(s.supports):
        p = m.points[np.unique(m.facets_of(f"support{i}"))]
        assert np.allclose(p[:, 0], sup.x)
        assert p[:, 1].min() == pytest.approx(-hc2 - h) and p[:, 1].max() == pytest.approx(-hc2)
    lo, hi = s.loads[0].span
    p = m.points[np.unique(m.facets_of("load0"))]
    assert np.allclose(p[:, 1], hc2 + s.top.thickness)
    assert p[:, 0].min() == pytest.approx(lo) and p[:, 0].max() == pytest.approx(hi)
    probe = m.points[m.point_nodes["probe_w_top_mid"]]
    assert probe == pytest.approx([150.0, hc2 + 0.5 * s.top.thickness])


def test_debond_reaching_a_beam_end_has_an_open_mouth(coarse_meshes):
    s, m = coarse_meshes["paper-fig7-cantilever-c2"]
    assert s.debonds[0].start == 0
    assert len(m.tip_nodes[0]) == 1
    mouth = m.lip_pairs[0][np.isclose(m.points[m.lip_pairs[0][:, 0], 0], 0.0)]
    assert len(mouth) == 1 and mouth[0, 0] != mouth[0, 1]
