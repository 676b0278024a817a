"""Deformed pictures: child-process pyvista render and matplotlib fallback both write a PNG."""

import numpy as np

from sandwich.compare.deformed import draw_picture, picture_of, render_frame
from sandwich.results import FieldFrame


def _frame():
    x, z = np.meshgrid(np.linspace(0, 10, 6), np.linspace(-1, 1, 3))
    pts = np.column_stack([x.ravel(), z.ravel()])
    cells = np.array([[j * 6 + i, j * 6 + i + 1, (j + 1) * 6 + i + 1, (j + 1) * 6 + i]
                      for j in range(2) for i in range(5)])
    disp = np.column_stack([0 * pts[:, 0], -0.01 * pts[:, 0] ** 2])
    return FieldFrame(3, 12.0, pts, cells, disp, {},
                      {"von_mises": np.arange(10.0), "region": np.array([0] * 5 + [1] * 5)})


def test_render_frame_writes_a_png_even_with_dolfinx_loaded(tmp_path):
    try:
        import dolfinx  # noqa: F401  (the library clash this guards against)
    except ImportError:
        pass
    out = render_frame("beam", _frame(), tmp_path / "a.png")
    assert out.is_file() and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_matplotlib_fallback_writes_a_png(tmp_path):
    out = draw_picture(picture_of("beam", _frame()), tmp_path / "b.png", note="fallback; ")
    assert out.is_file() and out.stat().st_size > 1000
