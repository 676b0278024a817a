"""Scene files (TOML): the typed scene every model consumes, and its loader.

A scene describes one problem — geometry, materials, debonds, supports, loads, analysis, probes —
in N, mm and MPa. :func:`sandwich.scene_file.load_scene` reads, checks and returns it; every
problem found is reported at once as a :class:`SceneError` that names the file, the key and the
reason. The checks themselves live in :mod:`sandwich.scene_checks`. This module imports neither.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

FACES = ("top", "bottom")
INTERFACES = ("top", "bottom")
SUPPORT_SITES = ("top", "bottom", "faces")
SUPPORT_TYPES = ("pin", "roller", "clamp")
ANALYSIS_KINDS = ("linear", "nonlinear")
CONTROLS = ("load", "displacement", "arc-length")
GRADINGS = ("graded", "tips", "uniform")  # [beam_model] grading: the beam mesh along x
FACE_MEMBRANES = ("paper", "averaged")  # [beam_model] face_membrane
FACE_KINEMATICS = ("stretch", "paper")  # [beam_model] faces
CONTACT_SEARCHES = ("closest-point", "same-x")  # [beam_model] contact_search
MESH_LEVELS = ("coarse", "medium", "fine", "explicit")  # [reference2d] level: the 2D mesh
# Scene and probe names become folder and file names (results/<scene>/, load_<probe>.png)
NAME_PATTERN = r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}"
CORE_BASES = ("sublayers", "polynomial")  # enrichment families of the beam's core levels
MAX_CORE_LEVEL = 6


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a scene: where (file, key) and why."""

    file: str
    key: str
    reason: str

    def __str__(self) -> str:
        return f"{self.file}: {self.key}: {self.reason}"


class SceneError(ValueError):
    """A scene that cannot be used; ``problems`` lists every reason found."""

    def __init__(self, problems: list[Problem]):
        self.problems = problems
        super().__init__("\n".join(str(p) for p in problems))


@dataclass(frozen=True)
class Material:
    """Plane-stress linear elastic material (eqs. 3-4, 27).

    An isotropic material is stored as Ex = Ez = E, Gzx = E / (2 (1 + nu)), nu_zx = nu.
    """

    name: str
    kind: str  # "isotropic" | "orthotropic"
    Ex: float  # MPa
    Ez: float  # MPa
    Gzx: float  # MPa
    nu_zx: float  # contraction in x for extension in z

    @property
    def D(self) -> float:
        """Denominator of eq. (4): 1 − (Ex/Ez) ν_zx²."""
        return 1.0 - (self.Ex / self.Ez) * self.nu_zx**2

    @property
    def Qx(self) -> float:
        """Plane-stress stiffness Q_x = Ex / D, eq. (4) (MPa)."""
        return self.Ex / self.D

    @property
    def Qz(self) -> float:
        """Plane-stress stiffness Q_z = Ez / D, eq. (4) (MPa)."""
        return self.Ez / self.D

    @property
    def Q(self) -> float:
        """Coupling stiffness Q = Ex ν_zx / D, eq. (4) (MPa)."""
        return self.Ex * self.nu_zx / self.D


@dataclass(frozen=True)
class Layer:
    """A face or the core: thickness (mm) and material."""

    thickness: float
    material: Material


@dataclass(frozen=True)
class Toughness:
    """Interface toughness of a debond (N/mm) for the Benzeggagh–Kenane criterion.

    Growth when G ≥ G_c = GIc + (GIIc − GIc) (G_II / G)^eta (:mod:`sandwich.fracture`).
    """

    GIc: float
    GIIc: float
    eta: float = 2.0  # Benzeggagh–Kenane exponent


GROWTH_METHODS = ("crack-length", "cohesive")


@dataclass(frozen=True)
class Growth:
    """How a debond is grown: by crack-length control or by a cohesive law.

    ``method = "crack-length"`` (:mod:`sandwich.growth`): the debond's tips advance by ``step``
    (mm) one at a time, each time at the load where its G reaches the Benzeggagh–Kenane
    toughness, until the debond is ``max_length`` long (mm; ``None``: until a tip comes within
    one step of a beam end or of another debond).

    ``method = "cohesive"`` (beam: :mod:`sandwich.beam.cohesive`): the interface ahead of each
    tip, over ``zone`` mm (``None``: to the beam end or the next debond on the interface),
    carries a bilinear mixed-mode cohesive law of strengths ``sigma_c`` and ``tau_c`` (MPa) and
    the debond's toughness, with the penalty ``stiffness`` (N/mm³; ``None``: the default of
    :func:`sandwich.cohesive_law.default_stiffness`). The tips move along the one path.
    """

    step: float = 2.0
    max_length: float | None = None
    method: str = "crack-length"
    sigma_c: float | None = None
    tau_c: float | None = None
    zone: float | None = None
    stiffness: float | None = None

    @property
    def cohesive(self) -> bool:
        """Whether the debond grows by the cohesive law."""
        return self.method == "cohesive"


@dataclass(frozen=True)
class CohesiveSpan:
    """The stretch of interface a cohesive tip may open: from ``origin`` (the tip) to ``far``."""

    debond: int
    tip: str  # "start" | "end"
    interface: str
    origin: float  # mm
    far: float  # mm; below origin for a start tip

    @property
    def direction(self) -> int:
        """+1 where the tip grows towards larger x (an end tip), −1 otherwise."""
        return 1 if self.tip == "end" else -1


@dataclass(frozen=True)
class Debond:
    """A debonded stretch [start, end] (mm) of the top or bottom face/core interface."""

    interface: str
    start: float
    end: float
    toughness: Toughness | None = None  # optional: report the first step where it grows
    growth: Growth | None = None  # optional (needs a toughness): grow it, crack-length control

    @property
    def length(self) -> float:
        """Length of the debond (mm); zero is allowed and means bonded."""
        return self.end - self.start


@dataclass(frozen=True)
class Support:
    """A support at station x acting on one face or both ("faces")."""

    x: float
    on: str
    type: str

    @property
    def faces(self) -> tuple[str, ...]:
        """The faces this support acts on."""
        return FACES if self.on == "faces" else (self.on,)


@dataclass(frozen=True)
class Load:
    """A dead transverse load on a face: point load (width 0) or uniform patch, total force in N."""

    on: str
    x: float
    width: float
    force: float

    @property
    def span(self) -> tuple[float, float]:
        """The stretch [x − width/2, x + width/2] the load covers (mm)."""
        return (self.x - 0.5 * self.width, self.x + 0.5 * self.width)


@dataclass(frozen=True)
class Probe:
    """Transverse displacement w of a face at station x, recorded at every step (mm)."""

    name: str
    on: str
    x: float


@dataclass(frozen=True)
class PathControls:
    """How a path is followed and how far: the part of ``[analysis]`` the path follower takes.

    :class:`Analysis` is these and the analysis ``kind``; the solver's
    :class:`~sandwich.solver.path.PathOptions` is these and its own settings, so that neither
    lists them again.
    """

    control: str = "load"
    until_probe: str | None = None
    until_value: float | None = None
    until_load_factor: float | None = None
    max_steps: int = 200
    initial_increment: float | None = None
    min_increment: float | None = None
    max_increment: float | None = None
    tol: float = 1e-8
    max_iterations: int = 25
    # narrow each step across a bifurcation or a load extremum by shorter steps inside it (a
    # corrector each), so its load is located to ~0.5 % whatever the step
    # (sandwich.solver.critical, sandwich.solver.extrema); off: located from the step's two
    # states alone (free; second order in the step for a bifurcation, fourth for an extremum)
    locate_critical_points: bool = False


@dataclass(frozen=True)
class Analysis(PathControls):
    """What to solve and how far: the load factor λ multiplies every load's force."""

    kind: str = "nonlinear"  # "linear" | "nonlinear"


@dataclass(frozen=True)
class BeamModelOptions:
    """Resolution and numerics of the beam element model (table ``[beam_model]``)."""

    elements: int = 240  # fig5 to -15 mm: 240 graded elements within 4.5 % (paper element)
    grading: str = "graded"  # "graded" (small at supports, load edges, debond tips and all along
    # debonds) | "tips" (small at the points only) | "uniform"
    face_membrane: str = "averaged"  # "averaged" (element-mean face strain: no membrane
    # locking) | "paper" (eq. 15 at every point)
    faces: str = "stretch"  # "stretch" (w linear through each face: rotated faces bend right) |
    # "paper" (w constant through each face, the paper's eq. 13)
    contact_search: str = "closest-point"  # "closest-point" (node to segment) | "same-x"
    gauss_x: int | None = None  # None: the rule that integrates the strain energy exactly
    gauss_z: int | None = None
    contact_penalty: float | None = None
    profile_every: int = 0  # 0: profiles at the last step only
    core: int | str = "auto"  # core level 1 (the paper's) .. MAX_CORE_LEVEL, or "auto"
    core_basis: str = "sublayers"  # "sublayers" (graded C1 cubic sublayers) | "polynomial"
    tolerance: float = 0.01  # "auto": target relative error of the core's through-thickness field
    max_core_level: int = 3  # "auto": highest level it may choose (docs/beam_element.md)
    core_zones: tuple[CoreZone, ...] = ()  # explicit levels over stretches of x
    settling_allowance: int | None = 2  # step sizes (docs/solver.md "Settling iterations")


@dataclass(frozen=True)
class CoreZone:
    """A stretch [start, end] of x (mm) where the beam's core has at least ``level``."""

    start: float
    end: float
    level: int


@dataclass(frozen=True)
class Reference2DOptions:
    """Resolution and numerics of the 2D reference (table ``[reference2d]``)."""

    level: str = "medium"  # "coarse" | "medium" | "fine" | "explicit"
    refine: int = 0  # uniform refinement count on top of the level (each halves sizes)
    face_elements: int = 2  # quadratic elements through each face thickness
    core_size: float | None = None  # explicit element size in the core (mm), level "explicit"
    face_size: float | None = None  # explicit element length along the faces (mm)
    tip_size: float | None = None  # element size at crack tips / loads / supports (mm)
    half_model: bool = False
    contact_penalty: float | None = None
    profile_every: int = 0
    closure_length: float | None = None  # VCCT closure length (mm); None: the thinner face
    error_estimate: bool = True  # the answer at the target against the next coarser level


@dataclass(frozen=True)
class Accuracy:
    """What a run estimates at its target and what it holds each to (table ``[accuracy]``).

    Relative tolerances (G_II/G's absolute); None: each model's default (docs/scenes.md,
    "Accuracy"). ``estimate_G`` / ``estimate_stresses`` False: G and G_II/G at the debond tips /
    the averaged stress peaks are not estimated (the load and probes, the path's answer, always
    are).
    """

    load: float | None = None  # the load at the target and every probe
    G: float | None = None  # G at the debond tips; G_II/G
    stresses: float | None = None  # 5-mm averaged peaks of the interface σzz and the core τ
    estimate_G: bool = True
    estimate_stresses: bool = True


@dataclass(frozen=True)
class Scene:
    """One problem, the single source of truth for every model."""

    name: str
    description: str
    length: float
    width: float
    top: Layer
    core: Layer
    bottom: Layer
    debonds: tuple[Debond, ...]
    supports: tuple[Support, ...]
    loads: tuple[Load, ...]
    probes: tuple[Probe, ...]
    analysis: Analysis
    beam_model: BeamModelOptions = field(default_factory=BeamModelOptions)
    reference2d: Reference2DOptions = field(default_factory=Reference2DOptions)
    accuracy: Accuracy = field(default_factory=Accuracy)
    source: Path | None = None

    @property
    def total_height(self) -> float:
        """Face + core + face thickness (mm)."""
        return self.top.thickness + self.core.thickness + self.bottom.thickness

    def layer(self, name: str) -> Layer:
        """The layer called ``name`` ("top", "core" or "bottom")."""
        return {"top": self.top, "core": self.core, "bottom": self.bottom}[name]

    def debonds_on(self, interface: str) -> tuple[Debond, ...]:
        """The debonds of one interface, sorted by start."""
        return tuple(sorted((d for d in self.debonds if d.interface == interface),
                            key=lambda d: d.start))

    def cohesive_spans(self) -> list[CohesiveSpan]:
        """Every tip of a debond grown by a cohesive law, with the stretch ahead it may open.

        The stretch runs from the tip ``zone`` mm away from the debond (its ``growth.zone``),
        at most to the beam end or to the next debond on the interface (to half way where that
        one grows by a cohesive law too). An end at a beam end is an open mouth, not a tip.
        """
        tol = 1e-9 * self.length
        out = []
        for i, d in enumerate(self.debonds):
            if d.growth is None or not d.growth.cohesive or d.length <= tol:
                continue
            # a neighbour growing towards this debond shares the stretch between them
            others = [(o.start, o.end) if o.growth is None or not o.growth.cohesive
                      else (0.5 * (d.end + o.start), 0.5 * (o.end + d.start))
                      for o in self.debonds_on(d.interface) if o is not d]
            reach = d.growth.zone if d.growth.zone is not None else self.length
            if d.end < self.length - tol:
                far = min([d.end + reach, self.length]
                          + [a for a, _ in others if a > d.end])
                out.append(CohesiveSpan(i, "end", d.interface, d.end, far))
            if d.start > tol:
                far = max([d.start - reach, 0.0] + [b for _, b in others if b < d.start])
                out.append(CohesiveSpan(i, "start", d.interface, d.start, far))
        return out

    def is_bonded(self, interface: str, x: float, tol: float = 1e-9) -> bool:
        """Whether ``x`` is bonded on ``interface``.

        Debond tips (ends inside the beam) count as bonded. The end of a debond that reaches a
        beam end is an open mouth, not a tip: the face and the core are not attached there.
        A zero-length debond is bonded everywhere.
        """
        at_beam_end = x <= tol or x >= self.length - tol
        for d in self.debonds_on(interface):
            if d.start + tol < x < d.end - tol:
                return False
            if at_beam_end and d.end - d.start > tol and d.start - tol <= x <= d.end + tol:
                return False
        return True

    def probe(self, name: str) -> Probe:
        """The probe called ``name``."""
        for p in self.probes:
            if p.name == name:
                return p
        raise KeyError(name)


def is_finite_number(value: object) -> bool:
    """True for an int or float (not bool) that is finite."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
