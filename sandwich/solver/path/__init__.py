"""Path following of R(u, λ) = f_int(u) − λ f_ref = 0: load, displacement and arc-length control.

Every step goes from the last converged state ``(u₀, λ₀)`` with the factorised tangent ``K₀``
there and its load tangent ``t = K₀⁻¹ f_ref``:

- predictor along the tangent, ``(Δu, Δλ) = Δλ (t, 1)``, with ``Δλ`` fixed by the control:
  load ``Δλ = ±h``; displacement ``Δλ = ±h / (c·t)``; arc-length
  ``Δλ = σ h / √(t·t + ψ²)``;
- Newton corrector (:mod:`sandwich.solver.newton`) with the matching constraint
  (:mod:`sandwich.solver.controls`); ``h`` is the step increment in the units of the control
  (load factor, probe value, arc length) (:mod:`.attempts`);
- acceptance guard against jumps to a distant branch: the predictor may not be longer than
  ``max_predictor_growth`` × the previous step, and the corrector may not move farther than
  ``max_correction_ratio`` × the predictor length from the predictor (norm ``‖(Δu, ψΔλ)‖``);
- retrace / branch-jump guard (Crisfield's angle criterion applied to the converged step): the
  displacement increment ``Δu`` of a converged step may not make an obtuse angle with the
  previous step's (``cos < min_step_cosine``, 0 by default, in the system's inner product);
  such a step went back along the path or jumped to another branch. It is rejected like a
  failed one, and if the predictor itself pointed backwards the arc-length sign is flipped for
  the retry (Feng, Perić & Owen's displacement-only predictor criterion) (:mod:`.guards`);
- a converged step whose state the model declares inadmissible (optional
  ``system.admissible(u)`` returning a non-empty reason, e.g. an inverted element) is rejected
  like a failed one, so the path never leaves the model's domain of physical meaning;
- a model may add history columns to every accepted state (optional ``system.state_columns(u)``
  returning ``{name: value or None}``, kept in :attr:`PathState.extra`): a caller that
  streams the states (an interrupted run) then has them without the model's post-processing;
- a step's corrector gives up early once its residual has risen twice in a row above its first
  one (``DIVERGENCE_RISES``): the step is cut, and its retries run without that test (an
  iteration hunting for its contact set may rise so and still converge); once a corrector has
  converged after rising so, the test is off for the rest of the path (:mod:`.follower`);
- from its first failed corrector on, the path asks for contact-limited corrections
  (``LIMIT_AFTER_FAILURE``, ``NewtonSettings.limit_corrections``: a system with
  ``correction_limit(u, du)`` shortens a correction that would carry open contact pairs deep
  into the core, :mod:`sandwich.solver.newton`);
- on failure the increment is halved (``cuts``) down to ``min_increment``, then the path stops;
  on success it grows or shrinks by ``√(desired_iterations / iterations)`` within [½, 2]
  (it never grows after a cut step) and is clipped to [min_increment, max_increment], with
  the settling allowance of :mod:`.step_size`;
- a step that overshoots a stopping target is shortened onto it (:mod:`.targets`); where the
  arc collapses at a critical point, one step under control of the until probe is tried, and
  a branch a step left is walked to bound its top (:mod:`.rescue`);
- after each accepted step, a bifurcation or load extremum inside it is located
  (:mod:`.critical_points`), and a path that retraces its own branch stops
  (:class:`~.guards.ReturnGuard`), unless the system says it is path-dependent (optional
  ``system.path_dependent`` true: a state with history, such as a damaging interface, is not
  its (u, λ) alone, and unloading past a snap-back passes near states it was at before).

ψ (:attr:`PathOptions.arc_load_weight` × ``‖K(0)⁻¹ f_ref‖``) converts λ into displacement units,
so in the linear range the λ and u parts of the arc weigh the same.

Modules: :mod:`.options` (:class:`PathOptions`), :mod:`.records` (:class:`PathState`,
:class:`PathResult`, :class:`Trial`), :mod:`.state` (what the follower's parts share),
:mod:`.guards`, :mod:`.attempts`, :mod:`.targets`, :mod:`.step_size`, :mod:`.critical_points`,
:mod:`.rescue`, :mod:`.switching` (going on on a finer system a caller's hook hands over),
and :mod:`.follower` (:class:`PathFollower` composed of those parts, the step
loop, :func:`follow_path`).
"""

from sandwich.solver.path.attempts import LIMIT_AFTER_FAILURE
from sandwich.solver.path.follower import (
    DIVERGENCE_RISES,
    PathFollower,
    follow_path,
    solve_linear,
)
from sandwich.solver.path.guards import (
    INADMISSIBLE,
    JUMP_CORRECTION,
    JUMP_LOSS,
    RETRACE,
    RETURN_FRACTION,
    RETURN_STATES,
    ReturnGuard,
)
from sandwich.solver.path.options import CONTROLS, PathOptions
from sandwich.solver.path.records import PathResult, PathState, Refinement, Trial
from sandwich.solver.path.rescue import (
    RESCUE_FRACTION,
    RESCUE_MEMORY,
    WALK_LOSS,
    WALK_MIN_FRACTION,
    WALK_SLOPE_KEPT,
    WALK_TRIES,
)
from sandwich.solver.path.step_size import BENT, HALF_REACH, SETTLING_BEND, StepSize
from sandwich.solver.path.switching import RefineHook, SystemSwitch
from sandwich.solver.path.targets import CRITICAL_TARGET, CRITICAL_TARGET_CUTS, TARGET_SUBSTEP_CUTS

__all__ = [
    "BENT",
    "CONTROLS",
    "CRITICAL_TARGET",
    "CRITICAL_TARGET_CUTS",
    "DIVERGENCE_RISES",
    "HALF_REACH",
    "INADMISSIBLE",
    "JUMP_CORRECTION",
    "JUMP_LOSS",
    "LIMIT_AFTER_FAILURE",
    "RESCUE_FRACTION",
    "RESCUE_MEMORY",
    "RETRACE",
    "RETURN_FRACTION",
    "RETURN_STATES",
    "SETTLING_BEND",
    "TARGET_SUBSTEP_CUTS",
    "WALK_LOSS",
    "WALK_MIN_FRACTION",
    "WALK_SLOPE_KEPT",
    "WALK_TRIES",
    "PathFollower",
    "PathOptions",
    "PathResult",
    "PathState",
    "RefineHook",
    "Refinement",
    "ReturnGuard",
    "StepSize",
    "SystemSwitch",
    "Trial",
    "follow_path",
    "solve_linear",
]
