"""``solve(scene)``: the 2D reference on the equilibrium path, as a :class:`Solution`."""

from __future__ import annotations

import time

import numpy as np

from sandwich.fracture import growth_onset
from sandwich.growth.cohesive import cohesive_growing, cohesive_summary, process_zone_warnings
from sandwich.plane2d.beside import Beside, can_run_beside
from sandwich.plane2d.cohesive import growth_columns, lip_element_length
from sandwich.plane2d.core_crushing import CoreCrushing, CoreState, crushing_warning
from sandwich.plane2d.fracture import VcctEvaluator, history_columns
from sandwich.plane2d.mesh_error import (
    coarser_level,
    mesh_estimate,
    mesh_warnings,
    not_measured,
    plane2d_tolerances,
)
from sandwich.plane2d.model import Model2D, build_model
from sandwich.plane2d.profiles import ProfileSampler
from sandwich.results import InterruptedSolve, PathNote, Profile, Solution, StepRecord
from sandwich.results.fracture import column_names
from sandwich.scene import Scene
from sandwich.solver.path import PathOptions, PathState, follow_path, solve_linear

MODEL_NAME = "2d"
PENETRATION_BOUND = 1e-3  # penetration allowed, a fraction of the thinner face (docs/contact.md)
PROGRESS_EVERY = 10  # the mesh estimate's coarser path is told every this many steps


def build_scene_mesh(scene: Scene, level: str | None = None, refine: int | None = None):
    """The scene's LayeredMesh from :mod:`sandwich.meshes` (level/refine default to the scene's)."""
    from sandwich.meshes import build_mesh

    return build_mesh(scene, level=level, refine=refine)


def solve(scene: Scene, progress=None, level: str | None = None, refine: int | None = None,
          mesh=None, penalty: float | None = None, keep_states: bool = False,
          closure_length: float | None = None, estimate: bool | None = None) -> Solution:
    """Solve ``scene`` with the 2D plane-stress reference.

    Parameters
    ----------
    scene
        The problem.
    progress
        Called with every converged path state (``step``, ``load_factor``, ``probes``).
    level, refine
        Mesh resolution (default: the scene's ``[reference2d]``).
    mesh
        A ready ``LayeredMesh`` (or an object with its arrays) instead of building one.
    penalty
        Contact penalty (N/mm³) instead of the scene's or the default.
    closure_length
        VCCT closure length Δ (mm) of the energy release rate at the debond tips
        (:mod:`sandwich.plane2d.fracture`); default ``[reference2d] closure_length``, else the
        thinner face's thickness.
    keep_states
        Keep the model and the displacement vector of every converged state on the returned
        solution (attribute ``reference2d_states``) for :func:`sandwich.plane2d.write_fields`.
    estimate
        Estimate the mesh's error at the target by solving the path again at the next coarser
        level (:mod:`sandwich.plane2d.mesh_error`; summary ``mesh_error``); default
        ``[reference2d] error_estimate``. Not with a ready ``mesh``.
    """
    t0 = time.perf_counter()
    level = scene.reference2d.level if level is None else level
    refine = scene.reference2d.refine if refine is None else refine
    given_mesh = mesh is not None
    wanted = scene.reference2d.error_estimate if estimate is None else estimate
    options = dict(penalty=penalty, closure_length=closure_length)
    against = coarser_level(level, refine)
    beside = None
    if wanted and not given_mesh and against is not None and can_run_beside():
        beside = Beside(solve, scene, against, options)  # the coarser path, while this one runs
        if progress is not None:
            progress(PathNote(f"estimating the mesh's error: the path at level {against} "
                              "runs in a second process beside this one", restart=False))
    try:
        # without a process beside, the path's model is released before the coarser path runs
        # (its memory is not held twice)
        solution = _solve_path(scene, progress, level, refine, mesh, penalty, keep_states,
                               closure_length)
    except BaseException:
        if beside is not None:
            beside.stop()
        raise
    if wanted:
        try:
            entry = _mesh_error(scene, solution, level, refine, given_mesh, progress, options,
                                beside)
        except KeyboardInterrupt as exc:
            if beside is not None:
                beside.stop()
            if type(exc) is not KeyboardInterrupt:  # a study's time limit goes on up as it is
                raise
            # a user's Ctrl-C: the path reached its target, it is the answer, written as such
            solution.extra["mesh_error"] = not_measured(
                "interrupted while the path was followed again one level coarser", against,
                plane2d_tolerances(scene))
            solution.warnings.append("interrupted while estimating the mesh's error: the path "
                                     "reached its target, its mesh error is not measured")
            solution.wall_seconds = time.perf_counter() - t0
            raise InterruptedSolve(solution) from exc
        solution.extra["mesh_error"] = entry
        solution.warnings.extend(mesh_warnings(entry, level, refine))
        solution.wall_seconds = time.perf_counter() - t0
    return solution


def _solve_path(scene: Scene, progress, level: str, refine: int, mesh, penalty: float | None,
                keep_states: bool, closure_length: float | None) -> Solution:
    """The path at one resolution: :func:`solve` without the mesh estimate."""
    t0 = time.perf_counter()
    if mesh is None:
        from mpi4py import MPI

        comm = MPI.COMM_WORLD
        if comm.size == 1:
            mesh = build_scene_mesh(scene, level, refine)
        else:  # gmsh on rank 0 only; every rank needs the arrays (lips, profile stations)
            mesh = comm.bcast(build_scene_mesh(scene, level, refine) if comm.rank == 0 else None,
                              root=0)
    model = build_model(scene, mesh, penalty=penalty)
    system = model.system
    vcct = VcctEvaluator(model, closure_length if closure_length is not None
                         else scene.reference2d.closure_length)
    names = [p.name for p in scene.probes]
    a = scene.analysis
    rows: list[StepRecord] = []
    # The linear 2D run solves with the tangent at u = 0, where the penalty contact counts the
    # touching lips as active (sandwich/plane2d/contact.py): the lips are tied normally and cannot
    # open, so a debond behaves nearly as bonded and its G is wrong (measured on the peel couple
    # of tests/fracture: G 0.07 of the closed form at 12x the load). No G then.
    tied_lips = a.kind == "linear" and bool(vcct.tips)
    states: list[tuple[int, float, np.ndarray]] = []
    crushing = CoreCrushing(model)
    core_states: list[tuple[int, float, CoreState]] = []  # (step, λ, the core) of every state

    def record(state: PathState) -> None:
        contact = system.contact_summary()
        core = crushing.at(state.u)
        core_states.append((int(state.step), float(state.load_factor), core))
        extra = {"max_penetration": contact["max_penetration"],
                 "max_contact_pressure": contact["max_contact_pressure"],
                 "max_sliding": contact["max_sliding"],
                 "core_min_stretch": core.min_stretch,
                 "core_ellipticity": core.ellipticity,
                 "cuts": float(state.cuts)}
        if state.negative_pivots is not None:
            extra["negative_pivots"] = float(state.negative_pivots)
        extra.update(growth_columns(system.cohesive_lips))  # of the damage just committed
        if tied_lips:  # G columns left empty (G_warning below says why)
            extra.update({n: None for t in vcct.tips for n in column_names(t.debond, t.tip)})
        else:
            extra.update(history_columns(vcct.evaluate(state.u)))  # G at the tips, N/mm
        state.extra = dict(extra)  # streamed with the state: an interrupted run keeps them
        rows.append(StepRecord(state.step, float(state.load_factor),
                               {n: float(state.probes[n]) for n in names},
                               int(state.iterations), extra))
        states.append((state.step, float(state.load_factor), np.array(state.u)))
        if progress is not None:
            progress(state)

    limit_points = []
    roundoff = newton_tol = None
    if a.kind == "linear":
        u1 = solve_linear(system, 1.0)
        lam = _linear_target(scene, system, u1)
        for step, lf in ((0, 0.0), (1, lam)):
            u = lf * u1
            system.commit(u, lf)
            record(PathState(step, u, lf, 0 if step == 0 else 1,
                             {n: system.dot(system.probe_vector(n), u) for n in names}, None))
        converged, message = True, f"linear solution scaled to λ = {lam:.6g}"
        warnings: list[str] = []
    else:
        # Newton cannot get the residual below the round-off of its own evaluation: ask for the
        # scene's tolerance or that bound, whichever is larger (reported in the summary)
        roundoff = system.residual_roundoff_bound()
        newton_tol = max(a.tol, roundoff)
        options = PathOptions.from_analysis(a, tol=newton_tol)
        result = follow_path(system, options, names, progress=record)
        converged, message = result.reached_target, result.message
        limit_points, warnings = result.limit_points, list(result.warnings)

    profiles = _profiles(model, scene, states)
    penetration = max((r.extra["max_penetration"] for r in rows), default=0.0)
    extra: dict[str, object] = {
        "cells": int(len(mesh.cells)),
        "level": getattr(mesh, "level", level or scene.reference2d.level),
        "refine": int(getattr(mesh, "refine", refine or 0)),
        "contact_penalty": model.penalty,
        "max_penetration": float(penetration),
        "max_sliding": float(max((r.extra["max_sliding"] for r in rows), default=0.0)),
        "max_penetration_over_face_thickness": float(
            penetration / min(scene.top.thickness, scene.bottom.thickness)),
        "newton_iterations": int(sum(r.iterations for r in rows)),
        "stress_measure": "second Piola-Kirchhoff, reference frame",
        "mpi_ranks": int(model.disc.mesh.comm.size),
        "vcct_closure_length": float(vcct.closure_length),
        "vcct_closure_over_tip_element": (float(vcct.closure_over_element)
                                          if vcct.tips else None),
    }
    if tied_lips:
        extra["G_warning"] = ("linear analysis: the 2D model's linear solve ties the debond lips "
                              "(contact linearised at closed lips), so the debonds cannot open "
                              "and G is not computed (columns left empty); use kind = "
                              "\"nonlinear\" for G and for any debond that opens")
    elif vcct.supported_tips():
        extra["G_warning"] = (f"a support acts within the closure length ahead of tip(s) "
                              f"{', '.join(vcct.supported_tips())}: its reaction enters the "
                              "VCCT force, G there is not reliable")
    if cohesive_growing(scene):  # the tips the path moved
        size = lip_element_length(system.cohesive_lips)
        entry, grown = cohesive_summary(scene, rows, size)
        extra["debond_growth"] = entry
        warnings += grown + process_zone_warnings(entry, size,
                                                  "a finer [reference2d] level or refine")
    elif onset := growth_onset(scene, rows):  # debonds with a toughness: first step G >= G_c
        extra["debond_growth"] = onset
    if core_states:
        extra["core_min_stretch"] = min(c.min_stretch for _, _, c in core_states)
        extra["core_min_ellipticity"] = min(c.ellipticity for _, _, c in core_states)
        crushed = [k for k, (_, _, c) in enumerate(core_states) if c.ellipticity <= 0.0]
        extra["core_crushed_at_step"] = core_states[crushed[0]][0] if crushed else None
        if crushed:
            step, lf, core = core_states[crushed[0]]
            before = core_states[crushed[0] - 1][:2] if crushed[0] > 0 else None
            warnings.append(crushing_warning(core, step, lf, before))
    bound = PENETRATION_BOUND * min(scene.top.thickness, scene.bottom.thickness)
    if penetration > bound:
        warnings.append(f"contact penetration {penetration:.3g} mm exceeds {bound:.3g} mm "
                        f"({PENETRATION_BOUND:g} x the face thickness; raise "
                        f"reference2d.contact_penalty, now {model.penalty:.4g} N/mm^3)")
    if newton_tol is not None:
        extra["newton_tol"] = float(newton_tol)
        extra["residual_roundoff_bound"] = float(roundoff)
    solution = Solution(MODEL_NAME, scene.name, rows, profiles, bool(converged), message,
                        limit_points, time.perf_counter() - t0, int(system.global_size), extra,
                        warnings=warnings)
    if states:  # the last state for ParaView (VTU + PVD), gathered to every rank
        from sandwich.plane2d.fields import field_frame

        step, lf, u_last = states[-1]
        solution.fields = [field_frame(model, step, lf, u_last)]
    if keep_states:  # not part of the result contract: kept off ``extra`` (summary.json)
        solution.reference2d_states = (model, states)
    return solution


def _mesh_error(scene: Scene, solution: Solution, level: str, refine: int, given_mesh: bool,
                progress, options: dict, beside: Beside | None = None) -> dict[str, object]:
    """``summary.json`` → ``mesh_error`` of ``solution``: the path again one level coarser.

    ``beside``: that path, followed in a second process while this one ran (stopped unheard
    where the run's path did not reach its target); else it is followed now.
    """
    against, held = coarser_level(level, refine), plane2d_tolerances(scene)
    if given_mesh:
        return not_measured("a mesh given to the solve has no coarser level", held=held)
    if against is None:
        return not_measured(f"level {level} at refine = {refine} has no coarser level to "
                            "compare with (a medium or fine run has)", held=held)
    if not solution.converged:
        if beside is not None:
            beside.stop()
        return not_measured(f"the path did not reach the target ({solution.message})",
                            against, held)
    if beside is not None:
        if progress is not None:
            progress(PathNote(f"mesh estimate: waiting for the path at level {against} "
                              "beside this one", restart=False))
        coarse = beside.result()
        if isinstance(coarse, str):
            return not_measured(coarse, against, held)
        return {**mesh_estimate(solution, coarse, against, held), "coarser_path": "beside"}
    told = None
    if progress is not None:
        steps = len(solution.history) - 1
        progress(PathNote(f"estimating the mesh's error: the path again at level {against} "
                          f"(this one took {steps} steps)", restart=False))

        def told(state) -> None:  # the coarser path's states are not this run's: told, not kept
            if state.step and state.step % PROGRESS_EVERY == 0:
                progress(PathNote(f"mesh estimate: level {against} at step {state.step}, "
                                  f"λ = {state.load_factor:.6g}", restart=False))
    coarse = solve(scene, progress=told, level=against.level, refine=against.refine,
                   estimate=False, **options)
    return {**mesh_estimate(solution, coarse, against, held), "coarser_path": "after"}


def _linear_target(scene: Scene, system, u1: np.ndarray) -> float:
    """Load factor of the linear solution: the until load factor, or the λ hitting until_value."""
    a = scene.analysis
    if a.until_load_factor is not None:
        return float(a.until_load_factor)
    if a.until_probe is not None:
        w1 = system.dot(system.probe_vector(a.until_probe), u1)
        if w1 == 0.0:
            raise ValueError(f"probe {a.until_probe!r} does not move under the load")
        return float(a.until_value) / w1
    return 1.0


def _profiles(model: Model2D, scene: Scene, states) -> list[Profile]:
    if not states:
        return []
    every = scene.reference2d.profile_every
    chosen = [s for s in states if every and s[0] % every == 0 and s[0] > 0]
    if not chosen or chosen[-1][0] != states[-1][0]:
        chosen.append(states[-1])
    sampler = ProfileSampler(model)
    return [Profile(step, sampler.sample(u)) for step, _lf, u in chosen]
