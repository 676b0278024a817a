"""One following of a scene's nonlinear path on the beam model at fixed core levels.

:func:`follow` hands a model to the path follower (:func:`sandwich.solver.path.follow_path`)
with the beam's settings; :func:`follow_penalised` builds the model and follows its path again
with a stiffer contact penalty while its converged states penetrate deeper than the model's
bound. Both give a :class:`PathPass`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from sandwich.beam.build import build_model, scene_gauss_orders
from sandwich.beam.model import BeamModel
from sandwich.results import LimitPoint, PathNote
from sandwich.solver import PathState

MIN_INCREMENT_PER_SMOOTHING = 0.01  # default path increment floor / contact smoothing width s
# Newton iterations per step at which the path follower keeps the increment (its default is 5).
# The beam's corrector needs 4-5 iterations even on short steps of the smooth c2 path (tol 1e-8
# plus the increment test), so 5 held the arc near 0.25 mm: 69 steps to −15 mm. With 8: 22 steps,
# 168 iterations, same end state (λ 352.811). The floor (min_increment) is unchanged.
DESIRED_ITERATIONS = 8
# A path whose converged states penetrate deeper than the model's bound (issue: 1e-3 × the face
# thickness) is rerun with the penalty raised by PENALTY_GROWTH × (penetration / bound), at most
# PENALTY_RESTARTS times. Penetration grows as the element length shrinks where a face presses
# a point force on the core (a clamped mouth: fig. 7 c4 at 480 elements), so no fixed penalty
# meets the bound at every resolution.
PENALTY_RESTARTS = 2
PENALTY_GROWTH = 2.0


@dataclass
class PathPass:
    """The path followed once at fixed core levels (its penalty reruns included)."""

    model: BeamModel  # the model of the last attempt
    states: list[PathState]
    message: str
    converged: bool  # the target was reached
    limit_points: list[LimitPoint]
    # the penalties the reruns raised from (the first: the model's own), empty without rerun
    penalties_raised: list[float] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # the path follower's and auto's

    @property
    def last(self) -> PathState:
        """The last converged state."""
        return self.states[-1]


def min_increment(model: BeamModel, analysis: object) -> float | None:
    """Smallest path increment: the scene's, else 0.01 × the contact regularisation width s (mm).

    A contact pair opening next to a buckling face is a sharp limit point of width ~s
    (:mod:`sandwich.beam.contact_law`); the path follower's own floor (1e-4 × the first
    increment, ~1e-3 mm for the fig. 7 scenes) is too coarse to turn there (measured: 5e-5 mm
    fails on the jump guard at the turn of C3/C4 at 40 elements, 1e-5 mm passes). The floor
    applies to arc-length and displacement control (increments in mm) of models with contact
    pairs; load control and bonded models keep the follower's default.
    """
    if analysis.min_increment is not None:
        return analysis.min_increment
    if model.pairs and analysis.control in ("arc-length", "displacement") and model.smoothing > 0:
        return MIN_INCREMENT_PER_SMOOTHING * model.smoothing
    return None


def follow(
    model: BeamModel, scene: object, progress: Callable[[object], None] | None,
    max_steps: int | None = None, refine: object | None = None,
) -> PathPass:
    """Follow the nonlinear path of ``scene`` on ``model``.

    ``refine``: the follower's refinement hook (:mod:`sandwich.solver.path.switching`) with
    the model the path is on as its ``model`` (:class:`~sandwich.beam.one_pass.OnePass`): the
    pass's model is the one the path ended on.

    ``max_steps`` given (an ``auto`` rerun, which checks a pass at lower levels): also stop
    where the path comes back through zero load (``stop_at_load_reversal``): the pass it checks
    never did, so the rerun has met another path, and it is then dropped as one that stops
    short (fig. 5's scene with a 45 mm debond at x = 70: a level-3 rerun went on to λ = −2447
    for 156 steps, 23 s of the run's 33).
    """
    from sandwich.solver.path import PathOptions, follow_path

    a = scene.analysis
    caps = {} if max_steps is None else {"max_steps": int(max_steps),
                                         "stop_at_load_reversal": True}
    options = PathOptions.from_analysis(a, min_increment=min_increment(model, a),
                                        desired_iterations=DESIRED_ITERATIONS,
                                        settling_allowance=scene.beam_model.settling_allowance,
                                        **caps)
    result = follow_path(model, options, list(model.probe_rows), progress, refine)
    states = list(result.states)
    if refine is not None:
        model = refine.model
    return PathPass(model, states, result.message, result.reached_target,
                    list(result.limit_points), warnings=list(result.warnings))


def follow_penalised(
    scene: object, elements: int | None, options: dict,
    progress: Callable[[object], None] | None, max_steps: int | None = None,
    refine: Callable[[BeamModel, dict], object] | None = None,
) -> PathPass:
    """Follow the path; rerun with a stiffer penalty while converged states penetrate too deep.

    ``options``: :func:`~sandwich.beam.build.build_model`'s; ``max_steps`` (default the
    scene's) caps the steps of each attempt; ``refine(model, options)`` makes each attempt's
    refinement hook (:func:`follow`).
    """
    raised: list[float] = []
    model = build_model(scene, elements=elements, gauss=scene_gauss_orders(scene), **options)
    while True:
        hook = None if refine is None else refine(model, options)
        path = follow(model, scene, progress, max_steps, hook)
        model = path.model
        pen, bound = states_penetration(model, path.states), model.penetration_bound()
        if pen <= bound or len(raised) == PENALTY_RESTARTS:
            path.penalties_raised = raised
            return path
        raised.append(model.penalty)
        penalty = model.penalty * PENALTY_GROWTH * pen / bound
        options = {**options, "contact_penalty": penalty}
        if progress is not None:
            progress(PathNote(f"contact penalty raised to {penalty:.4g} N/mm³: following the "
                              "path again"))
        model = build_model(scene, elements=elements, gauss=scene_gauss_orders(scene), **options)


def max_penetration(model: BeamModel, displacements: list[np.ndarray]) -> float:
    """Deepest contact penetration (mm) over states given by their free DOFs."""
    return max((c.max_penetration for u in displacements
                for c in model.contact_summary(u).values()), default=0.0)


def states_penetration(model: BeamModel, states: list[PathState]) -> float:
    """Deepest contact penetration (mm) over ``states``, from their path columns if kept."""
    return max((s.extra["max_penetration"] if "max_penetration" in s.extra
                else max_penetration(model, [s.u]) for s in states), default=0.0)
