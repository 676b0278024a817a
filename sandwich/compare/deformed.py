"""Deformed-configuration pictures, from a model's field frame or from face profiles.

Both models fill the one field type :class:`~sandwich.results.FieldFrame` (points, cells,
displacement, point or cell data): the picture of a model is its last frame, drawn deformed
(matplotlib) with the core coloured by its von Mises stress and the faces by theirs, each on
its own colour bar (the faces carry stresses one to two orders above the core's). The beam's
stress is per point (second Piola-Kirchhoff), the 2D reference's per cell (Cauchy); cell data
``region`` tells core (0), top face (1) and bottom face (2).

A comparison draws both models with one deformation scale and one colour range per region
(:func:`shared_view`), so that equal colours mean equal stresses side by side; the scale is
stated in each title ("deformation × 1" is true scale). Axes are x and z in mm at equal aspect.
Without frames, the pictures fall back to the face lines of the profiles
(:mod:`sandwich.compare.face_lines`).

Drawing only: stresses and displacements come from the model.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from sandwich.compare.face_lines import FaceLines  # noqa: E402
from sandwich.results import FieldFrame, Solution  # noqa: E402

STRESS = "von_mises"
CORE, FACES = "core", "faces"
COLOUR_MAPS = {CORE: "viridis", FACES: "magma"}  # one map per region, the same for both models
VISIBLE_DEFLECTION = 0.25  # magnify until the largest displacement is this × the section depth
NICE_FACTORS = (1, 2, 5)  # deformation scales are these × a power of ten


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

    def cell_stress(self) -> np.ndarray:
        """Von Mises per cell (MPa): the cell's own, or the mean of its points'."""
        return self.von_mises if self.per_cell else self.von_mises[self.cells].mean(axis=1)

    def in_region(self, region: str) -> np.ndarray:
        """Mask of the cells of ``region`` (``"core"`` or ``"faces"``)."""
        return self.region == 0 if region == CORE else self.region != 0


@dataclass(frozen=True)
class View:
    """What pictures drawn side by side share: deformation scale and colour range per region."""

    scale: float
    ranges: dict[str, tuple[float, float]]  # region -> (min, max) von Mises, MPa


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


def deformation_scale(pictures: Sequence[Picture]) -> float:
    """True scale (1) when the largest displacement is visible, else a round magnification.

    Visible: at least ``VISIBLE_DEFLECTION`` × the section depth; a smaller one is magnified by
    the smallest of 1, 2, 5 × 10ⁿ that makes it so.
    """
    depth = max((float(np.ptp(p.points[:, 1])) for p in pictures), default=0.0)
    largest = max((float(np.max(np.linalg.norm(p.displacement, axis=1)))
                   for p in pictures if len(p.displacement)), default=0.0)
    if depth <= 0 or largest <= 0 or largest >= VISIBLE_DEFLECTION * depth:
        return 1.0
    need = VISIBLE_DEFLECTION * depth / largest
    power = 10.0 ** math.floor(math.log10(need))
    return next(f * power for f in (*NICE_FACTORS, 10) if f * power >= need)


def shared_view(pictures: Sequence[Picture]) -> View:
    """One deformation scale and one colour range per region over ``pictures``."""
    ranges = {}
    for region in (CORE, FACES):
        values = [p.cell_stress()[p.in_region(region)] for p in pictures]
        values = [v[np.isfinite(v)] for v in values]
        values = [v for v in values if v.size]
        if values:
            lo = min(float(v.min()) for v in values)
            hi = max(float(v.max()) for v in values)
            ranges[region] = (lo, hi if hi > lo else lo + 1.0)
    return View(deformation_scale(pictures), ranges)


def picture_figure(pic: Picture, view: View | None = None, *, note: str = "") -> Figure:
    """The deformed section of ``pic`` as a matplotlib figure (axes in mm, equal aspect)."""
    view = view or shared_view([pic])
    xz = pic.points + view.scale * pic.displacement
    stress = pic.cell_stress()
    fig, ax = plt.subplots(figsize=(12.0, 3.6), layout="constrained")
    bars = []
    for region in (CORE, FACES):
        mask = pic.in_region(region)
        if not mask.any() or region not in view.ranges:
            continue
        polys = PolyCollection(xz[pic.cells[mask]], array=stress[mask], cmap=COLOUR_MAPS[region],
                               norm=Normalize(*view.ranges[region]), edgecolors="face",
                               linewidths=0.2, antialiaseds=False)
        ax.add_collection(polys)
        bars.append((polys, f"{region} von Mises (MPa)"))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    shown = " and ".join(region for region in (CORE, FACES) if pic.in_region(region).any())
    ax.set_title(f"{note}{pic.model}: step {pic.step}, load factor {pic.load_factor:.4g}; "
                 f"deformation × {view.scale:g}; {shown} shown", fontsize=9)
    for polys, label in bars:
        fig.colorbar(polys, ax=ax, orientation="horizontal", location="bottom", label=label,
                     fraction=0.08, aspect=60, pad=0.02)
    return fig


def draw_picture(pic: Picture, path: Path, view: View | None = None, *, note: str = "") -> Path:
    """Write :func:`picture_figure` of ``pic`` to ``path`` (PNG)."""
    fig = picture_figure(pic, view, note=note)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
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
