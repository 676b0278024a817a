"""The adapter between the models' field output and the deformed-configuration pictures.

The one place that knows where a model's 2D field data lives. A model provides a
:class:`FieldSnapshot` either in memory (``solution.extra["field_snapshot"]``) or as
``fields.npz`` in its result folder (written by :func:`save_snapshot`: arrays ``points``,
``displacement``, ``cells``, ``von_mises``, optional ``region``, scalars ``step``,
``load_factor``). Without it the pictures fall back to the face deflections of ``profiles.csv``
(:func:`face_lines`).

Known sources: the beam model's ``beam_element.run`` + ``section_fields`` (a structured grid of
the section with per-point von Mises), wrapped by :func:`beam_solver_with_fields`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import numpy as np

from sandwich.results import Profile, Solution
from sandwich.scene import Scene

SNAPSHOT_FILE = "fields.npz"


@dataclass(frozen=True)
class FieldSnapshot:
    """A deformed state on a 2D mesh of the section (x along the beam, z up; mm, MPa).

    Attributes
    ----------
    model, step, load_factor
        Whose state, and where on the path.
    points
        ``(n, 2)`` reference coordinates (x, z).
    displacement
        ``(n, 2)`` displacement (u_x, u_z) at the points.
    cells
        ``(m, 3)`` triangles or ``(m, 4)`` quadrilaterals, counter-clockwise point indices.
    von_mises
        Core von Mises stress, ``(m,)`` per cell or ``(n,)`` per point, computed by the model.
    region
        Optional ``(m,)`` labels: 0 core, 1 top face, 2 bottom face (faces drawn grey).
    """

    model: str
    step: int
    load_factor: float
    points: np.ndarray
    displacement: np.ndarray
    cells: np.ndarray
    von_mises: np.ndarray
    region: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.points)
        if self.points.shape != (n, 2) or self.displacement.shape != (n, 2):
            raise ValueError(f"{self.model}: points and displacement must both be (n, 2), got "
                             f"{self.points.shape} and {self.displacement.shape}")
        if self.cells.ndim != 2 or self.cells.shape[1] not in (3, 4):
            raise ValueError(f"{self.model}: cells must be (m, 3) or (m, 4), "
                             f"got {self.cells.shape}")
        if self.cells.size and (self.cells.min() < 0 or self.cells.max() >= n):
            raise ValueError(f"{self.model}: cells refer to points outside 0..{n - 1}")
        if len(self.von_mises) not in (n, len(self.cells)):
            raise ValueError(f"{self.model}: von_mises has {len(self.von_mises)} values, expected "
                             f"{len(self.cells)} (per cell) or {n} (per point)")
        if self.region is not None and len(self.region) != len(self.cells):
            raise ValueError(f"{self.model}: region needs one label per cell")

    @property
    def per_cell(self) -> bool:
        """Whether ``von_mises`` is given per cell (else per point)."""
        return len(self.von_mises) == len(self.cells) != len(self.points)


def save_snapshot(snapshot: FieldSnapshot, folder: Path) -> Path:
    """Write ``snapshot`` as ``fields.npz`` into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    arrays = {"points": snapshot.points, "displacement": snapshot.displacement,
              "cells": snapshot.cells, "von_mises": snapshot.von_mises,
              "step": np.array(snapshot.step), "load_factor": np.array(snapshot.load_factor)}
    if snapshot.region is not None:
        arrays["region"] = snapshot.region
    path = folder / SNAPSHOT_FILE
    np.savez_compressed(path, **arrays)
    return path


def snapshot_of(solution: Solution, folder: Path | None) -> FieldSnapshot | None:
    """The model's field snapshot (in memory first, then ``fields.npz``), or ``None``."""
    snap = solution.extra.get("field_snapshot")
    if isinstance(snap, FieldSnapshot):
        return snap
    path = None if folder is None else Path(folder) / SNAPSHOT_FILE
    if path is None or not path.is_file():
        return None
    with np.load(path) as z:
        return FieldSnapshot(
            model=solution.model, step=int(z["step"]), load_factor=float(z["load_factor"]),
            points=z["points"], displacement=z["displacement"], cells=z["cells"],
            von_mises=z["von_mises"], region=z["region"] if "region" in z else None)


@dataclass(frozen=True)
class FaceLines:
    """Deformed face mid-lines from a profile: z = reference height + w (mm)."""

    model: str
    x: np.ndarray
    z_top: np.ndarray
    z_bottom: np.ndarray
    tau_core: np.ndarray


def face_lines(scene: Scene, profile: Profile, model: str) -> FaceLines:
    """Face mid-lines of ``profile`` placed at their heights in ``scene`` (z = 0 at the bottom).

    Axial face displacements are used when the profile has ``u_top``/``u_bottom``; the lines are
    drawn over the reference ``x`` otherwise.
    """
    c = profile.columns
    order = np.argsort(c["x"], kind="stable")
    x = np.asarray(c["x"], dtype=float)[order]
    z_bottom0 = 0.5 * scene.bottom.thickness
    z_top0 = scene.bottom.thickness + scene.core.thickness + 0.5 * scene.top.thickness
    return FaceLines(model, x, z_top0 + np.asarray(c["w_top"])[order],
                     z_bottom0 + np.asarray(c["w_bottom"])[order],
                     np.asarray(c["tau_core"])[order])


def snapshot_from_section(model: str, step: int, load_factor: float,
                          fields: object) -> FieldSnapshot:
    """Build a :class:`FieldSnapshot` from fields such as ``beam_element.SectionFields``.

    ``fields`` needs ``points, displacement, cells, von_mises`` and may have ``region``.
    """
    return FieldSnapshot(model=model, step=step, load_factor=load_factor,
                         points=np.asarray(fields.points, dtype=float),  # type: ignore[attr-defined]
                         displacement=np.asarray(fields.displacement,  # type: ignore[attr-defined]
                                                 dtype=float),
                         cells=np.asarray(fields.cells, dtype=int),  # type: ignore[attr-defined]
                         von_mises=np.asarray(fields.von_mises,  # type: ignore[attr-defined]
                                              dtype=float),
                         region=getattr(fields, "region", None))


def beam_solver_with_fields(module: ModuleType) -> Callable[..., Solution] | None:
    """``solve`` for the beam model that also keeps the section fields of the last state.

    Uses ``module.run`` (solution, model, states) and ``module.section_fields``; returns ``None``
    when the module does not offer them (the caller then uses plain ``solve``). The snapshot is
    put into ``solution.extra["field_snapshot"]``; the harness moves it into ``fields.npz``.
    """
    run, fields = getattr(module, "run", None), getattr(module, "section_fields", None)
    if not callable(run) or not callable(fields):
        return None

    def solve(scene: Scene, progress: Callable[[object], None] | None = None) -> Solution:
        result = run(scene, progress)
        solution = result.solution
        if result.states:
            last = result.states[-1]
            section = fields(result.model, last.u, nonlinear=result.nonlinear)
            solution.extra["field_snapshot"] = snapshot_from_section(
                solution.model or "beam", last.step, last.load_factor, section)
        return solution

    return solve
