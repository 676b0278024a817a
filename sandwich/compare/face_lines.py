"""Deformed face mid-lines from a profile: the picture of a model that gives no field frames.

Both models fill :class:`~sandwich.results.FieldFrame` (the deformed pictures are drawn from
those, :mod:`sandwich.compare.deformed`); a solution without frames (synthetic solvers in tests, a
model that reconstructs none) is drawn from the face deflections of its last profile instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.results import Profile
from sandwich.scene import Scene


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

    The lines are drawn over the reference ``x`` (the profile's axial displacements are not used).
    """
    c = profile.columns
    order = np.argsort(c["x"], kind="stable")
    x = np.asarray(c["x"], dtype=float)[order]
    z_bottom0 = 0.5 * scene.bottom.thickness
    z_top0 = scene.bottom.thickness + scene.core.thickness + 0.5 * scene.top.thickness
    return FaceLines(model, x, z_top0 + np.asarray(c["w_top"])[order],
                     z_bottom0 + np.asarray(c["w_bottom"])[order],
                     np.asarray(c["tau_core"])[order])
