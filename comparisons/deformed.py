"""Deformed-configuration pictures, from 2D fields or from face profiles.

pyvista (off screen) from a :class:`FieldSnapshot`, or matplotlib face lines from profiles when
no model gave 2D fields.

Drawing only: the von Mises stress comes from the model; deformation is drawn at true scale.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from comparisons.snapshots import FaceLines, FieldSnapshot  # noqa: E402


def render_snapshot(snapshot: FieldSnapshot, path: Path, *, scale: float = 1.0,
                    window: tuple[int, int] = (1600, 420)) -> Path:
    """Render ``snapshot`` deformed (× ``scale``) and coloured by core von Mises into ``path``."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    xz = snapshot.points + scale * snapshot.displacement
    pts = np.column_stack([xz[:, 0], np.zeros(len(xz)), xz[:, 1]])
    k = snapshot.cells.shape[1]
    kind = pv.CellType.TRIANGLE if k == 3 else pv.CellType.QUAD
    conn = np.column_stack([np.full(len(snapshot.cells), k), snapshot.cells]).ravel()
    grid = pv.UnstructuredGrid(conn, np.full(len(snapshot.cells), kind, dtype=np.uint8), pts)
    name = "von Mises (MPa)"
    if snapshot.per_cell:
        grid.cell_data[name] = np.asarray(snapshot.von_mises, dtype=float)
    else:
        grid.point_data[name] = np.asarray(snapshot.von_mises, dtype=float)
    plotter = pv.Plotter(off_screen=True, window_size=list(window))
    plotter.set_background("white")
    if snapshot.region is not None:
        core = grid.extract_cells(np.flatnonzero(snapshot.region == 0))
        faces = grid.extract_cells(np.flatnonzero(snapshot.region != 0))
        if faces.n_cells:
            plotter.add_mesh(faces, color="gray")
        grid = core
    plotter.add_mesh(grid, scalars=name, cmap="viridis",
                     scalar_bar_args={"title": name, "color": "black"})
    plotter.add_text(f"{snapshot.model}: step {snapshot.step}, "
                     f"load factor {snapshot.load_factor:.4g}", font_size=10, color="black")
    plotter.view_xz()
    plotter.enable_parallel_projection()
    span_x = float(np.ptp(xz[:, 0])) or 1.0
    span_z = float(np.ptp(xz[:, 1])) or 1.0
    # half the visible height: fit the whole length (and height) with a 10 % margin
    plotter.camera.parallel_scale = 0.55 * max(span_x * window[1] / window[0], span_z)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def draw_face_lines(lines: Sequence[FaceLines], titles: Sequence[str], path: Path) -> Path:
    """Deformed faces of each model (one axes each), core coloured by mid-core τ (MPa).

    The core colour is the core shear at mid-core from the profiles, *not* von Mises: profiles do
    not hold the stress state through the core.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(len(lines), 1, figsize=(9.0, 2.4 * len(lines)), squeeze=False,
                             sharex=True, sharey=True)
    vmax = max((float(np.max(np.abs(fl.tau_core))) for fl in lines), default=1.0) or 1.0
    mesh = None
    for ax, fl, title in zip(axes[:, 0], lines, titles, strict=True):
        X = np.vstack([fl.x, fl.x])
        Z = np.vstack([fl.z_bottom, fl.z_top])
        C = 0.5 * (fl.tau_core[:-1] + fl.tau_core[1:])[None, :]
        mesh = ax.pcolormesh(X, Z, C, shading="flat", cmap="coolwarm", vmin=-vmax, vmax=vmax)
        ax.plot(fl.x, fl.z_top, "k-", linewidth=1.2)
        ax.plot(fl.x, fl.z_bottom, "k-", linewidth=1.2)
        ax.set_title(title, fontsize=9)
        ax.set_ylabel("z (mm)")
    axes[-1, 0].set_xlabel("x (mm)")
    if mesh is not None:
        fig.colorbar(mesh, ax=axes[:, 0].tolist(), label="core τ at mid-core (MPa)")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
