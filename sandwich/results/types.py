"""Typed results every model returns (the result contract's in-memory side).

:class:`Solution` holds the equilibrium path (:class:`StepRecord` per converged step), profiles
along the beam (:class:`Profile`), limit points and, when the model reconstructs them, 2D field
frames (:class:`FieldFrame`, the one field type both models fill).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, Union

import numpy as np

PROFILE_COLUMNS = ("x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom", "tau_core")


@dataclass
class StepRecord:
    """One converged equilibrium state on the path."""

    step: int
    load_factor: float
    probes: dict[str, float]
    iterations: int
    extra: dict[str, float] = field(default_factory=dict)

    @classmethod
    def of(cls, state: StateLike) -> StepRecord:
        """The record of a solver's converged state (its solution vector left behind)."""
        return cls(int(state.step), float(state.load_factor), dict(state.probes),
                   int(state.iterations), dict(state.extra or {}))


class StateLike(Protocol):
    """What a model streams for each converged state (the solver's ``PathState`` is one)."""

    step: int
    load_factor: float
    probes: dict[str, float]
    iterations: int
    extra: dict[str, float | None]


class InterruptedSolve(KeyboardInterrupt):
    """An interrupt (Ctrl-C) that reached a model holding a whole answer: ``solution``.

    The beam's ``auto`` core levels raise it when interrupted while checking a pass that
    reached the target: that pass is the answer, its error not estimated (said in its warnings).
    """

    def __init__(self, solution: Solution):
        super().__init__("interrupted; an answer that reached the target is kept")
        self.solution = solution


@dataclass(frozen=True)
class PathNote:
    """What a model tells while it solves, besides its states.

    The one other event a model's ``progress`` callback receives. With ``restart`` the path
    starts again and the states streamed before it are superseded (a rerun at raised core
    levels follows the path from its start); without, it is news only (levels raised along
    the path: the state re-converged at them comes next, with the step number of the one it
    replaces).
    """

    message: str
    restart: bool = True


ProgressItem = Union[StateLike, PathNote]  # noqa: UP007 - a runtime alias of a Protocol


@dataclass
class Profile:
    """Fields sampled along the beam axis at one converged step (mm, MPa).

    ``columns`` holds at least the names of ``PROFILE_COLUMNS`` (each an array over ``x``);
    models may add more (``p_contact_top``, ``u_top`` ...).
    """

    step: int
    columns: dict[str, np.ndarray]


@dataclass
class LimitPoint:
    """An extremum of the load factor along the path, or a bifurcation (tangent inertia change)."""

    kind: str  # "max" | "min" | "bifurcation"
    step: int
    load_factor: float
    probes: dict[str, float]
    # load factors of the converged states that enclose the point along the path: a
    # bifurcation lies between the state before ``step`` and ``step``, an extremum between the
    # states either side of ``step``; the point is known to that resolution only
    between: tuple[float, float] | None = None
    # a point located within the step that ends at the state ``step``: for a bifurcation
    # (:mod:`sandwich.solver.critical`) the fraction of the step's size from the state before
    # at which the tangent's crossed eigenvalue is zero, for a load extremum
    # (:mod:`sandwich.solver.extrema`) the fraction of the step's change of the load curve's
    # probe at which λ's interpolant is stationary; ``load_factor`` and ``probes`` are the
    # located point's, ``between`` the step's (or the narrowed bracket's) load factors. None:
    # reported at the state ``step``
    located_at: float | None = None


@dataclass
class FieldFrame:
    """Fields of one converged step on a 2D grid of the beam, for ParaView.

    ``points`` are reference coordinates (x, z) in mm, ``cells`` counter-clockwise quads (m, 4) or
    triangles (m, 3); ``displacement`` (n, 2) in mm; stresses in MPa as point or cell data.
    """

    step: int
    load_factor: float
    points: np.ndarray
    cells: np.ndarray
    displacement: np.ndarray
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)


@dataclass
class Solution:
    """What a solve returns: the equilibrium path, profiles and a summary."""

    model: str
    scene: str
    history: list[StepRecord]
    profiles: list[Profile]
    converged: bool
    message: str
    limit_points: list[LimitPoint]
    wall_seconds: float
    dofs: int
    extra: dict[str, object] = field(default_factory=dict)
    fields: list[FieldFrame] = field(default_factory=list)
    # what a user must know about the answer besides why the run ended (``message``): an
    # estimate above its tolerance, a rerun that stopped, a core that crushed, …; one sentence each
    warnings: list[str] = field(default_factory=list)

    @property
    def final_load_factor(self) -> float:
        """Load factor of the last converged step (0 when none converged)."""
        return self.history[-1].load_factor if self.history else 0.0
