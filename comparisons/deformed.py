"""Deformed-configuration pictures, from 2D fields or from face profiles.

pyvista (off screen) from a :class:`FieldSnapshot`, or matplotlib face lines from profiles when
no model gave 2D fields.

Drawing only: the von Mises stress comes from the model; deformation is drawn at true scale.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from comparisons.snapshots import FaceLines, FieldSnapshot, save_snapshot  # noqa: E402


def render_snapshot(snapshot: FieldSnapshot, path: Path, *, scale: float = 1.0) -> Path:
    """Render ``snapshot`` deformed (× ``scale``), coloured by core von Mises, into ``path``.

    pyvista renders in a child process: VTK's wheel and the FEniCSx stack loaded in one process
    have been seen to abort inside VTK (a C++ library clash). If the child fails, the picture is
    drawn with matplotlib instead, and the title says so.
    """
    with tempfile.TemporaryDirectory() as tmp:
        npz = save_snapshot(snapshot, Path(tmp))
        cmd = [sys.executable, "-m", "comparisons.render_worker", str(npz), str(path),
               snapshot.model, repr(scale)]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
            ok = done.returncode == 0 and Path(path).is_file()
        except (OSError, subprocess.TimeoutExpired):
            ok = False
    return path if ok else draw_snapshot(snapshot, path, scale=scale, note="pyvista failed; ")


def draw_snapshot(snapshot: FieldSnapshot, path: Path, *, scale: float = 1.0,
                  note: str = "") -> Path:
    """Matplotlib picture of the deformed section, core cells coloured by von Mises."""
    from matplotlib.collections import PolyCollection

    xz = snapshot.points + scale * snapshot.displacement
    vm = np.asarray(snapshot.von_mises, dtype=float)
    if not snapshot.per_cell:
        vm = vm[snapshot.cells].mean(axis=1)
    region = snapshot.region if snapshot.region is not None else np.zeros(len(vm), dtype=int)
    fig, ax = plt.subplots(figsize=(14, 3.6))
    core = region == 0
    polys = PolyCollection(xz[snapshot.cells[core]], array=vm[core], cmap="viridis",
                           edgecolors="none")
    ax.add_collection(polys)
    ax.add_collection(PolyCollection(xz[snapshot.cells[~core]], facecolors="gray",
                                     edgecolors="none"))
    fig.colorbar(polys, ax=ax, label="core von Mises (MPa)", fraction=0.03)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title(f"{note}{snapshot.model}: step {snapshot.step}, "
                 f"load factor {snapshot.load_factor:.4g}", fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def render_with_pyvista(snapshot: FieldSnapshot, path: Path, *, scale: float = 1.0,
                        window: tuple[int, int] = (1600, 420)) -> Path:
    """Render in this process with pyvista (off screen); see :func:`render_snapshot`."""
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
