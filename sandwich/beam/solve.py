"""Solve a scene with the beam element: linear, or nonlinear path following.

:func:`solve` returns the project's common :class:`~sandwich.results.Solution` (model "beam");
:func:`run` also hands back the model and the converged states, for field reconstruction
(:mod:`sandwich.beam.fields`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from sandwich.beam.contact_search import NORMAL_SIGN
from sandwich.beam.core_levels import (
    DORFLER_FRACTION,
    LevelChoice,
    auto_levels,
    level_counts,
    lookahead_levels,
    raise_levels,
    state_shares,
    transfer,
    zone_levels,
)
from sandwich.beam.fields import profile_columns, section_fields
from sandwich.beam.fracture import (
    beam_tips,
    column_names,
    level_warning,
    release_columns,
    uniform_tip_levels,
)
from sandwich.beam.model import (
    CONTACT_COLUMNS,
    BeamModel,
    beam_mesh,
    build_model,
    contact_columns,
)
from sandwich.beam.quadrature import EXACT_ORDER
from sandwich.results import FieldFrame, LimitPoint, Profile, Solution, StepRecord
from sandwich.scene import Scene

# Passes of the linear step's active-set iteration: at least this many, and at least
# ACTIVE_SET_PASSES_PER_PAIR per contact pair. Where the contact zone is narrower than the
# debond, each pass releases the zone's edge pair alone (it alone is in tension) and the edge
# walks one pair per pass: fig. 5's scene with a 65-80 mm top debond needs 52-58 passes over
# 140-152 pairs (the flat 50 stopped every `auto` run and linear analysis of it).
MAX_ACTIVE_SET_PASSES = 50
ACTIVE_SET_PASSES_PER_PAIR = 2
MIN_INCREMENT_PER_SMOOTHING = 0.01  # default path increment floor / contact smoothing width s
# Newton iterations per step at which the path follower keeps the increment (its default is 5).
# The beam's corrector needs 4-5 iterations even on short steps of the smooth c2 path (tol 1e-8
# plus the increment test), so 5 held the arc near 0.25 mm: 69 steps to −15 mm. With 8: 22 steps,
# 168 iterations, same end state (λ 352.811). The floor (_min_increment) is unchanged.
DESIRED_ITERATIONS = 8
# A path whose converged states penetrate deeper than the model's bound (issue: 1e-3 × the face
# thickness) is rerun with the penalty raised by PENALTY_GROWTH × (penetration / bound), at most
# PENALTY_RESTARTS times. Penetration grows as the element length shrinks where a face presses
# a point force on the core (a clamped mouth: fig. 7 c4 at 480 elements), so no fixed penalty
# meets the bound at every resolution.
PENALTY_RESTARTS = 2
PENALTY_GROWTH = 2.0
# "auto" core levels along a path: the last converged state says where the core wants more
# levels (sandwich.beam.core_levels.state_shares); the path is rerun with those raised and the
# change of the end load is the estimate; reruns continue while it exceeds the tolerance, at most
# CORE_RECHECKS times. A rerun may take at most RERUN_STEP_FACTOR times the steps of the pass it
# checks (at least RERUN_MIN_STEPS): a raised model that needs far more steps has met a path the
# checked pass did not see (default scene, level 4 over the debond: a limit point at −6 mm the
# 2D model does not have, 240+ steps), and the kept answer is then the checked pass, said so.
CORE_RECHECKS = 3
RERUN_STEP_FACTOR = 4
RERUN_MIN_STEPS = 30
# Each raise is first tried on the checked pass's end state alone (solve._end_state): Newton
# with up to END_STATE_BACKTRACKS halvings per correction, END_STATE_ITERATIONS corrections.
END_STATE_CHECKS = True
END_STATE_MATCH = 1e-5  # relative: the pass at the checked levels must end at the check's load
END_STATE_ITERATIONS = 40
END_STATE_BACKTRACKS = 20
# A check whose change δ is at most BELOW_FRACTION × the tolerance says the levels below it are
# within the tolerance themselves: those levels are reported, with the estimate BELOW_FACTOR × δ
# (≈ δ / (1 − ρ) for a raise that halves the error, ρ = ½ — an estimate, not a bound: what it
# reads against level 4: docs/beam_element.md), and the path at the raised ones is not followed.
BELOW_FRACTION = 0.25
BELOW_FACTOR = 2.0


@dataclass(frozen=True)
class ConvergedState:
    """A converged equilibrium state on the free DOFs."""

    step: int
    load_factor: float
    u: np.ndarray
    iterations: int
    probes: dict[str, float]
    extra: dict[str, float | None] = field(default_factory=dict)  # the path's state columns


@dataclass
class BeamRun:
    """A solve's result with the model and every converged state."""

    solution: Solution
    model: BeamModel
    states: list[ConvergedState]
    nonlinear: bool


def _gauss_orders(scene: object) -> dict[str, tuple[int, int]]:
    """Per-layer Gauss orders: the exact rule, raised (never lowered) by the scene's options."""
    opts = getattr(scene, "beam_model", None)
    gx, gz = getattr(opts, "gauss_x", None), getattr(opts, "gauss_z", None)
    orders = {}
    for layer, (nx, nz) in EXACT_ORDER.items():
        orders[layer] = (max(nx, gx or 0), max(nz, gz or 0))
    return orders


def _linear_contact_matrix(model: BeamModel, active: list[np.ndarray]) -> sp.csr_matrix:
    """Penalty stiffness of the linearised gap g ≈ s_n (w_face − w_core) on active pairs."""
    n = model.dof_map.n_full
    K = sp.csr_matrix((n, n))
    for pairs, on in zip(model.pairs, active, strict=True):
        s_n = NORMAL_SIGN[pairs.interface]
        grad = np.array([0.0, s_n, 0.0, -s_n, 0.0, 0.0])  # ∂g_lin/∂(pair DOFs)
        blocks = (model.penalty * pairs.area * on)[:, None, None] * np.outer(grad, grad)
        rows = np.repeat(pairs.dofs[:, :, None], 6, axis=2)
        cols = np.repeat(pairs.dofs[:, None, :], 6, axis=1)
        K = K + sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n))
    T = model.dof_map.T
    return (T.T @ K @ T).tocsr()


def _pattern_keys(model: BeamModel, K: sp.csr_matrix) -> np.ndarray | None:
    """Row · n + column of each entry of ``K`` (increasing), if ``K`` is on the model's pattern.

    :meth:`~sandwich.beam.model.BeamModel.tangent` returns its matrices on that pattern, explicit
    zeros included. None for any other pattern.
    """
    p = model.pattern
    if (K.shape != (p.n, p.n) or K.indices.size != p.indices.size
            or not np.array_equal(K.indptr, p.indptr) or not np.array_equal(K.indices, p.indices)):
        return None
    rows = np.repeat(np.arange(p.n, dtype=np.int64), np.diff(p.indptr))
    return rows * p.n + p.indices


def _plus_on_pattern(K0: sp.csr_matrix, C: sp.csr_matrix, keys: np.ndarray
                     ) -> sp.csr_matrix | None:
    """``K0 + C`` on ``K0``'s pattern (``keys``: :func:`_pattern_keys`), or None.

    ``C`` (the linearised contact's few entries) is added at its slots of a copy of ``K0``'s
    values: each entry is K0_ij + C_ij, what scipy's sum gives, without the sum's new pattern
    (it drops ``K0``'s explicit zeros) and its embedding back into the model's
    (:meth:`~sandwich.beam.model.BeamModel.factorize`): 4 ms of a 10 ms pass at level 3. None
    where an entry of ``C`` lies outside the pattern.
    """
    C = sp.csr_matrix(C)
    C.sum_duplicates()
    n = K0.shape[0]
    wanted = np.repeat(np.arange(n, dtype=np.int64), np.diff(C.indptr)) * n + C.indices
    slots = np.searchsorted(keys, wanted)
    if np.any(slots >= keys.size) or not np.array_equal(keys[slots], wanted):
        return None
    data = K0.data.copy()
    data[slots] += C.data  # (canonical C: each slot once)
    return sp.csr_matrix((data, K0.indices, K0.indptr), shape=K0.shape)


def linear_solution(model: BeamModel, load_factor: float) -> tuple[np.ndarray, int]:
    """Small-displacement solution at ``load_factor`` with unilateral contact on debonds.

    The tangent at u = 0 plus the penalty on the linearised gap of the pairs in contact; the
    active set is iterated to a fixed point. Returns the free DOFs and the number of passes.
    """
    u, passes, _ = _active_set_solution(model, load_factor)
    return u, passes


def _active_set_solution(
    model: BeamModel, load_factor: float, start: list[np.ndarray] | None = None
) -> tuple[np.ndarray, int, list[np.ndarray]]:
    """:func:`linear_solution` from the active set ``start`` (default: every pair open).

    Also returns the active set it settled on. The start changes the passes, not the answer:
    a fixed point is a stationary point of ½uᵀK₀u − fᵀu + ½ε Σ A ⟨−g_lin⟩², strictly convex
    for a positive definite K₀, so there is one (pairs with a gap exactly zero aside). The auto
    core levels solve the same scene at several levels with the same pairs, and each solve
    starts from the last one's set.
    """
    K0 = model.tangent(np.zeros(model.size))
    keys = _pattern_keys(model, K0)
    f = load_factor * model.f_ref
    active = [np.zeros(p.size, dtype=bool) for p in model.pairs]
    if start is not None and [a.shape for a in start] == [a.shape for a in active]:
        active = [np.array(a, dtype=bool) for a in start]
    most = max(MAX_ACTIVE_SET_PASSES, ACTIVE_SET_PASSES_PER_PAIR * sum(p.size for p in model.pairs))
    for passes in range(1, most + 1):
        C = _linear_contact_matrix(model, active)
        K = _plus_on_pattern(K0, C, keys) if keys is not None else None
        fac = model.factorize(K0 + C if K is None else K)
        u = np.asarray(fac.solve(f), dtype=float)
        u_full = model.expand(u)
        new = []
        for pairs in model.pairs:
            v = u_full[pairs.dofs]
            new.append(NORMAL_SIGN[pairs.interface] * (v[:, 1] - v[:, 3]) < 0.0)
        if all(np.array_equal(a, b) for a, b in zip(active, new, strict=True)):
            return u, passes, active
        active = new
    raise RuntimeError(f"linear contact active set did not settle in {most} passes")


def _toward_target(
    model: BeamModel, probe: str, target: float, start: list[np.ndarray] | None = None
) -> tuple[float, np.ndarray, int, list[np.ndarray]]:
    """The sign of λ whose linear solution moves ``probe`` towards ``target``.

    Returns (sign, the linear solution at λ = sign, active-set passes, its active set).
    Unilateral contact makes the response homogeneous for λ > 0 only, so both signs are solved
    if need be, each from the active set ``start`` (:func:`_active_set_solution`).
    """
    row = model.probe_vector(probe)
    for sign in (1.0, -1.0):
        u1, passes, active = _active_set_solution(model, sign, start)
        if float(row @ u1) * target > 0:
            return sign, u1, passes, active
    raise ValueError(f"probe {probe!r} does not move under the scene's loads")


def _linear_states(model: BeamModel, scene: object) -> tuple[list[ConvergedState], str]:
    a = scene.analysis
    names = list(model.probe_rows)
    probe = {n: model.probe_vector(n) for n in names}
    zero = ConvergedState(0, 0.0, np.zeros(model.size), 0, {n: 0.0 for n in names})
    if a.until_probe is not None:
        sign, u1, passes, _ = _toward_target(model, a.until_probe, a.until_value)
        λ = sign * a.until_value / float(probe[a.until_probe] @ u1)
        u = u1 * (λ / sign)
        message = f"linear solution scaled to {a.until_probe} = {a.until_value:g}"
    else:
        λ = a.until_load_factor if a.until_load_factor is not None else 1.0
        u, passes = linear_solution(model, λ)
        message = f"linear solution at load factor {λ:g}"
    state = ConvergedState(1, float(λ), u, passes, {n: float(probe[n] @ u) for n in names})
    model.commit(u, λ)
    return [zero, state], message


def linear_responses(scene: Scene, cores: Sequence[int]) -> list[float]:
    """The linear step's response at each uniform core level of ``cores``, in that order.

    The model is the one :func:`run` builds for ``scene`` with ``[beam_model] core`` set to the
    level (its ``core_zones`` kept). The response is the until probe's value c·u at the unit load
    factor that moves it towards its target (the linear stiffness, as :func:`_linear_states`
    scales it), else the compliance fᵀu at λ = ±1 (the sign of ``until_load_factor``). Each
    unilateral active-set solve starts from the set the one before settled on: the iteration
    has one fixed point (:func:`_active_set_solution`), so each level's set is the one it finds
    from every pair open — knock-down cases of fig. 5 at level 3: 7, 6 and 4 passes instead of
    7, 14 and 18 — and its solution the same to round-off (the envelope's order depends on the
    first matrix a model factorises).
    """
    a = scene.analysis
    options = scene_model_options(scene)
    out: list[float] = []
    settled = None
    for core in cores:
        s = dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model,
                                                                      core=int(core)))
        levels = choose_core_levels(s, None, options).levels
        model = build_model(s, gauss=_gauss_orders(s), **{**options, "core_level": levels})
        if a.until_probe is not None:
            _, u1, _, settled = _toward_target(model, a.until_probe, a.until_value, settled)
            out.append(float(model.probe_vector(a.until_probe) @ u1))
        else:
            sign = -1.0 if a.until_load_factor is not None and a.until_load_factor < 0 else 1.0
            u1, _, settled = _active_set_solution(model, sign, settled)
            out.append(float(model.f_ref @ u1))
    return out


def _min_increment(model: BeamModel, analysis: object) -> float | None:
    """Smallest path increment: the scene's, else 0.01 × the contact regularisation width s (mm).

    A contact pair opening next to a buckling face is a sharp limit point of width ~s
    (:mod:`sandwich.beam.contact`); the path follower's own floor (1e-4 × the first increment,
    ~1e-3 mm for the fig. 7 scenes) is too coarse to turn there (measured: 5e-5 mm fails on the
    jump guard at the turn of C3/C4 at 40 elements, 1e-5 mm passes). The floor applies to arc-length
    and displacement control (increments in mm) of models with contact pairs; load control and
    bonded models keep the follower's default.
    """
    if analysis.min_increment is not None:
        return analysis.min_increment
    if model.pairs and analysis.control in ("arc-length", "displacement") and model.smoothing > 0:
        return MIN_INCREMENT_PER_SMOOTHING * model.smoothing
    return None


def scene_model_options(scene: object) -> dict[str, object]:
    """The :func:`~sandwich.beam.model.build_model` options a scene's ``[beam_model]`` sets.

    Grading, face membrane, contact search, core basis and faces (the element choices; the
    core levels are chosen by :func:`choose_core_levels`).
    """
    bm = scene.beam_model
    return {"grading": getattr(bm, "grading", "graded"),
            "face_membrane": getattr(bm, "face_membrane", "averaged"),
            "contact_search": getattr(bm, "contact_search", "closest-point"),
            "core_basis": getattr(bm, "core_basis", "sublayers"),
            "face_stretch": getattr(bm, "faces", "stretch") == "stretch"}


def run(
    scene: Scene,
    progress: Callable[[object], None] | None = None,
    *,
    elements: int | None = None,
    model_options: dict | None = None,
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
        Further keyword arguments of :func:`~sandwich.beam.model.build_model` (e.g. ``grading``).
    """
    t0 = time.perf_counter()
    a = scene.analysis
    if a.kind not in ("linear", "nonlinear"):
        raise ValueError(f"analysis kind must be 'linear' or 'nonlinear', got {a.kind!r}")
    bm = scene.beam_model
    options = {**scene_model_options(scene), **(model_options or {})}
    choice = choose_core_levels(scene, elements, options)
    nonlinear = a.kind == "nonlinear"
    limit_points: list[LimitPoint] = []
    raised: list[float] = []
    stopped_rerun, capped = "", False
    if not nonlinear:
        model = build_model(scene, elements=elements, gauss=_gauss_orders(scene),
                            **{**options, "core_level": choice.levels})
        states, message = _linear_states(model, scene)
        converged = True
    else:
        previous: float | None = None  # end load at the levels the current ones raised
        kept: tuple | None = None  # the last pass that reached the target, and its levels
        raises = 0
        checks = END_STATE_CHECKS and a.until_probe is not None
        pending: tuple | None = None  # the end-state check this pass must confirm
        below_estimate: float | None = None  # of the levels below a check within BELOW_…
        while True:
            budget = None if kept is None else min(
                int(a.max_steps), max(RERUN_MIN_STEPS, RERUN_STEP_FACTOR * (len(kept[0][1]) - 1)))
            result = _follow_penalised(scene, elements, {**options, "core_level": choice.levels},
                                       progress, max_steps=budget)
            model, states, message, converged, limit_points, raised = result
            last = states[-1]
            if choice.how != "auto" or last.load_factor == 0.0:
                break
            if pending is not None:
                checked_load, start = pending
                pending = None
                if not converged or abs(last.load_factor - checked_load) > \
                        END_STATE_MATCH * abs(last.load_factor):
                    # The path at these levels does not end at the continued end state (another
                    # equilibrium at the same deflection: fig. 6, fig. 4's rerun stopping short):
                    # the checks are not the paths' ends here. From the pass they started at,
                    # follow the path after every raise, as without them.
                    checks, below_estimate = False, None
                    kept, first, previous, raises = start
                    if not np.array_equal(first, choice.levels):
                        choice.passes.append({"stage": f"path step {last.step}",
                                              "elements_per_level": level_counts(choice.levels),
                                              "load_factor": last.load_factor,
                                              "reached": converged, "estimate": None,
                                              "end_state_confirmed": False})
                        choice.levels = first
                        continue
            if not converged and kept is not None:
                # The raised path stopped short of the target: keep the pass it was checking.
                choice.passes.append({"stage": f"path step {last.step}",
                                      "elements_per_level": level_counts(choice.levels),
                                      "load_factor": last.load_factor, "reached": False,
                                      "estimate": None, "stopped": message})
                stopped_rerun = message
                (model, states, message, converged, limit_points, raised), choice.levels, \
                    choice.estimate = kept
                break
            if previous is not None:  # the change the last raise made is the estimate
                choice.estimate = (abs(last.load_factor - previous) / abs(last.load_factor)
                                   if converged else None)
            if below_estimate is not None:  # confirmed: the levels below a check within it
                choice.estimate = below_estimate
            choice.passes.append({"stage": f"path step {last.step}",
                                  "elements_per_level": level_counts(choice.levels),
                                  "load_factor": last.load_factor, "reached": converged,
                                  "estimate": choice.estimate if previous is not None else None})
            tol, top = float(bm.tolerance), int(bm.max_core_level)
            if not converged or not np.any(choice.levels < top) or raises >= CORE_RECHECKS or (
                    choice.estimate is not None and previous is not None
                    and choice.estimate <= tol):
                break
            kept = (result, choice.levels.copy(), choice.estimate)
            levels = _raised_levels(scene, elements, options, model, last, choice.levels, top)
            if levels is None:
                capped = True
                break
            raises += 1
            previous = last.load_factor
            choice.levels = levels
            if checks and _at_probe_target(a, last):
                # Before following the path at the raised levels, continue its end state into
                # them: where the path at those levels ends there (the pass that follows
                # confirms it, else the checks are dropped), a raise that proves too small
                # costs one Newton solve instead of a path.
                start = (kept, levels, previous, raises)
                found, complete, below = _check_end_states(scene, elements, options, model,
                                                           last, levels, previous, raises, tol,
                                                           top, choice.passes)
                # A check that does not converge says the raised path ends far from the checked
                # one (c2: 736.8 → 268.3); the later raises' checks failed as well on every
                # shipped scene (c2, fig. 4), so none is tried after it.
                checks = complete
                if below is not None and found is None:
                    # this pass's own levels are within the tolerance: it is the answer
                    choice.levels, choice.estimate = kept[1], below
                    break
                if found is not None:
                    choice.levels, previous, raises, checked_load = found
                    pending = (checked_load, start)
                    below_estimate = below
            if progress is not None:
                progress(CoreRecheck(level_counts(choice.levels)))
        if stopped_rerun:
            message += (f"; WARNING: the rerun with raised core levels stopped ({stopped_rerun}); "
                        "this is the pass it was checking")
        if choice.how == "auto" and not converged and np.any(choice.levels > 1):
            # The path at the chosen levels stopped short: the paper's element is the fallback
            # (extremes map: thin faces, L/h = 5 and load x2 reach their target only at level 1).
            stopped = message
            fallback = _follow_penalised(scene, elements, {**options, "core_level": 1}, progress)
            if fallback[3]:
                model, states, message, converged, limit_points, raised = fallback
                choice.levels = np.ones_like(choice.levels)
                choice.estimate = None
                choice.passes.append({"stage": "fallback to level 1",
                                      "elements_per_level": level_counts(choice.levels),
                                      "load_factor": states[-1].load_factor, "reached": True,
                                      "estimate": None})
                message += (f"; WARNING: with auto core levels the path stopped ({stopped}); "
                            "this is the paper's element (core level 1), its error not estimated")
        if raised:
            message += (f" (contact penalty raised from {raised[0]:.4g} to {model.penalty:.4g} "
                        f"N/mm³ in {len(raised)} rerun(s) of the path: the converged states "
                        f"penetrated deeper than {model.penetration_bound():.3g} mm)")
    if choice.how == "auto" and converged and np.any(choice.levels > 1) and (
            choice.estimate is None or choice.estimate > float(bm.tolerance)):
        said = ("could not be estimated" if choice.estimate is None else
                f"{100 * choice.estimate:.2g} % exceeds the tolerance "
                f"{100 * float(bm.tolerance):.2g} %")
        reruns = f", {_path_passes(choice) - 1} rerun(s) of the path" if nonlinear else ""
        message += (f"; WARNING: the core's estimated error {said} (max_core_level "
                    f"{bm.max_core_level}{reruns})")
    if capped:
        message += (f"; the debond and load zones are at max_core_level {bm.max_core_level}: "
                    "what a further raise there would change is not measured")
    solution = _solution(scene, model, states, nonlinear, converged, message, limit_points)
    solution.extra["contact_penalty_reruns"] = len(raised)
    solution.extra.update(_growth_summary(scene, solution))
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
    }
    solution.wall_seconds = time.perf_counter() - t0
    return BeamRun(solution=solution, model=model, states=states, nonlinear=nonlinear)


def _raised_levels(scene: object, elements: int | None, options: dict, model: BeamModel,
                   last: ConvergedState, levels: np.ndarray, top: int) -> np.ndarray | None:
    """The levels a rerun checks after ``last``, or None where the zones are at the cap.

    The elements carrying DORFLER_FRACTION of the state shares (:func:`state_shares`) are raised,
    and so is every element over a debond or a load patch: the residual points at singular spots
    (debond tips, point supports), where a raise hardly moves the load, while the load error of
    a buckled debond lives in the contact strip all along it (fig. 5: residual shares 81 % at the
    tips, load change there 0.5 %, true error 12 %). None when those zones cannot be raised: a
    rerun would raise only elements where the load error does not live, and its small change
    would read as convergence (demo scene: 0.05 % for a true 4.8 %).
    """
    up = build_model(scene, elements=elements, gauss=_gauss_orders(scene),
                     **{**options, "core_level": lookahead_levels(levels)})
    shares = state_shares(model, last.u, last.load_factor, up)
    marked = raise_levels(levels, shares, DORFLER_FRACTION * shares.sum(), top)
    zone = np.minimum(levels + 1, top)
    inside = _local_zone_elements(scene, model)
    # no level change next to a debond tip: it biases G (docs/fracture.md)
    raised = uniform_tip_levels(model, beam_tips(scene, model),
                                np.where(inside, np.maximum(marked, zone), marked))
    if np.any(inside) and not np.any(raised[inside] > levels[inside]):
        return None
    return raised


def _at_probe_target(analysis: object, state: ConvergedState) -> bool:
    """Whether ``state`` ended the path at the until probe's target (not at a load target)."""
    target = float(analysis.until_value)
    return abs(state.probes[analysis.until_probe] - target) <= 1e-4 * max(abs(target), 1e-12)


def _check_end_states(
    scene: object, elements: int | None, options: dict, model: BeamModel,
    last: ConvergedState, levels: np.ndarray, previous: float, raises: int, tol: float,
    top: int, passes: list[dict],
) -> tuple[tuple[np.ndarray, float, int, float] | None, bool, float | None]:
    """Raise on end states alone while the change they show exceeds ``tol``.

    From ``last`` (the end of the pass at the levels below ``levels``, end load ``previous``),
    each check continues the end state into the raised levels (:func:`_end_state`); while its
    change exceeds ``tol`` (and raises remain, the zones are not at the cap) the levels are
    raised again from it. Returns the levels of the last check that converged, the end load at
    the levels below them, the raises count and the check's end load — the pass that follows
    must end there — or None if the first check fails; whether no check failed; and, where the
    last check's change δ is at most ``BELOW_FRACTION × tol``, the estimate ``BELOW_FACTOR × δ``
    of the levels below it, which are then the ones returned (None: the checked pass's own
    levels, no path to follow). Each check is listed in ``passes``.
    """
    found = None
    cur, state = model, last
    while True:
        checked = _end_state(scene, elements, options, cur, state, levels)
        if checked is None:
            return found, False, None
        up, state = checked
        estimate = abs(state.load_factor - previous) / abs(state.load_factor)
        entry = {"stage": f"end state at step {last.step}",
                 "elements_per_level": level_counts(levels),
                 "load_factor": state.load_factor, "reached": True,
                 "estimate": estimate, "iterations": state.iterations}
        passes.append(entry)
        if estimate <= BELOW_FRACTION * tol:
            entry["levels_below_reported"] = True
            return found, True, BELOW_FACTOR * estimate
        found = (levels, previous, raises, state.load_factor)
        if estimate <= tol or not np.any(levels < top) or raises >= CORE_RECHECKS:
            return found, True, None
        higher = _raised_levels(scene, elements, options, up, state, levels, top)
        if higher is None:
            return found, True, None
        cur, previous, levels, raises = up, state.load_factor, higher, raises + 1


def _end_state(
    scene: object, elements: int | None, options: dict, model: BeamModel,
    state: ConvergedState, levels: np.ndarray,
) -> tuple[BeamModel, ConvergedState] | None:
    """``state`` (at the until target) continued into the model at ``levels``, or None.

    The state is carried over (new enrichment amplitudes zero) and re-equilibrated at the same
    value of the until probe by Newton with a backtracking line search
    (:func:`sandwich.solver.newton.newton_correct`, ``backtracks``): the equilibrium of the
    raised model nearest the checked one, which is where the raised path ends when it stays on
    the same branch. None if that Newton fails or the state penetrates deeper than the bound.
    """
    from sandwich.solver.controls import ProbeConstraint
    from sandwich.solver.newton import NewtonSettings, newton_correct
    from sandwich.solver.system import inner_product

    a = scene.analysis
    up = build_model(scene, elements=elements, gauss=_gauss_orders(scene),
                     **{**options, "core_level": levels})
    c = np.asarray(up.probe_vector(a.until_probe), dtype=float)
    settings = NewtonSettings(tol=float(a.tol), max_iterations=END_STATE_ITERATIONS,
                              force_floor=float(np.linalg.norm(up.f_ref)) * abs(state.load_factor),
                              backtracks=END_STATE_BACKTRACKS)
    res = newton_correct(up, transfer(state.u, model, up), state.load_factor,
                         ProbeConstraint(c, float(a.until_value), inner_product(up)), settings)
    if not res.converged or res.load_factor == 0.0:
        return None
    if _max_penetration(up, [res.u]) > up.penetration_bound():
        return None
    probes = {n: float(np.asarray(up.probe_vector(n)) @ res.u) for n in up.probe_rows}
    return up, ConvergedState(state.step, float(res.load_factor), res.u, res.iterations, probes)


def _path_passes(choice: LevelChoice) -> int:
    """How many times auto followed the path (its passes after the linear-step ones)."""
    return sum(p["stage"].startswith("path step") for p in choice.passes)


def _growth_summary(scene: object, solution: Solution) -> dict[str, object]:
    """Summary entry of the debond growth criterion (debonds with a toughness only)."""
    from sandwich.fracture import growth_onset

    onset = growth_onset(scene, solution.history)
    return {"debond_growth": onset} if onset else {}


def choose_core_levels(scene: object, elements: int | None, options: dict) -> LevelChoice:
    """The core level of every element: given, from ``[beam_model]``, or chosen by "auto".

    ``options["core_level"]`` (an integer or one level per element) overrides the scene. Else
    ``[beam_model] core`` is a level or ``"auto"`` (:func:`~sandwich.beam.core_levels.auto_levels`
    on the linear step against ``tolerance``, up to ``max_core_level``); ``core_zones`` raise the
    levels over their stretches in both cases.
    """
    bm = scene.beam_model
    n = elements if elements is not None else getattr(bm, "elements", 240)
    mesh_options = {k: options[k] for k in ("grading", "growth", "size_ratio") if k in options}
    mesh = beam_mesh(scene, n, **mesh_options)
    given = options.get("core_level")
    if given is not None:
        levels = np.broadcast_to(np.asarray(given, dtype=int), (mesh.n_elements,)).copy()
        return LevelChoice(levels=levels, how="explicit")
    core = getattr(bm, "core", 1)
    zones = tuple(getattr(bm, "core_zones", ()))
    if core != "auto":
        return LevelChoice(levels=zone_levels(mesh, int(core), zones), how="explicit")
    gauss = _gauss_orders(scene)
    floor = zone_levels(mesh, 1, zones)

    built: dict[bytes, BeamModel] = {}  # the first level choice is the floor's model again

    def build(levels: np.ndarray) -> BeamModel:
        levels = np.maximum(levels, floor)
        key = levels.astype(np.int64).tobytes()
        if key not in built:
            built[key] = build_model(scene, elements=n, gauss=gauss,
                                     **{**options, "core_level": levels})
        return built[key]

    base = build(floor)
    sign, first = _load_sign(base, scene)
    settled: list[list[np.ndarray]] = []  # the last linear solve's active set
    solved: dict[int, np.ndarray] = {}
    if first is not None:  # the floor at λ = sign, from every pair open: solved for the sign
        solved[id(base)], active = first
        settled.append(active)

    def solve_linear(model: BeamModel) -> np.ndarray:
        if id(model) not in solved:
            u, _, active = _active_set_solution(model, sign, settled[-1] if settled else None)
            settled[:] = [active]
            solved[id(model)] = u
        return solved[id(model)]

    choice = auto_levels(build, solve_linear, mesh.n_elements,
                         float(getattr(bm, "tolerance", 0.01)),
                         int(getattr(bm, "max_core_level", 3)), probe=scene.analysis.until_probe)
    # no level change next to a debond tip: it biases G (docs/fracture.md)
    choice.levels = uniform_tip_levels(base, beam_tips(scene, base),
                                       np.maximum(choice.levels, floor))
    return choice


def _local_zone_elements(scene: object, model: BeamModel) -> np.ndarray:
    """Elements over a debonded stretch or a load patch, widened by a core thickness."""
    margin = scene.core.thickness
    spans = [(d.start, d.end) for d in scene.debonds if d.end > d.start]
    spans += [(ld.x - ld.width / 2, ld.x + ld.width / 2) for ld in scene.loads]
    a, b = model.mesh.x[:-1], model.mesh.x[1:]
    inside = np.zeros(model.mesh.n_elements, dtype=bool)
    for lo, hi in spans:
        inside |= (b > lo - margin) & (a < hi + margin)
    return inside


def _load_sign(
    model: BeamModel, scene: object
) -> tuple[float, tuple[np.ndarray, list[np.ndarray]] | None]:
    """Sign of the load factor the analysis heads for (unilateral contact is not odd in λ).

    Also returns the linear solution at λ = sign and its active set where finding the sign
    solved it (an until probe), else None: the level choice's first solve is that one.
    """
    a = scene.analysis
    if a.until_probe is not None:
        try:
            sign, u1, _, active = _toward_target(model, a.until_probe, a.until_value)
            return sign, (u1, active)
        except ValueError:  # the path follower says so in its own words
            return 1.0, None
    if a.until_load_factor is not None and a.until_load_factor < 0:
        return -1.0, None
    return 1.0, None


@dataclass(frozen=True)
class CoreRecheck:
    """Progress event: the path is rerun with raised core levels (the bar restarts)."""

    elements_per_level: dict[str, int]
    step: int = 0
    load_factor: float = 0.0

    @property
    def message(self) -> str:
        """What a user is told."""
        return ("checking the core levels: rerunning the path with elements per core level "
                f"{self.elements_per_level}")


def _follow_penalised(
    scene: object, elements: int | None, options: dict,
    progress: Callable[[object], None] | None, max_steps: int | None = None,
) -> tuple[BeamModel, list[ConvergedState], str, bool, list[LimitPoint], list[float]]:
    """Follow the path; rerun with a stiffer penalty while converged states penetrate too deep.

    ``max_steps`` (default the scene's) caps the steps of each attempt.
    """
    raised: list[float] = []
    model = build_model(scene, elements=elements, gauss=_gauss_orders(scene), **options)
    while True:
        states, message, converged, limit_points = _follow(model, scene, progress, max_steps)
        pen, bound = _states_penetration(model, states), model.penetration_bound()
        if pen <= bound or len(raised) == PENALTY_RESTARTS:
            return model, states, message, converged, limit_points, raised
        raised.append(model.penalty)
        penalty = model.penalty * PENALTY_GROWTH * pen / bound
        model = build_model(scene, elements=elements, gauss=_gauss_orders(scene),
                            **{**options, "contact_penalty": penalty})


def _follow(
    model: BeamModel, scene: object, progress: Callable[[object], None] | None,
    max_steps: int | None = None,
) -> tuple[list[ConvergedState], str, bool, list[LimitPoint]]:
    """Follow the nonlinear path of ``scene`` on ``model``: states, message, reached, limits.

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
    options = PathOptions.from_analysis(a, min_increment=_min_increment(model, a),
                                        desired_iterations=DESIRED_ITERATIONS,
                                        settling_allowance=scene.beam_model.settling_allowance,
                                        **caps)
    result = follow_path(model, options, list(model.probe_rows), progress)
    states = [ConvergedState(s.step, s.load_factor, s.u, s.iterations, dict(s.probes),
                             dict(s.extra)) for s in result.states]
    return states, result.message, result.reached_target, list(result.limit_points)


def _max_penetration(model: BeamModel, displacements: list[np.ndarray]) -> float:
    """Deepest contact penetration (mm) over states given by their free DOFs."""
    return max((c.max_penetration for u in displacements
                for c in model.contact_summary(u).values()), default=0.0)


def _contact_columns(model: BeamModel, u: np.ndarray, nonlinear: bool) -> dict[str, float]:
    """A state's contact history columns, evaluated (a linear analysis: none, zeros)."""
    return contact_columns(model.contact_summary(u) if nonlinear else {})


def _states_penetration(model: BeamModel, states: list[ConvergedState]) -> float:
    """Deepest contact penetration (mm) over ``states``, from their path columns if kept."""
    return max((s.extra["max_penetration"] if "max_penetration" in s.extra
                else _max_penetration(model, [s.u]) for s in states), default=0.0)


def solve(scene: Scene, progress: Callable[[object], None] | None = None) -> Solution:
    """Solve ``scene`` with the beam element; see :func:`run`."""
    return run(scene, progress).solution


def _field_frame(model: BeamModel, state: ConvergedState, nonlinear: bool) -> FieldFrame:
    """Faces and core of ``state`` on one quad grid (``section_fields``) as a ParaView frame.

    Point data: σ_x, σ_z, τ, von Mises (MPa, 2nd Piola-Kirchhoff); cell data: ``region``
    (0 core, 1 top face, 2 bottom face) and ``core_level`` (0 on faces). Points are reference
    (x, z), displacement (u, w) in mm.
    """
    f = section_fields(model, state.u, nonlinear=nonlinear)
    return FieldFrame(
        step=state.step, load_factor=state.load_factor, points=f.points, cells=f.cells,
        displacement=f.displacement,
        point_data={"sigma_x": f.sigma_x, "sigma_z": f.sigma_z, "tau": f.tau,
                    "von_mises": f.von_mises},
        cell_data={"region": f.region.astype(float), "core_level": f.core_level.astype(float)},
    )


def _solution(
    scene: object, model: BeamModel, states: list[ConvergedState], nonlinear: bool,
    converged: bool, message: str, limit_points: list[LimitPoint],
) -> Solution:
    history = []
    max_pen = max_slide = 0.0
    tips = beam_tips(scene, model)  # energy release rate at every debond tip (N/mm)
    names = {n for t in tips for n in column_names(t.debond, t.tip)}
    for s in states:
        # the path's columns of this state (model.state_columns), else evaluated
        contact = ({n: s.extra[n] for n in CONTACT_COLUMNS} if set(CONTACT_COLUMNS) <=
                   s.extra.keys() else _contact_columns(model, s.u, nonlinear))
        max_pen = max(max_pen, contact["max_penetration"])
        max_slide = max(max_slide, contact["max_sliding"])
        extra = {**contact,
                 **({n: s.extra[n] for n in names} if names <= s.extra.keys()
                    else release_columns(model, s.u, tips))}
        history.append(StepRecord(step=s.step, load_factor=s.load_factor, probes=dict(s.probes),
                                  iterations=s.iterations, extra=extra))
    every = int(getattr(getattr(scene, "beam_model", None), "profile_every", 0) or 0)
    chosen = [s for s in states if every and s.step % every == 0 and s is not states[-1]]
    chosen.append(states[-1])
    profiles = [Profile(step=s.step, columns=profile_columns(model, s.u, nonlinear))
                for s in chosen]
    fields = [_field_frame(model, s, nonlinear) for s in chosen]
    bound = model.penetration_bound()
    if max_pen > bound:
        message += (f"; WARNING: contact penetration {max_pen:.3g} mm exceeds "
                    f"{bound:.3g} mm (raise beam_model.contact_penalty)")
    return Solution(
        model="beam", scene=scene.name, history=history, profiles=profiles, converged=converged,
        message=message, limit_points=limit_points, wall_seconds=0.0, dofs=model.size,
        fields=fields,
        extra={
            "elements": model.mesh.n_elements,
            "nodes": model.mesh.n_nodes,
            "analysis": "nonlinear" if nonlinear else "linear",
            **{f"gauss_{layer}_{axis}": n for layer, orders in _gauss_orders(scene).items()
               for axis, n in zip(("x", "z"), orders, strict=True)},
            "contact_pairs": int(sum(p.size for p in model.pairs)),
            "contact_penalty": model.penalty,
            "max_penetration": max_pen,
            "penetration_bound": bound,
            "max_sliding": max_slide,
            "total_newton_iterations": int(sum(s.iterations for s in states)),
        },
    )
