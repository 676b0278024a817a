"""What a path is made of: its converged states, the result, and a step's converged candidate."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from sandwich.results import LimitPoint
from sandwich.solver.critical import Crossing
from sandwich.solver.extrema import Extremum
from sandwich.solver.system import Factorization

__all__ = ["PathResult", "PathState", "Refinement", "Trial", "format_probes"]


@dataclass
class PathState:
    """A converged equilibrium state (step 0 is the unloaded state ``u = 0, λ = 0``)."""

    step: int
    u: np.ndarray
    load_factor: float
    iterations: int
    probes: dict[str, float]
    negative_pivots: int | None
    cuts: int = 0
    # where the tangent's inertia changed on the step that ends here: the bifurcation located
    # within the step (:meth:`~.critical_points.CriticalPoints.locate_crossing`), None if it did
    # not change or could not be located
    crossing: Crossing | None = None
    # dw/dλ of the load curve's probe w along the path here, c·K⁻¹f_ref (from the next step's
    # load tangent; None without that probe or where the tangent failed)
    probe_rate: float | None = None
    # the load extremum located within the step that ends here (:mod:`sandwich.solver.extrema`)
    extremum: Extremum | None = None
    # per-state history columns the model adds (``system.state_columns(u)``, optional): kept on
    # the state so that an interrupted run still writes them (e.g. G at the debond tips)
    extra: dict[str, float | None] = field(default_factory=dict)


@dataclass
class PathResult:
    """The computed path: every converged state, whether the target was reached, and why not."""

    states: list[PathState]
    reached_target: bool
    message: str
    limit_points: list[LimitPoint] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # one sentence each, besides the message


@dataclass
class Trial:
    """A converged step candidate: an equilibrium the path may accept as its next state."""

    u: np.ndarray
    load_factor: float
    iterations: int
    factorization: Factorization
    rises: int = 0  # the corrector's longest run of rises above its first residual
    increment_iterations: int | None = None  # until its increment test first passed


@dataclass
class Refinement:
    """A finer discretisation of the same problem, continued from a converged state.

    What a caller's ``refine`` hook hands :func:`~.follower.follow_path` to go on on another
    system from the last converged state (:mod:`.switching`): the system, the map of a vector
    of the old system's free DOFs onto the new one's, and the state re-converged on it with the
    factorised tangent there.
    """

    system: object  # a DiscreteSystem
    transfer: Callable[[np.ndarray], np.ndarray]
    u: np.ndarray
    load_factor: float
    iterations: int
    factorization: Factorization
    # the refinement is of the state this many steps before the last: the steps after it are
    # dropped and taken again on the new system (a critical point located within them is then
    # located on that system)
    rewind: int = 0


def format_probes(probes: dict[str, float]) -> str:
    """``"name = value, …"`` of a state's probes, for messages."""
    return ", ".join(f"{k} = {v:.6g}" for k, v in probes.items())
