"""Solve a scene with the beam element: linear, or nonlinear path following.

:func:`solve` returns the project's common :class:`~sandwich.results.Solution` (model "beam");
:func:`run` also hands back the model and the converged states, for field reconstruction
(:mod:`sandwich.beam.fields`). The core levels are chosen first
(:mod:`sandwich.beam.core_choice`); a nonlinear analysis follows the path once at fixed levels
(:mod:`sandwich.beam.path_pass`), or, with ``auto`` levels, once with the levels checked and
raised along it (:class:`~sandwich.beam.one_pass.OnePass`; or, with
``AutoSettings(one_pass=False)``, again after each raise:
:class:`~sandwich.beam.core_controller.CoreController`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sandwich.beam.build import build_model, scene_gauss_orders, scene_model_options
from sandwich.beam.core_choice import choose_core_levels
from sandwich.beam.core_controller import (
    AutoSettings,
    CoreController,
    level_1_fallback,
    path_passes,
)
from sandwich.beam.core_levels import LevelChoice, level_counts
from sandwich.beam.fracture import beam_tips, level_warning
from sandwich.beam.linear_step import linear_solution, toward_target
from sandwich.beam.model import BeamModel
from sandwich.beam.one_pass import OnePass, beam_tolerances
from sandwich.beam.path_pass import PathPass, follow_penalised
from sandwich.beam.solution import beam_solution, growth_summary
from sandwich.results import InterruptedSolve, Solution
from sandwich.scene import Scene
from sandwich.solver import PathState


@dataclass
class BeamRun:
    """A solve's result with the model and every converged state."""

    solution: Solution
    model: BeamModel
    states: list[PathState]
    nonlinear: bool


def solve(scene: Scene, progress: Callable[[object], None] | None = None) -> Solution:
    """Solve ``scene`` with the beam element; see :func:`run`."""
    return run(scene, progress).solution


def run(
    scene: Scene,
    progress: Callable[[object], None] | None = None,
    *,
    elements: int | None = None,
    model_options: dict | None = None,
    auto: AutoSettings | None = None,
) -> BeamRun:
    """Build the beam model of ``scene``, solve it, and return solution, model and states.

    Parameters
    ----------
    scene
        A :class:`sandwich.scene.Scene`.
    progress
        Per-step callback of the path follower (nonlinear analyses).
    elements
        Element count (default ``scene.beam_model.elements``).
    model_options
        Further keyword arguments of :func:`~sandwich.beam.build.build_model` (e.g. ``grading``).
    auto
        How ``auto`` core levels are re-checked along a nonlinear path (default
        :class:`~sandwich.beam.core_controller.AutoSettings`).
    """
    t0 = time.perf_counter()
    a = scene.analysis
    if a.kind not in ("linear", "nonlinear"):
        raise ValueError(f"analysis kind must be 'linear' or 'nonlinear', got {a.kind!r}")
    bm = scene.beam_model
    options = {**scene_model_options(scene), **(model_options or {})}
    choice = choose_core_levels(scene, elements, options)
    nonlinear = a.kind == "nonlinear"
    limit_points = []
    quantities: dict[str, dict] = {}
    raised: list[float] = []
    warnings: list[str] = []
    capped = interrupted = False
    if not nonlinear:
        model = build_model(scene, elements=elements, gauss=scene_gauss_orders(scene),
                            **{**options, "core_level": choice.levels})
        states, message = _linear_states(model, scene)
        converged = True
    else:
        if choice.how == "auto" and (auto or AutoSettings()).one_pass:
            path, capped, quantities = _one_pass(scene, elements, options, choice, progress)
        elif choice.how == "auto":
            controller = CoreController(scene, elements, options, choice, progress, auto)
            try:
                path = controller.run()
            except KeyboardInterrupt as exc:
                # a user's Ctrl-C only (a study's time limit, a subclass, goes on up as it is);
                # nothing to keep before a pass reached the target
                if type(exc) is not KeyboardInterrupt or controller.kept is None:
                    raise
                path, interrupted = controller.kept.path, True
                choice.levels, choice.estimate = controller.kept.levels, controller.kept.estimate
                warnings.append("interrupted while checking the core levels: this is the pass "
                                "that reached the target" + (
                                    ", its error not estimated" if choice.estimate is None
                                    else f", its estimated error {100 * choice.estimate:.2g} %"))
            capped = controller.capped
        else:
            path = follow_penalised(scene, elements, {**options, "core_level": choice.levels},
                                    progress)
        model, states, message = path.model, path.states, path.message
        converged, limit_points, raised = path.converged, path.limit_points, path.penalties_raised
        warnings += path.warnings
        if raised:
            message += (f" (contact penalty raised from {raised[0]:.4g} to {model.penalty:.4g} "
                        f"N/mm³ in {len(raised)} rerun(s) of the path: the converged states "
                        f"penetrated deeper than {model.penetration_bound():.3g} mm)")
    if choice.how == "auto" and converged and not interrupted and np.any(choice.levels > 1) and (
            choice.estimate is None or choice.estimate > float(bm.tolerance)):
        said = ("could not be estimated" if choice.estimate is None else
                f"{100 * choice.estimate:.2g} % exceeds the tolerance "
                f"{100 * float(bm.tolerance):.2g} %")
        reruns = (f", {path_passes(choice) - 1} rerun(s) of the path"
                  if nonlinear and path_passes(choice) > 1 else "")
        warnings.append(f"the core's estimated error {said} (max_core_level "
                        f"{bm.max_core_level}{reruns})")
    held = beam_tolerances(scene)
    warnings += quantity_warnings(quantities, held)
    if capped:
        message += (f"; the debond and load zones are at max_core_level {bm.max_core_level}: "
                    "what a further raise there would change is not measured")
    solution = beam_solution(scene, model, states, nonlinear, converged, message, limit_points)
    solution.warnings[:0] = warnings  # the path's and auto's first, then the solution's own
    solution.extra["contact_penalty_reruns"] = len(raised)
    solution.extra.update(growth_summary(scene, solution, model))
    if level_warning(model, beam_tips(scene, model)):
        solution.extra["G_warning"] = level_warning(model, beam_tips(scene, model))
    solution.extra["faces"] = "stretch" if options["face_stretch"] else "paper"
    solution.extra["face_membrane"] = options["face_membrane"]
    solution.extra["contact_search"] = options["contact_search"]
    solution.extra["core"] = {
        "how": choice.how, "basis": options["core_basis"],
        "levels": choice.zones(model.mesh), "estimated_error": choice.estimate,
        "passes": choice.passes, "zones_at_max_level": capped,
        "tolerance": getattr(bm, "tolerance", None) if choice.how == "auto" else None,
        "quantities": {name: {**parts, "estimated_error": _total(parts),
                              "tolerance": held[name]}
                       for name, parts in quantities.items()},
    }
    solution.wall_seconds = time.perf_counter() - t0
    if interrupted:
        raise InterruptedSolve(solution)
    return BeamRun(solution=solution, model=model, states=states, nonlinear=nonlinear)


def _one_pass(scene: Scene, elements: int | None, options: dict, choice: LevelChoice,
              progress: Callable[[object], None] | None) -> tuple[PathPass, bool, dict]:
    """The path at ``auto`` levels checked and raised along it (:class:`OnePass`).

    Returns the path, whether a check found the zones at ``max_core_level``, and per quantity
    at the target its estimate's shares: ``core_levels`` (:attr:`OnePass.quantities`) and
    ``element_length`` (:attr:`OnePass.lengths`, None where not measured); empty where no
    estimate was made there.

    Each penalty rerun of the path starts again at the linear step's levels. Where the path
    stops short, the paper's element is the fallback (:func:`level_1_fallback`).
    """
    initial = choice.levels.copy()
    hooks: list[OnePass] = []

    def hook(model: BeamModel, opts: dict) -> OnePass:
        choice.levels, choice.estimate = initial.copy(), None
        hooks.append(OnePass(scene, elements, opts, choice, model, progress))
        return hooks[-1]

    path = follow_penalised(scene, elements, {**options, "core_level": initial}, progress,
                            refine=hook)
    one = hooks[-1]
    quantities = {}
    if one.checked_at_target:
        lengths = one.lengths or {}
        quantities = {name: {"core_levels": value, "element_length": lengths.get(name)}
                      for name, value in one.quantities.items()}
    if not one.checked_at_target:
        choice.estimate = None  # the last check was not at the path's end
    choice.passes.append({"stage": f"path step {path.last.step}",
                          "elements_per_level": level_counts(choice.levels),
                          "load_factor": path.last.load_factor, "reached": path.converged,
                          "estimate": choice.estimate})
    path = level_1_fallback(scene, elements, options, choice, path, progress)
    return path, one.capped, quantities if choice.estimate is not None else {}


def _total(parts: dict[str, float | None]) -> float | None:
    """A quantity's estimate: its core levels' and element length's shares (None: one missing)."""
    values = list(parts.values())
    return None if any(v is None for v in values) else float(sum(values))


def quantity_warnings(quantities: dict[str, dict], held: dict[str, float]) -> list[str]:
    """What a run must say of its quantities' estimates at the target.

    The element length's share where not measured, or where a quantity's estimate (core levels
    plus element length) exceeds its tolerance — the core levels' part of the load and probes
    alone is said by the caller (``the core's estimated error …``).
    """
    out = []
    if quantities and all(q["element_length"] is None for q in quantities.values()):
        out.append("the element length's share of the error is not measured (the state did "
                   "not re-converge with every element split in two)")
        return out
    for name, parts in quantities.items():
        total, tol = _total(parts), held[name]
        if total is None or total <= tol:
            continue
        if name == "load and probes" and parts["core_levels"] > tol:
            continue  # said with the core levels' estimate
        out.append(f"{name}: estimated error {100 * total:.2g} % (core levels "
                   f"{100 * parts['core_levels']:.2g} %, element length "
                   f"{100 * parts['element_length']:.2g} %) exceeds {100 * tol:.2g} %"
                   + ("; more elements ([beam_model] elements) would lower it"
                      if parts["element_length"] > parts["core_levels"] else ""))
    return out


def _linear_states(model: BeamModel, scene: object) -> tuple[list[PathState], str]:
    """The linear analysis: the unloaded state and the linear step at the scene's target."""
    a = scene.analysis
    names = list(model.probe_rows)
    probe = {n: model.probe_vector(n) for n in names}
    zero = PathState(0, np.zeros(model.size), 0.0, 0, {n: 0.0 for n in names}, None)
    if a.until_probe is not None:
        sign, u1, passes, _ = toward_target(model, a.until_probe, a.until_value)
        λ = sign * a.until_value / float(probe[a.until_probe] @ u1)
        u = u1 * (λ / sign)
        message = f"linear solution scaled to {a.until_probe} = {a.until_value:g}"
    else:
        λ = a.until_load_factor if a.until_load_factor is not None else 1.0
        u, passes = linear_solution(model, λ)
        message = f"linear solution at load factor {λ:g}"
    state = PathState(1, u, float(λ), passes, {n: float(probe[n] @ u) for n in names}, None)
    model.commit(u, λ)
    return [zero, state], message
