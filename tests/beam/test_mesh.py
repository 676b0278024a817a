"""The mesher along x: exact element count, stations as nodes, bounded grading (definitions)."""

from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import build_model
from sandwich.beam.mesh import build_mesh
from sandwich.scene_file import load_scene

SCENES = Path(__file__).parents[2] / "scenes"
FIG5 = dict(stations=[130, 170, 0, 300, 145, 155, 150, 150],
            centres=[130, 170, 0, 300, 145, 155])


@pytest.mark.parametrize("grading", ["graded", "uniform"])
@pytest.mark.parametrize("n", [9, 40, 41, 120, 481])
def test_element_count_is_exact_and_stations_are_nodes(grading, n):
    m = build_mesh(300.0, n, grading=grading, **FIG5)
    assert m.n_elements == n
    assert np.all(np.diff(m.x) > 0)
    for x in FIG5["stations"]:
        m.node_at(x, tol=1e-12)  # exactly a node


def test_too_few_elements_for_the_stations_is_an_error():
    with pytest.raises(ValueError, match="stretches"):
        build_mesh(300.0, 5, **FIG5)  # 6 stretches between 7 distinct stations


def test_uniform_mesh_without_stations_has_equal_elements():
    m = build_mesh(300.0, 37, grading="uniform")
    assert np.allclose(m.lengths, 300.0 / 37, rtol=1e-12)


@pytest.mark.parametrize("growth", [1.1, 1.2, 1.3])
def test_graded_mesh_growth_is_bounded_and_smallest_at_the_centres(growth):
    # Once the elements are small against the station spacing, neighbours differ by ≤ growth
    # (plus the rounding of whole elements per stretch, a few %).
    m = build_mesh(300.0, 480, growth=growth, size_ratio=12.0, **FIG5)
    l = m.lengths
    r = l[1:] / l[:-1]
    assert np.max(np.maximum(r, 1 / r)) <= growth * 1.05
    assert l.max() / l.min() == pytest.approx(12.0, rel=0.15)
    # the element next to each centre is within 15 % of the smallest
    for c in FIG5["centres"]:
        i = m.node_at(c)
        near = [l[j] for j in (i - 1, i) if 0 <= j < l.size]
        assert min(near) <= 1.15 * l.min()


def test_a_zone_is_filled_with_the_smallest_elements_and_grading_resumes_outside():
    # Definition (module docstring): d = 0 inside a zone, so h = h_min all along it.
    m = build_mesh(300.0, 480, zones=[(130.0, 170.0)], **FIG5)
    l, mid = m.lengths, 0.5 * (m.x[1:] + m.x[:-1])
    inside = l[(mid > 130) & (mid < 170)]
    assert inside.max() <= 1.05 * l.min()
    assert l.max() / l.min() == pytest.approx(12.0, rel=0.15)
    # outside, the first elements grow by about the growth factor, not a jump
    r = l[1:] / l[:-1]
    assert np.max(np.maximum(r, 1 / r)) <= 1.2 * 1.05
    # the zone takes more elements than the tips-only grading puts there
    tips = build_mesh(300.0, 480, **FIG5)
    tip_mid = 0.5 * (tips.x[1:] + tips.x[:-1])
    assert inside.size > ((tip_mid > 130) & (tip_mid < 170)).sum()


@pytest.mark.parametrize("zones", [[(170.0, 130.0)], [(-5.0, 10.0)], [(1.0, float("nan"))]])
def test_bad_zones_are_refused(zones):
    with pytest.raises(ValueError, match="zones"):
        build_mesh(300.0, 40, zones=zones, **FIG5)


def test_model_grading_zones_the_debonds_only_when_graded():
    scene = load_scene(SCENES / "paper-fig5-top-debond-40-load-top.toml")
    counts = {}
    for grading in ("graded", "tips", "uniform"):
        x = build_model(scene, elements=240, grading=grading).mesh.x
        counts[grading] = int(((x > 130) & (x < 170)).sum())
    assert counts["graded"] > counts["tips"] > counts["uniform"]
    with pytest.raises(ValueError, match="grading"):
        build_model(scene, elements=40, grading="zoned")


def test_shipped_scenes_get_exactly_the_requested_count():
    # the old mesher gave 32-46 elements for 40 asked
    for path in sorted(SCENES.glob("paper-*.toml")):
        scene = load_scene(path)
        for grading in ("graded", "tips", "uniform"):
            assert build_model(scene, elements=40, grading=grading).mesh.n_elements == 40
