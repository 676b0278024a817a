"""Deformed-configuration pictures, from a model's field frame or from face profiles.

Both models fill the one field type :class:`~sandwich.results.FieldFrame` (points, cells,
displacement, point or cell data): the picture of a model is its last frame, drawn deformed and
coloured by the von Mises stress the model computed (the beam: per point, second Piola-Kirchhoff;
the 2D reference: per cell, Cauchy), faces grey (cell data ``region``: 0 core, 1 top face,
2 bottom face). pyvista renders off screen in a child process, matplotlib when that fails.
Without frames, the pictures fall back to the face lines of the profiles
(:mod:`sandwich.compare.face_lines`).

Drawing only: stresses come from the model; deformation is drawn at true scale.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from sandwich.compare.face_lines import FaceLines  # noqa: E402
from sandwich.results import FieldFrame, Solution  # noqa: E402
from sandwich.results.vtu import read_vtu, vtu_text  # noqa: E402

STRESS = "von_mises"


@dataclass(frozen=True)
class Picture:
    """What one deformed picture shows: a model's frame reduced to the drawn arrays."""

    model: str
    step: int
    load_factor: float
    points: np.ndarray  # (n, 2) reference (x, z), mm
    displacement: np.ndarray  # (n, 2), mm
    cells: np.ndarray  # (m, 3 | 4)
    von_mises: np.ndarray  # (m,) per cell or (n,) per point, MPa
    per_cell: bool
    region: np.ndarray  # (m,) 0 core, 1 top face, 2 bottom face


def picture_of(model: str, frame: FieldFrame) -> Picture:
    """The picture data of ``frame``; ``ValueError`` if it holds no von Mises stress."""
    if STRESS in frame.cell_data:
        vm, per_cell = np.asarray(frame.cell_data[STRESS], dtype=float), True
    elif STRESS in frame.point_data:
        vm, per_cell = np.asarray(frame.point_data[STRESS], dtype=float), False
    else:
        raise ValueError(f"{model}: field frame of step {frame.step} has no {STRESS}")
    cells = np.asarray(frame.cells, dtype=np.int64)
    region = np.asarray(frame.cell_data.get("region", np.zeros(len(cells))), dtype=int)
    return Picture(model, int(frame.step), float(frame.load_factor),
                   np.asarray(frame.points, dtype=float)[:, :2],
                   np.asarray(frame.displacement, dtype=float)[:, :2], cells, vm, per_cell,
                   region)


def last_picture(solution: Solution) -> Picture | None:
    """The picture of the solution's last field frame, ``None`` when it has no frames."""
    if not solution.fields:
        return None
    frame = max(solution.fields, key=lambda f: f.step)
    return picture_of(solution.model, frame)


def render_frame(model: str, frame: FieldFrame, path: Path, *, scale: float = 1.0) -> Path:
    """Render ``frame`` deformed (× ``scale``), coloured by core von Mises, into ``path``.

    pyvista renders in a child process (the frame handed over as VTU): VTK's wheel and the
    FEniCSx stack loaded in one process have been seen to abort inside VTK (a C++ library
    clash). If the child fails, the picture is drawn with matplotlib instead, and the title says
    so.
    """
    pic = picture_of(model, frame)
    with tempfile.TemporaryDirectory() as tmp:
        vtu = Path(tmp) / "frame.vtu"
        vtu.write_text(vtu_text(pic.points, pic.cells, {"displacement": pic.displacement,
                                                        **({} if pic.per_cell else
                                                           {STRESS: pic.von_mises})},
                                {"region": pic.region.astype(float),
                                 **({STRESS: pic.von_mises} if pic.per_cell else {})}))
        cmd = [sys.executable, "-m", "sandwich.compare.render_worker", str(vtu), str(path), model,
               str(pic.step), repr(pic.load_factor), repr(scale)]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
            ok = done.returncode == 0 and Path(path).is_file()
        except (OSError, subprocess.TimeoutExpired):
            ok = False
    return path if ok else draw_picture(pic, path, scale=scale, note="pyvista failed; ")


def picture_from_vtu(path: Path, model: str, step: int, load_factor: float) -> Picture:
    """The picture written by :func:`render_frame` for its child process."""
    points, cells, point_data, cell_data = read_vtu(path)
    frame = FieldFrame(step, load_factor, points[:, :2], cells,
                       point_data.pop("displacement")[:, :2], point_data, cell_data)
    return picture_of(model, frame)


def draw_picture(pic: Picture, path: Path, *, scale: float = 1.0, note: str = "") -> Path:
    """Matplotlib picture of the deformed section, core cells coloured by von Mises."""
    from matplotlib.collections import PolyCollection

    xz = pic.points + scale * pic.displacement
    vm = pic.von_mises if pic.per_cell else pic.von_mises[pic.cells].mean(axis=1)
    fig, ax = plt.subplots(figsize=(14, 3.6))
    core = pic.region == 0
    polys = PolyCollection(xz[pic.cells[core]], array=vm[core], cmap="viridis",
                           edgecolors="none")
    ax.add_collection(polys)
    ax.add_collection(PolyCollection(xz[pic.cells[~core]], facecolors="gray",
                                     edgecolors="none"))
    fig.colorbar(polys, ax=ax, label="core von Mises (MPa)", fraction=0.03)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title(f"{note}{pic.model}: step {pic.step}, load factor {pic.load_factor:.4g}",
                 fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def render_with_pyvista(pic: Picture, path: Path, *, scale: float = 1.0,
                        window: tuple[int, int] = (1600, 420)) -> Path:
    """Render in this process with pyvista (off screen); see :func:`render_frame`."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    xz = pic.points + scale * pic.displacement
    pts = np.column_stack([xz[:, 0], np.zeros(len(xz)), xz[:, 1]])
    k = pic.cells.shape[1]
    kind = pv.CellType.TRIANGLE if k == 3 else pv.CellType.QUAD
    conn = np.column_stack([np.full(len(pic.cells), k), pic.cells]).ravel()
    grid = pv.UnstructuredGrid(conn, np.full(len(pic.cells), kind, dtype=np.uint8), pts)
    name = "von Mises (MPa)"
    if pic.per_cell:
        grid.cell_data[name] = pic.von_mises
    else:
        grid.point_data[name] = pic.von_mises
    plotter = pv.Plotter(off_screen=True, window_size=list(window))
    plotter.set_background("white")
    core = grid.extract_cells(np.flatnonzero(pic.region == 0))
    faces = grid.extract_cells(np.flatnonzero(pic.region != 0))
    if faces.n_cells:
        plotter.add_mesh(faces, color="gray")
    plotter.add_mesh(core, scalars=name, cmap="viridis",
                     scalar_bar_args={"title": name, "color": "black"})
    plotter.add_text(f"{pic.model}: step {pic.step}, load factor {pic.load_factor:.4g}",
                     font_size=10, color="black")
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
