"""Refinement levels, explicit sizes, degenerate geometry and the half model."""

import dataclasses

import numpy as np
import pytest

from sandwich.meshes import build_mesh
from sandwich.meshes.q9 import cell_areas
from sandwich.scene import Debond, Load, Probe, SceneError


def _with(scene, **kw):
    return dataclasses.replace(scene, **kw)


def _r2d(scene, **kw):
    return _with(scene, reference2d=dataclasses.replace(scene.reference2d, **kw))


def test_refine_quadruples_the_cells(fig5):
    n = [build_mesh(fig5, level="coarse", refine=k).n_cells for k in (0, 1, 2)]
    assert n[1] / n[0] == pytest.approx(4.0, rel=0.05)
    assert n[2] / n[1] == pytest.approx(4.0, rel=0.05)


def test_levels_grow(fig5):
    n = {lv: build_mesh(fig5, level=lv).n_cells for lv in ("coarse", "medium", "fine")}
    assert 2.5 < n["medium"] / n["coarse"] < 4.5
    assert 2.5 < n["fine"] / n["medium"] < 4.5


def test_explicit_sizes(fig5):
    coarse = _r2d(fig5, level="explicit", core_size=5.0, face_size=10.0, tip_size=1.0)
    fine = _r2d(fig5, level="explicit", core_size=2.5, face_size=5.0, tip_size=0.5)
    a, b = build_mesh(coarse), build_mesh(fine)
    assert b.n_cells > 2 * a.n_cells
    widths = np.ptp(a.points[a.cells[:, :4], 0], axis=1)
    assert widths.max() <= 10.0 + 1e-9 and widths.min() == pytest.approx(1.0, rel=1e-6)


def test_unknown_level_refused(fig5):
    with pytest.raises(ValueError, match="unknown mesh level"):
        build_mesh(fig5, level="ultra")


def test_zero_length_debond_is_bonded(fig5):
    s = _with(fig5, debonds=(Debond("top", 100.0, 100.0),))
    m = build_mesh(s, level="coarse")
    assert m.lip_pairs == {} and not any(k.startswith("debond") for k in m.groups)


def test_close_stations_are_snapped_with_a_warning(fig5):
    s = _with(fig5, probes=(*fig5.probes, Probe("near_tip", "top", 130.01)))
    with pytest.warns(UserWarning, match="near_tip"):
        m = build_mesh(s, level="coarse")
    assert m.points[m.point_nodes["probe_near_tip"], 0] == pytest.approx(130.0)
    assert np.isclose(cell_areas(m.points, m.cells).sum(), 300.0 * 26.0, rtol=1e-12)


def test_tiny_debond_refused(fig5):
    s = _with(fig5, debonds=(Debond("bottom", 100.0, 100.01),))
    with pytest.raises(SceneError, match="shorter than") as info:  # bad input: file, key
        build_mesh(s, level="coarse")
    assert [p.key for p in info.value.problems] == ["debonds[0]"]


def test_debonds_closer_than_an_element_refused(fig5):
    s = _with(fig5, debonds=(Debond("top", 100.0, 120.0), Debond("top", 120.05, 125.0)))
    with pytest.raises(SceneError, match="apart"):  # no snapping warning first
        build_mesh(s, level="coarse")


def test_point_load_is_a_node_on_the_outer_surface(fig5):
    s = _with(fig5, loads=(Load("bottom", 150.0, 0.0, -1.0),))
    m = build_mesh(s, level="coarse")
    assert m.points[m.point_nodes["load0"]] == pytest.approx([150.0, -13.0])


def test_half_model(fig5):
    m = build_mesh(_r2d(fig5, half_model=True), level="coarse")
    full = build_mesh(fig5, level="coarse")
    assert m.points[:, 0].max() == pytest.approx(150.0)
    assert m.n_cells == full.n_cells // 2
    sym = m.points[np.unique(m.facets_of("symmetry"))]
    assert np.allclose(sym[:, 0], 150.0) and np.ptp(sym[:, 1]) == pytest.approx(26.0)
    assert len(m.tip_nodes[0]) == 1  # the other tip is the mirror image
    lips = m.points[m.lip_pairs[0][:, 0]]
    assert np.isclose(lips[:, 0], 150.0).sum() == 1  # lips stay open on the symmetry plane


def test_half_model_refused_for_an_unsymmetric_scene(coarse_meshes):
    s, _ = coarse_meshes["paper-fig7-cantilever-c2"]
    with pytest.raises(ValueError, match="half model"):
        build_mesh(_r2d(s, half_model=True), level="coarse")
