"""Deformed pictures: axes in mm, a stated deformation scale, one colour range for both models.

Reference values by construction: two small frames whose stresses and displacements are known.
"""

import numpy as np
import pytest

from sandwich.compare.deformed import (
    deformation_scale,
    draw_picture,
    picture_figure,
    picture_of,
    shared_view,
)
from sandwich.results import FieldFrame


def _frame(stress_scale=1.0, sag=0.01, per_cell=True):
    x, z = np.meshgrid(np.linspace(0, 10, 6), np.linspace(-1, 1, 3))
    pts = np.column_stack([x.ravel(), z.ravel()])
    cells = np.array([[j * 6 + i, j * 6 + i + 1, (j + 1) * 6 + i + 1, (j + 1) * 6 + i]
                      for j in range(2) for i in range(5)])
    disp = np.column_stack([0 * pts[:, 0], -sag * pts[:, 0] ** 2])
    region = np.array([0] * 5 + [1] * 5)
    vm = stress_scale * np.concatenate([np.arange(5.0), 100 + np.arange(5.0)])
    if per_cell:
        return FieldFrame(3, 12.0, pts, cells, disp, {}, {"von_mises": vm, "region": region})
    return FieldFrame(3, 12.0, pts, cells, disp, {"von_mises": stress_scale * pts[:, 0]},
                      {"region": region})


def _bars(fig):
    return {ax.get_xlabel(): ax for ax in fig.axes[1:]}


def test_both_models_share_one_colour_range_per_region_and_the_scale():
    a, b = picture_of("2d", _frame(1.0)), picture_of("beam", _frame(2.0, per_cell=False))
    view = shared_view([a, b])
    # 2d core cells 0..4; beam core cells: the mean of 2x over each cell, 2(2i + 1) ≤ 18
    assert view.ranges["core"] == (0.0, 18.0)
    figs = [picture_figure(p, view) for p in (a, b)]
    for fig in figs:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "x (mm)" and ax.get_ylabel() == "z (mm)"
        assert f"deformation × {view.scale:g}" in ax.get_title()
        assert "core and faces shown" in ax.get_title()
    lims = [{label: tuple(bar.get_xlim()) for label, bar in _bars(fig).items()} for fig in figs]
    assert lims[0] == lims[1]
    assert set(lims[0]) == {"core von Mises (MPa)", "faces von Mises (MPa)"}


def test_the_faces_range_holds_the_face_stresses():
    pic = picture_of("2d", _frame(1.0))
    view = shared_view([pic])
    assert view.ranges["faces"] == (100.0, 104.0)
    assert view.ranges["core"] == (0.0, 4.0)


@pytest.mark.parametrize("sag, expected", [(0.01, 1.0), (1e-4, 50.0), (3e-4, 20.0), (1e-6, 5000.0)])
def test_small_deformations_are_magnified_by_a_round_factor(sag, expected):
    # depth 2 mm; largest displacement 100·sag mm; visible at 0.25 × depth = 0.5 mm
    assert deformation_scale([picture_of("beam", _frame(sag=sag))]) == expected


def test_draw_writes_a_png(tmp_path):
    out = draw_picture(picture_of("beam", _frame()), tmp_path / "b.png")
    assert out.is_file() and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
