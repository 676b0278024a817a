"""Resolution levels of the 2D reference mesh: element sizes from the scene's ``[reference2d]``.

Levels "coarse", "medium" and "fine" share one layout of segments along x computed with the coarse
sizes; "medium" splits every element along x and through the core in two (about 3-4x the cells),
"fine" in four. The faces keep ``face_elements`` through their thickness at every level. ``refine =
n`` then halves *every* size n more times, faces included, so each step has exactly 4x the cells.
Level "explicit" lays out the segments with the sizes given in the scene.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sandwich.scene import MESH_LEVELS, Scene

LEVELS = MESH_LEVELS
LEVEL_SUBDIVISION = {"coarse": 1, "medium": 2, "fine": 4, "explicit": 1}

COARSE_GROWTH = 1.5  # largest length ratio of neighbouring elements along x at level coarse
EXPLICIT_GROWTH = 1.3  # the same for level "explicit"
CORE_HALF_ELEMENTS = 4  # coarse: elements from an interface to the core mid-plane
CORE_GROWTH = 1.5  # coarse: length ratio of neighbouring elements from interface to mid-plane
FAR_PER_HEIGHT = 0.2  # coarse far-field element length as a fraction of the beam height
MAX_FACE_ASPECT = 20.0  # coarse far-field element length / face element thickness, at most
#: coarse element length / face element thickness, at most, over a debond: a debonded face bends
#: on its own there (at a clamp it carries the clamp's moment alone), and 9-node elements of
#: aspect 20 are far too stiff in that bending (c4: +16 % at aspect 20, +0.7 % at 5 against the
#: fine level; docs/meshes.md)
MAX_DEBOND_ASPECT = 5.0
#: the next coarser level of each level that has one (at ``refine = 0``): the levels are nested
COARSER = {"medium": "coarse", "fine": "medium"}


@dataclass(frozen=True)
class Coarser:
    """The next coarser resolution of a mesh: a level and its refinement count."""

    level: str
    refine: int

    def __str__(self) -> str:
        refined = self.refine or self.level == "explicit"
        return self.level + (f" + refine {self.refine}" if refined else "")


def coarser_level(level: str, refine: int) -> Coarser | None:
    """The next coarser resolution of ``level`` + ``refine`` halvings; None where none is."""
    if refine > 0:
        return Coarser(level, refine - 1)
    if level in COARSER:
        return Coarser(COARSER[level], 0)
    return None


@dataclass(frozen=True)
class Sizing:
    """Element sizes of one mesh; lengths in mm."""

    level: str
    refine: int
    tip_size: float  # element length along x at crack tips, load edges and supports
    far_size: float  # element length along x far from them
    debond_size: float  # the same over a debond (at most far_size)
    growth: float  # largest ratio of neighbouring element lengths along x
    core_half_elements: int  # elements from each interface to the core mid-plane
    core_growth: float  # element length ratio interface -> mid-plane, per element
    face_elements: int  # elements through each face
    subdivision: int  # every element along x (and through the core) is split into this many

    @property
    def face_rows(self) -> int:
        """Elements through each face thickness."""
        return self.face_elements * 2**self.refine

    @property
    def core_rows_half(self) -> int:
        """Elements from each interface to the core mid-plane."""
        return self.core_half_elements * self.subdivision

    @property
    def core_ratio(self) -> float:
        """Length ratio of neighbouring core elements, from an interface towards the mid-plane."""
        return self.core_growth ** (1.0 / self.subdivision)

    @property
    def snap_tolerance(self) -> float:
        """Key stations closer than this are merged (mm): a quarter of the finest x element."""
        return 0.25 * self.tip_size / LEVEL_SUBDIVISION[self.level]


def sizing_for(scene: Scene, level: str | None = None, refine: int | None = None,
               size_factor: float = 1.0) -> Sizing:
    """The sizes of ``scene`` at ``level`` with ``refine`` halvings (defaults from the scene).

    ``size_factor`` scales the x sizes of the segment layout (tip and far-field lengths).
    """
    opts = scene.reference2d
    level = opts.level if level is None else level
    refine = opts.refine if refine is None else refine
    if level not in LEVELS:
        raise ValueError(f"unknown mesh level {level!r}; expected one of {', '.join(LEVELS)}")
    if refine < 0:
        raise ValueError(f"refine must be >= 0, got {refine}")
    if size_factor <= 0:
        raise ValueError(f"size_factor must be positive, got {size_factor}")
    if opts.face_elements < 2:
        raise ValueError(f"reference2d.face_elements must be >= 2, got {opts.face_elements}")
    fe = opts.face_elements
    t_face = min(scene.top.thickness, scene.bottom.thickness)
    half_core = 0.5 * scene.core.thickness
    if level == "explicit":
        if opts.core_size is None:
            raise ValueError("level 'explicit' needs reference2d.core_size (mm)")
        far = opts.face_size if opts.face_size is not None else opts.core_size
        tip = opts.tip_size if opts.tip_size is not None else min(far, t_face)
        return Sizing(level, refine, tip * size_factor, far * size_factor, far * size_factor,
                      EXPLICIT_GROWTH,
                      max(1, math.ceil(half_core / opts.core_size - 1e-9)), 1.0, fe, 2**refine)
    far = min(FAR_PER_HEIGHT * scene.total_height, MAX_FACE_ASPECT * t_face / fe)
    tip = min(t_face, far)
    debond = max(tip, min(far, MAX_DEBOND_ASPECT * t_face / fe))
    return Sizing(level, refine, tip * size_factor, far * size_factor, debond * size_factor,
                  COARSE_GROWTH,
                  CORE_HALF_ELEMENTS, CORE_GROWTH, fe, LEVEL_SUBDIVISION[level] * 2**refine)
