"""Path following of R(u, λ) = f_int(u) − λ f_ref = 0: load, displacement and arc-length control.

Every step goes from the last converged state ``(u₀, λ₀)`` with the factorised tangent ``K₀``
there and its load tangent ``t = K₀⁻¹ f_ref``:

- predictor along the tangent, ``(Δu, Δλ) = Δλ (t, 1)``, with ``Δλ`` fixed by the control:
  load ``Δλ = ±h``; displacement ``Δλ = ±h / (c·t)``; arc-length
  ``Δλ = σ h / √(t·t + ψ²)``;
- Newton corrector (:mod:`sandwich.solver.newton`) with the matching constraint
  (:mod:`sandwich.solver.controls`); ``h`` is the step increment in the units of the control
  (load factor, probe value, arc length);
- acceptance guard against jumps to a distant branch: the predictor may not be longer than
  ``max_predictor_growth`` × the previous step, and the corrector may not move farther than
  ``max_correction_ratio`` × the predictor length from the predictor (norm ``‖(Δu, ψΔλ)‖``);
- retrace / branch-jump guard (Crisfield's angle criterion applied to the converged step): the
  displacement increment ``Δu`` of a converged step may not make an obtuse angle with the
  previous step's (``cos < min_step_cosine``, 0 by default, in the system's inner product);
  such a step went back along the path or jumped to another branch. It is rejected like a
  failed one, and if the predictor itself pointed backwards the arc-length sign is flipped for
  the retry (Feng, Perić & Owen's displacement-only predictor criterion);
- a converged step whose state the model declares inadmissible (optional
  ``system.admissible(u)`` returning a non-empty reason, e.g. an inverted element) is rejected
  like a failed one, so the path never leaves the model's domain of physical meaning;
- a model may add history columns to every accepted state (optional ``system.state_columns(u)``
  returning ``{name: value or None}``, kept in :attr:`PathState.extra`): a caller that
  streams the states (an interrupted run) then has them without the model's post-processing;
- a step's corrector gives up early once its residual has risen twice in a row above its first
  one (``DIVERGENCE_RISES``): the step is cut, and its retries run without that test (an
  iteration hunting for its contact set may rise so and still converge); once a corrector has
  converged after rising so, the test is off for the rest of the path;
- from its first failed corrector on, the path asks for contact-limited corrections
  (``LIMIT_AFTER_FAILURE``, ``NewtonSettings.limit_corrections``: a system with
  ``correction_limit(u, du)`` shortens a correction that would carry open contact pairs deep
  into the core, :mod:`sandwich.solver.newton`);
- on failure the increment is halved (``cuts``) down to ``min_increment``, then the path stops;
  on success it grows or shrinks by ``√(desired_iterations / iterations)`` within [½, 2]
  (it never grows after a cut step) and is clipped to [min_increment, max_increment]. With
  ``settling_allowance`` k (off unless a model sets it; the beam sets 2), ``iterations`` is at
  most the corrector's iterations until its increment test first passed plus k, as long as no
  corrector of the path has failed and the load curve's last two steps turn by less than
  ``SETTLING_BEND``; a step so grown whose secant turns from its predictor by more is cut,
  and its converged state is then the step after the retry where it lies ahead of the
  retry's state within ``HALF_REACH`` × the increment the controller asks for then
  (docs/solver.md, "Settling iterations").

ψ (:attr:`PathOptions.arc_load_weight` × ``‖K(0)⁻¹ f_ref‖``) converts λ into displacement units,
so in the linear range the λ and u parts of the arc weigh the same.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass, field

import numpy as np

from sandwich.results import LimitPoint
from sandwich.solver.controls import ArcLengthConstraint, LoadConstraint, ProbeConstraint
from sandwich.solver.critical import (
    LOCATE_RTOL,
    MAX_CROSSINGS,
    MAX_SUBSTEPS,
    SAFEGUARD,
    BracketEnd,
    Crossing,
    crossed_eigenvalue,
    crossing_in,
    halved,
    locate_crossing,
    next_fraction,
)
from sandwich.solver.extrema import Extremum, SlopeEnd, located_in, turns_over
from sandwich.solver.limits import find_limit_points
from sandwich.solver.newton import (
    RECOVERABLE_ERRORS,
    RISING,
    NewtonResult,
    NewtonSettings,
    newton_correct,
)
from sandwich.solver.system import DiscreteSystem, Factorization, inner_product

__all__ = ["PathOptions", "PathResult", "PathState", "follow_path", "solve_linear"]

CONTROLS = ("load", "displacement", "arc-length")
INADMISSIBLE = "inadmissible state"  # prefix of the reason of a step rejected by admissible()
RETRACE = "the step turns back"  # prefix of the reason of a step rejected by the retrace guard
TARGET_SUBSTEP_CUTS = 6  # halvings of the sub-increment when a crossed target is hit directly
RESCUE_FRACTION = 0.05  # probe rescue: tried once the arc is cut below this × its largest so far
RESCUE_MEMORY = 5  # accepted steps remembered for the rescue step's probe change
#: The corrector's rising test (``NewtonSettings.divergence_rises``) on a step's attempts until
#: one fails by it; the retries of that step, the target's and the rescue's correctors run without,
#: and the rest of the path once a corrector converged after rising so (docs/beam_speed.md,
#: "Corrector attempts that diverge").
DIVERGENCE_RISES = 2
#: Contact-limited corrections (``NewtonSettings.limit_corrections``, for a system with
#: ``correction_limit``) from the first failed corrector of a path on (docs/solver.md,
#: "Contact-limited corrections").
LIMIT_AFTER_FAILURE = True
#: A step that crosses both a critical point and a stopping target, converging only after more
#: than ``desired_iterations``, is cut and retried up to this many times (then accepted): the
#: target is then approached by ordinary steps past the critical point (docs/solver.md, "The
#: last step across a critical point").
CRITICAL_TARGET_CUTS = 2
CRITICAL_TARGET = "a hard step across a critical point and the target"  # that cut's reason
BENT = "the load curve bends within a step the settling allowance grew"  # that cut's reason
#: The settling allowance (``PathOptions.settling_allowance``) weighs a step only where the
#: path's last two steps turn by less than this angle (radians) in the plane of its load curve
#: (:meth:`_Follower._straight`; docs/solver.md, "Settling iterations").
SETTLING_BEND = math.radians(2.0)
#: A step cut as BENT: its converged state is the step after the retry where that step is at
#: most this many times the increment the step-size controller asks for then
#: (:meth:`_Follower._bent_half`).
HALF_REACH = 1.25
#: A step of an arc-length path whose load change falls short of its tangent's by more than
#: this fraction, with the tangent's inertia unchanged, may have jumped to another branch past
#: a snap: the branch it left is walked as a rescued step's is (:meth:`_Follower._jumped`) ...
JUMP_LOSS = 0.3
#: ... or that leaves its tangent's line by more than this fraction of its projection on it
#: (an arc step: its corrector's distance over its predictor's length; the face's snapped
#: shape appears in the correction, at little loss of load).
JUMP_CORRECTION = 0.25
#: The walk along the branch a step jumped from (:meth:`_Follower._walk_branch_left`): its
#: correctors at most, and its smallest probe step as a fraction of its first.
WALK_TRIES = 16
WALK_MIN_FRACTION = 1.0 / 16.0
#: A walk that reaches the branch's end with its slope dw/dλ at least this fraction of the one
#: it started with ended abruptly (no turn of w ahead, where dw/dλ would fall to 0) ...
WALK_SLOPE_KEPT = 0.5
#: ... and its end is a top where the step's end state lies below the branch continued to its
#: probe value by more than this fraction of the end's load (load lost); or below the walk's
#: top, or the branch walked past it, by as much.
WALK_LOSS = 1e-3
#: A converged state closer than this fraction of a passed step's length to that step's chord
#: (in the norm ‖(u, ψλ)‖; a step the path has since travelled away from by its length) lies on
#: the path already followed; RETURN_STATES such states in a row: the path is retracing its
#: branch (:meth:`_Follower._returned`).
RETURN_FRACTION = 0.1
RETURN_STATES = 3


@dataclass
class PathOptions:
    """How to follow the path and when to stop.

    Attributes
    ----------
    control
        ``"load"``, ``"displacement"`` (of :attr:`control_probe`) or ``"arc-length"``.
    until_load_factor
        Stop when λ reaches this value (hit exactly).
    until_probe, until_value
        Stop when this probe reaches this value (hit within :attr:`target_tol`).
    max_steps
        Largest number of steps after state 0.
    initial_increment
        First increment in the units of the control; ``None``: 1/20 of the target estimated with
        the linear solution.
    min_increment, max_increment
        Bounds of the increment; ``None``: ``1e-4`` and ``10`` times the initial increment.
    tol
        Relative residual tolerance of Newton (the increment tolerance is ``√tol``).
    max_iterations
        Newton corrections allowed per step.
    desired_iterations
        Iteration count for which the increment is kept; fewer grow it, more shrink it.
    settling_allowance
        ``None`` (default): the controller weighs a step by all its corrector's iterations.
        A number k (the beam's ``[beam_model] settling_allowance``, 2 by default): until the
        path's first failed corrector and where the load curve is straight, by at most the
        iterations its increment test took to pass plus k (module docstring, step size;
        docs/solver.md "Settling iterations").
    control_probe
        Probe driven under displacement control (default: :attr:`until_probe`).
    arc_load_weight
        ψ / ‖K(0)⁻¹ f_ref‖ in the arc-length norm (0: cylindrical arc).
    max_correction_ratio, max_predictor_growth
        Jump guards (see the module docstring).
    min_step_cosine
        Retrace guard: a converged step whose displacement increment has a cosine below this
        with the previous step's is rejected (0: no turn by more than 90° in one step; ``-1``
        switches the guard off).
    probe_rescue
        Arc-length with an ``until_probe``: when the arc collapses at a critical point (a failed
        step cut below ``RESCUE_FRACTION`` of the largest increment accepted so far), try one
        step under control of that probe, as long as its largest change over the last
        ``RESCUE_MEMORY`` steps, towards the target (what a testing machine driving that point
        does); the message counts such steps.
    target_tol
        Relative tolerance on hitting ``until_value`` / ``until_load_factor`` by step cutting.
    target_accept
        If the crossed target cannot be hit within ``target_tol`` (corrector failures on the
        shortened steps), the closest state is still accepted as reaching the target when it
        misses by at most this (relative); the message says by how much.
    stop_at_load_reversal
        Stop (not reached) at the first converged state whose λ has the other sign than the
        state before's: the path has come back through the unloaded state. Off by default (a
        snap-through may cross λ = 0 and come back); the beam's ``auto`` core levels set it on
        its reruns, which check a pass that never crossed it (docs/solver.md).
    locate_critical_points
        Narrow a step across a bifurcation or a load extremum by equilibria solved inside it:
        shorter steps from the state before (the path's own predictor and corrector, up to
        :data:`~sandwich.solver.critical.MAX_SUBSTEPS`), aimed where the crossed eigenvalue is
        interpolated to be zero (the load curve's slope, for an extremum), until the located
        load moves by less than :data:`~sandwich.solver.critical.LOCATE_RTOL`. They are not
        path states (the path is the same with or without). Off by default: the point is then
        located within its step from the step's two states (no corrector; second order in the
        step for a bifurcation, :meth:`_Follower._locate_crossing`; fourth for an extremum,
        :meth:`_Follower._locate_extremum`). Named ``locate_bifurcations`` until 2026-12-05.
    """

    control: str = "load"
    until_load_factor: float | None = None
    until_probe: str | None = None
    until_value: float | None = None
    max_steps: int = 200
    initial_increment: float | None = None
    min_increment: float | None = None
    max_increment: float | None = None
    tol: float = 1e-8
    max_iterations: int = 25
    desired_iterations: int = 5
    settling_allowance: int | None = None
    control_probe: str | None = None
    arc_load_weight: float = 1.0
    max_correction_ratio: float = 1.0
    max_predictor_growth: float = 4.0
    min_step_cosine: float = 0.0
    probe_rescue: bool = True
    target_tol: float = 1e-6
    target_accept: float = 1e-3
    stop_at_load_reversal: bool = False
    locate_critical_points: bool = False

    @classmethod
    def from_analysis(cls, analysis: object, **overrides: object) -> PathOptions:
        """The options of a scene's ``[analysis]`` (:class:`sandwich.scene.Analysis`).

        ``overrides`` are a model's own settings on top (e.g. a Newton tolerance floor, an
        increment floor, ``desired_iterations``); ``None`` values among them are kept.
        """
        names = ("control", "until_load_factor", "until_probe", "until_value", "max_steps",
                 "initial_increment", "min_increment", "max_increment", "tol", "max_iterations",
                 "locate_critical_points")
        return cls(**{**{n: getattr(analysis, n) for n in names}, **overrides})

    def __post_init__(self) -> None:
        if self.control not in CONTROLS:
            raise ValueError(f"control must be one of {CONTROLS}, got {self.control!r}")
        if (self.until_probe is None) != (self.until_value is None):
            raise ValueError("until_probe and until_value go together")
        if self.control == "displacement" and self.driven_probe is None:
            raise ValueError("displacement control needs control_probe (or until_probe)")
        if self.until_load_factor == 0.0:
            raise ValueError("until_load_factor = 0 is the initial state")
        if self.until_value == 0.0:
            raise ValueError("until_value = 0 is the initial state")
        if self.max_steps < 1 or self.max_iterations < 1 or self.desired_iterations < 1:
            raise ValueError("max_steps, max_iterations and desired_iterations must be >= 1")
        if self.settling_allowance is not None and self.settling_allowance < 0:
            raise ValueError(f"settling_allowance must be >= 0 or None, got "
                             f"{self.settling_allowance}")
        if not -1.0 <= self.min_step_cosine < 1.0:
            raise ValueError(f"min_step_cosine must be in [-1, 1), got {self.min_step_cosine}")

    @property
    def driven_probe(self) -> str | None:
        """The probe driven under displacement control."""
        return self.control_probe or self.until_probe


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
    # within the step (:meth:`_Follower._locate_crossing`), None if it did not change or could
    # not be located
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


def solve_linear(system: DiscreteSystem, load_factor: float) -> np.ndarray:
    """Return the linear solution ``u = K(0)⁻¹ λ f_ref``."""
    fac = system.factorize(system.tangent(np.zeros(system.size)))
    return np.asarray(fac.solve(load_factor * np.asarray(system.f_ref, dtype=float)), dtype=float)


@dataclass
class _Trial:
    """A converged step candidate."""

    u: np.ndarray
    load_factor: float
    iterations: int
    factorization: Factorization
    rises: int = 0  # the corrector's longest run of rises above its first residual
    increment_iterations: int | None = None  # until its increment test first passed


def _cosine(a: tuple[float, float], b: tuple[float, float]) -> float | None:
    """The cosine of the angle between two plane vectors; None if either is zero or not finite."""
    na, nb = math.hypot(*a), math.hypot(*b)
    if not (0.0 < na < math.inf and 0.0 < nb < math.inf):
        return None
    return float((a[0] * b[0] + a[1] * b[1]) / (na * nb))


def _fmt_probes(probes: dict[str, float]) -> str:
    return ", ".join(f"{k} = {v:.6g}" for k, v in probes.items())


@dataclass
class _StepSize:
    """The step-size controller: the increment ``h`` in the units of the control and its bounds.

    Halved on a failed try (by :meth:`_Follower._converge_step`); after a converged step scaled
    by ``√(desired_iterations / iterations)`` within [½, 2], never grown after a cut, and kept
    in [``h_min``, ``h_max``].
    """

    h: float
    h_min: float
    h_max: float
    desired_iterations: int
    by_allowance: bool = False  # h was grown by the settling allowance's weighing

    @classmethod
    def start(cls, opt: PathOptions, h_auto: Callable[[], float]) -> _StepSize:
        """The first increment (the options', else ``h_auto()`` within the bounds given)."""
        h = opt.initial_increment
        if h is None:  # automatic, kept within the bounds the user gave
            h = h_auto()
            if opt.max_increment is not None:
                h = min(h, opt.max_increment)
            if opt.min_increment is not None:
                h = max(h, opt.min_increment)
        h_min = opt.min_increment if opt.min_increment is not None else 1e-4 * h
        h_max = opt.max_increment if opt.max_increment is not None else 10.0 * h
        if not (0.0 < h_min <= h <= h_max):
            raise ValueError(f"need 0 < min_increment <= increment <= max_increment, got "
                             f"{h_min}, {h}, {h_max}")
        return cls(h, h_min, h_max, opt.desired_iterations)

    def after(self, h_try: float, iterations: int, cuts: int, all_iterations: int) -> None:
        """The increment of the next step after one of ``h_try`` converged.

        ``iterations``: those the step is weighed by (:meth:`_Follower._weighed_iterations`),
        fewer than ``all_iterations`` where the settling allowance applied (:attr:`by_allowance`).
        """
        factor = math.sqrt(self.desired_iterations / max(iterations, 1))
        factor = min(max(factor, 0.5), 2.0)
        if cuts:
            factor = min(factor, 1.0)
        self.h = min(max(h_try * factor, self.h_min), self.h_max)
        self.by_allowance = iterations < all_iterations and not cuts


class _Follower:
    """State machine of :func:`follow_path` (one instance per call)."""

    failed_once = False  # a corrector of this path has failed
    curve_probe: tuple[str | None, float] = (None, 0.0)  # set once the linear solution is known
    bent: tuple[int, _Trial] | None = None  # (start step, converged state) of a step cut as BENT
    kept_half: _Trial | None = None  # that state, while it is the step being accepted

    @property
    def limit_corrections(self) -> bool:
        """Contact-limited corrections: on once a corrector of this path has failed."""
        return self.failed_once and LIMIT_AFTER_FAILURE

    def __init__(
        self,
        system: DiscreteSystem,
        options: PathOptions,
        probe_names: Sequence[str],
        progress: Callable[[PathState], None] | None,
    ) -> None:
        self.system = system
        self.dot = inner_product(system)  # global over MPI ranks if the system provides it
        self.opt = options
        self.progress = progress
        names = list(dict.fromkeys([*probe_names, *(n for n in (options.until_probe,
                                                                 options.driven_probe) if n)]))
        self.c = {n: np.asarray(system.probe_vector(n), dtype=float) for n in names}
        self.f_ref = np.asarray(system.f_ref, dtype=float)
        self.states: list[PathState] = []
        self._chord_lengths2: list[float] = []  # ‖(Δu, ψΔλ)‖² of each step, for _returned
        self._path_length: list[float] = [0.0]  # the path's length up to each state
        self._returns: list[tuple[int, float]] = []  # the last states on the path followed
        self.rescues: list[int] = []
        admissible = getattr(system, "admissible", None)
        self.admissible = admissible if callable(admissible) else None
        columns = getattr(system, "state_columns", None)
        self.state_columns = columns if callable(columns) else None

    # -- helpers -------------------------------------------------------------------------------
    def probes(self, u: np.ndarray) -> dict[str, float]:
        return {n: self.dot(c, u) for n, c in self.c.items()}

    def wnorm(self, du: np.ndarray, dlam: float) -> float:
        return math.sqrt(self.dot(du, du) + (self.psi * dlam) ** 2)

    def accept(self, u: np.ndarray, lam: float, its: int, neg: int | None,
               cuts: int) -> PathState:
        """Record and commit a converged state; return it (the caller yields it)."""
        state = PathState(len(self.states), u.copy(), float(lam), its, self.probes(u), neg, cuts)
        self.states.append(state)
        self.system.commit(state.u.copy(), state.load_factor)
        if self.state_columns is not None:
            state.extra.update(self.state_columns(state.u))
        return state

    def finish(self, reached: bool, message: str) -> PathResult:
        opt = self.opt
        if (opt.until_probe is not None and opt.until_load_factor is None and self.states
                and self.states[-1].load_factor < 0
                and not any(s.load_factor > 0 for s in self.states)):
            # The probe's target lies the other way from where the loads push it: the follower
            # heads for it with λ < 0, which a user rarely means (a sign slip in until or force).
            # (Not said of a path that came back through zero load: no sign slip sends it there.)
            message += (f"; WARNING: {opt.until_probe} heads for {opt.until_value:g} only "
                        "with λ < 0: every load's force is reversed (check the sign of "
                        "analysis.until's value and of the loads' force)")
        if self.rescues:
            message += (f" ({len(self.rescues)} step(s) taken under control of "
                        f"{self.opt.until_probe} where the arc collapsed at a critical point: "
                        f"step(s) {', '.join(map(str, self.rescues))})")
        return PathResult(self.states, reached, message, find_limit_points(self.states))

    # -- the run -------------------------------------------------------------------------------
    def run(self) -> PathResult:
        """Follow the path, calling ``progress`` with every converged state."""
        states = self.converged_states()
        while True:
            try:
                state = next(states)
            except StopIteration as done:
                return done.value
            if self.progress is not None:
                self.progress(state)

    def converged_states(self) -> Generator[PathState, None, PathResult]:
        """Yield every converged state (state 0 first); return the :class:`PathResult`.

        One step is :meth:`_converge_step` (predictor-corrector tries with cuts and the probe
        rescue), then the target strategies (:meth:`_hit_crossed_target`,
        :meth:`_target_reached`, :meth:`_near_target`), then the step-size controller
        (:class:`_StepSize`). The follower's state (last states, previous step, arc sign,
        rescue memory) lives in this object.
        """
        opt = self.opt
        u0 = np.zeros(self.system.size)
        try:
            fac = self.system.factorize(self.system.tangent(u0))
            t = np.asarray(fac.solve(self.f_ref), dtype=float)
        except RECOVERABLE_ERRORS as exc:
            yield self.accept(u0, 0.0, 0, None, 0)
            return self.finish(False, f"step 1: the initial tangent cannot be factorised ({exc})")
        first = self.accept(u0, 0.0, 0, fac.negative_pivots, 0)
        yield first
        tn = math.sqrt(self.dot(t, t))
        if not math.isfinite(tn) or tn == 0.0:
            return self.finish(False, "step 1: f_ref is zero or the linear solution is not finite")
        self.psi = opt.arc_load_weight * tn
        self.lam_est = self._target_load_estimate(t)
        self.curve_probe = self._curve_probe(t)
        self.rate_probe = opt.driven_probe or self.curve_probe[0]
        first.probe_rate = self._probe_rate(t)
        size = _StepSize.start(opt, lambda: self._auto_increment(t))
        self.prev_step: tuple[np.ndarray, float] | None = None
        self.recent: list[tuple[float, float]] = []  # (increment, until-probe change) accepted
        self.peak = 0.0  # largest accepted increment so far
        self.sigma = 1.0 if self.lam_est >= 0 else -1.0
        if opt.control == "displacement":  # move the probe the way the load would move it
            ct = self.dot(self.c[opt.driven_probe], t)
            self.sigma = math.copysign(1.0, ct * self.lam_est) if ct != 0.0 else 1.0
        self.newton = NewtonSettings(tol=opt.tol, max_iterations=opt.max_iterations,
                                     psi=self.psi)
        self.divergence_rises = DIVERGENCE_RISES  # off once a corrector that rose so converged

        while len(self.states) - 1 < opt.max_steps:
            last = self.states[-1]
            step = last.step + 1
            if opt.control == "arc-length":
                self.sigma = self._arc_direction(t, last)
            outcome = self._converge_step(size, last, t, step)
            if isinstance(outcome, str):
                return self.finish(False, outcome)
            trial, h_try, direct, cuts = outcome
            crossed = ""
            if not direct:
                trial, h_try, crossed = self._hit_crossed_target(trial, h_try, last, t)
            self.prev_step = (trial.u - last.u, trial.load_factor - last.load_factor)
            if opt.until_probe is not None:
                dv = self._value(opt.until_probe, trial.u, 0.0) - last.probes[opt.until_probe]
                self.recent = [*self.recent, (h_try, dv)][-RESCUE_MEMORY:]
                self.peak = max(self.peak, h_try)
            fac_before, fac = fac, trial.factorization
            state = self.accept(trial.u, trial.load_factor, trial.iterations,
                                fac.negative_pivots, cuts)
            yield state
            if opt.stop_at_load_reversal and trial.load_factor * last.load_factor < 0:
                return self.finish(False, (
                    f"step {step}: the path came back through zero load (λ {last.load_factor:.6g}"
                    f" → {trial.load_factor:.6g}); stopped there (stop_at_load_reversal)"))
            back = self._returned(state)
            if back:
                return self.finish(False, back)
            try:
                t_next = np.asarray(fac.solve(self.f_ref), dtype=float)
            except RECOVERABLE_ERRORS as exc:  # pragma: no cover - factorization succeeded
                return self.finish(False, f"step {step + 1}: load tangent failed ({exc})")
            state.probe_rate = self._probe_rate(t_next)
            self._locate_extremum(state, last, t, t_next)
            if (self.rescues and self.rescues[-1] == step) or self._jumped(last, state, t):
                self._walk_branch_left(state, last, t)
            self._locate_crossing(state, last, fac_before, fac, t)
            t = t_next
            done = self._target_reached()
            if done:
                return self.finish(True, done)
            if crossed:
                return self._finish_crossed(crossed)
            kept, self.kept_half = self.kept_half, None
            if trial is kept:
                # its corrector's iterations were a whole bent step's, from the state before:
                # the increment stays as the retry's left it, not grown
                size.by_allowance = False
            else:
                size.after(h_try, self._weighed_iterations(trial), cuts, trial.iterations)
        s = self.states[-1]
        return self.finish(False, (
            f"max_steps = {opt.max_steps} reached at λ = {s.load_factor:.6g} "
            f"({_fmt_probes(s.probes)}) before the target"))

    def _converge_step(self, size: _StepSize, last: PathState, t: np.ndarray,
                       step: int) -> tuple[_Trial, float, bool, int] | str:
        """Try steps from ``last``, halving the increment on failure, with one probe rescue.

        A converged trial across a critical point and the stopping target that needed more than
        ``desired_iterations`` counts as a failure for its first ``CRITICAL_TARGET_CUTS`` tries
        (:meth:`_hard_across_target`). Returns the converged trial, its increment, whether it
        hit a controlled target directly, and the number of cuts; or, when the increment would
        go below its floor, the message saying where and why the path stops.
        """
        opt = self.opt
        cuts = 0
        rescued = False
        rises = self.divergence_rises  # the corrector's rising test, until it has cut this step
        limited_failed = False  # a limited attempt of this step failed: the rest without
        while True:
            h_try, direct, sign = self._clip_to_target(size.h, last)
            if sign is not None:  # towards a directly controlled target
                self.sigma = sign
            limit = self.limit_corrections and not limited_failed
            kept = self._bent_half(last, h_try) if cuts == 0 and not direct else None
            if kept is not None:  # the far half of the last step's bent one: converged already
                self.kept_half = kept
                return kept, self._increment(last, kept), False, 0
            trial, reason = self._attempt(h_try, last, t, rises, limit)
            if (trial is not None and size.by_allowance and cuts == 0 and not direct
                    and self._bends_within(last, trial, t)):
                self.bent = (last.step, trial)  # its state may end the cut retry's next step
                trial, reason = None, BENT
            if trial is not None and cuts < CRITICAL_TARGET_CUTS and 0.5 * h_try >= size.h_min \
                    and self._hard_across_target(last, trial):
                trial, reason = None, CRITICAL_TARGET
            if trial is not None:
                if 0 < DIVERGENCE_RISES <= trial.rises:
                    # a corrector that rose so converged: this model's iterations hunt (a contact
                    # set) and still converge; the test would shrink its steps, off for the path
                    self.divergence_rises = 0
                return trial, h_try, direct, cuts
            if reason.startswith(RISING):
                rises = 0
            # a failed limited attempt: the step's retries run plain, as before the limit
            # (as the rising test's do; a shortened iterate can leave the arc's equation
            # without a real root where a plain correction would not)
            limited_failed = limited_failed or limit
            size.h = 0.5 * h_try
            cuts += 1
            if not rescued and self._rescue_due(cuts, size.h):
                rescued = True
                trial, direct = self._probe_rescue(last, t)
                if trial is not None:
                    self.rescues.append(step)
                    h_try = self.wnorm(trial.u - last.u, trial.load_factor - last.load_factor)
                    return trial, h_try, direct, cuts
            if size.h < size.h_min:
                hint = ""
                if reason.startswith(INADMISSIBLE):
                    hint = (" The path leaves the model's admissible domain here (its "
                            "equations have no physical meaning beyond); the states before "
                            "it are kept.")
                elif opt.control == "load":
                    hint = (" Under load control this usually means a load maximum (limit "
                            "point) is near; use displacement or arc-length control.")
                elif opt.control == "displacement":
                    hint = (" Under displacement control this usually means the driven "
                            "probe has a turning point (snap-back) near; use arc-length "
                            "control.")
                return (f"step {step}: no convergence from λ = {last.load_factor:.6g} "
                        f"({_fmt_probes(last.probes)}): the {opt.control} increment was cut "
                        f"{cuts} time(s), last to {h_try:.3g}, and may not go below "
                        f"min_increment = {size.h_min:.3g}; "
                        f"last reason: {reason}.{hint}")

    def _bent_half(self, last: PathState, h: float) -> _Trial | None:
        """The converged state of a step cut as ``BENT``, as the step after its retry.

        A step the settling allowance grew converged at X but bent within it (:data:`BENT`);
        it was cut, and its retry from the same start at half the length converged at
        ``last``. X is an equilibrium of the same path (the corrector converged there, under
        the same guards) ahead of ``last``: it is taken as the next step where that step is no
        longer than :data:`HALF_REACH` × the increment ``h`` the controller asks for now (in
        the units of the control, :meth:`_increment`: the path is sampled as finely as the
        controller's own step would sample it), its displacement increment makes an angle of
        at most 90° with the retry's (:meth:`_turns_back`'s test, with ``min_step_cosine``)
        and no stopping target lies between (:meth:`_crossings`); else the path steps on as
        usual. Saves the corrector that repeats the second half (fig. 5 at the paper's core:
        107 corrector iterations in all instead of 115). The increment after it is the one the
        retry left (X's iterations were a whole step's, from the bent step's start). Taken
        once: the kept state is dropped at any other step.
        """
        kept, self.bent = self.bent, None
        if kept is None or len(self.states) < 2 or self.states[-2].step != kept[0]:
            return None  # nothing kept, or not right after the retry from the bent step's start
        trial, start = kept[1], self.states[-2]
        cos = self._step_cosine(trial.u - last.u, last.u - start.u)
        if (cos is None or cos < self.opt.min_step_cosine
                or not 0.0 < self._increment(last, trial) <= HALF_REACH * h
                or self._crossings(last, trial)):
            return None
        return trial

    def _locate_crossing(self, state: PathState, last: PathState, fac_before: object,
                         fac: object, t: np.ndarray) -> None:
        """Locate a bifurcation within the step ``last`` → ``state`` (their inertia differs).

        First from the two factorisations the step has
        (:func:`~sandwich.solver.critical.locate_crossing`: solves only, no tangent evaluated):
        where the crossed eigenvalue, linear along the step, is zero. Then, with
        ``locate_critical_points``, steps from ``last`` under the path's control (``t`` its load
        tangent), shorter than the step's increment h in the control's units (whether the step
        was the controller's, a target's, a rescue's or a kept bent one) and aimed at that
        point, narrow the bracket (regula falsi on the eigenvalue, Illinois' rule; the middle
        where an end's eigenvalue is unknown; after a try that fails, half as far from the
        bracket's lower end). Their equilibria are not path states, and the path's own
        settings (contact-limited corrections) are left as they were. Not narrowed: a change
        by one on a step with a located load extremum (:meth:`_locate_extremum`, run first),
        which :func:`~sandwich.solver.limits.find_limit_points` reads as that extremum's.
        """
        a, b = last.negative_pivots, state.negative_pivots
        if a is None or b is None or a == b:
            return
        h = self._increment(last, state)
        try:
            c = locate_crossing(fac_before, fac, b - a, self.system.size, self.dot,
                                state.u - last.u)
        except RECOVERABLE_ERRORS:  # a solve that fails: reported at the state, as before
            c = None
        lo = BracketEnd(0.0, last.load_factor, dict(last.probes),
                        None if c is None else c.mu_before)
        hi = BracketEnd(1.0, state.load_factor, dict(state.probes),
                        None if c is None else c.mu_after)
        found = None if c is None else crossing_in(lo, hi, 0)
        # a change by one on a step with a located load extremum is that extremum's (a
        # limit point makes the tangent singular; limits.py reads it so): no tries for it
        explained = state.extremum is not None and abs(b - a) == 1
        if not self.opt.locate_critical_points or not h > 0.0 or abs(b - a) > MAX_CROSSINGS \
                or explained:
            state.crossing = found
            return
        old_sign = 1.0 if b > a else -1.0
        replaced: list[str] = []
        retry = None  # after a try that failed: half as far from the bracket's lower end
        for _ in range(MAX_SUBSTEPS):
            if abs(hi.load_factor - lo.load_factor) <= LOCATE_RTOL * max(
                    abs(lo.load_factor), abs(hi.load_factor)):
                break
            f = retry if retry is not None else next_fraction(
                halved(lo) if replaced[-2:] == ["hi", "hi"] else lo,
                halved(hi) if replaced[-2:] == ["lo", "lo"] else hi)
            trial = self._inside_step(f * h, last, t)
            n = None if trial is None else trial.factorization.negative_pivots
            retry = None if n is not None else lo.f + 0.5 * (f - lo.f)
            if n is None:
                continue
            try:
                mu = crossed_eigenvalue(trial.factorization, old_sign if n == a else -old_sign,
                                        self.system.size, self.dot)
            except RECOVERABLE_ERRORS:
                mu = None
            end = BracketEnd(f, trial.load_factor, self.probes(trial.u), mu)
            replaced.append("lo" if n == a else "hi")
            lo, hi = (end, hi) if n == a else (lo, end)
            previous, found = found, crossing_in(lo, hi, len(replaced))
            if previous is not None and abs(found.load_factor - previous.load_factor) <= \
                    LOCATE_RTOL * abs(found.load_factor):
                break
        ends = (last.load_factor, state.load_factor)
        if found is not None and min(lo.load_factor, hi.load_factor) > max(ends):
            found = dataclasses.replace(found, kind="max")  # a maximum inside the step
        elif found is not None and max(lo.load_factor, hi.load_factor) < min(ends):
            found = dataclasses.replace(found, kind="min")
        state.crossing = found

    def _probe_rate(self, t: np.ndarray) -> float | None:
        """dw/dλ = c·t of the load curve's probe w (:attr:`rate_probe`) for the load tangent t."""
        if self.rate_probe is None:
            return None
        rate = self.dot(self.c[self.rate_probe], t)
        return float(rate) if math.isfinite(rate) else None

    def _locate_extremum(self, state: PathState, last: PathState, t: np.ndarray,
                         t_next: np.ndarray) -> None:
        """Locate a load extremum within the step ``last`` → ``state`` (:mod:`~.extrema`).

        From the two states' loads, probes and load tangents alone (``t`` at ``last``,
        ``t_next`` at ``state``; no solve): where the path's tangent, oriented forward along the
        step (the sense of t·Δu + ψ²Δλ), turns its λ component over while w keeps moving the
        step's way, the stationary point of λ's cubic Hermite interpolant in w. Then, with
        ``locate_critical_points``, steps from ``last`` under the path's control aimed at that
        point (the middle of the bracket where the interpolant is refused) narrow the bracket,
        each equilibrium's tangent from one solve with its factorisation, as
        :meth:`_locate_crossing` narrows a bifurcation.
        """
        name, qa, qb = self.rate_probe, last.probe_rate, state.probe_rate
        if name is None or qa is None or qb is None:
            return
        du, dlam = state.u - last.u, state.load_factor - last.load_factor

        def sense(tangent: np.ndarray) -> float:
            return float(np.sign(self.dot(tangent, du) + self.psi**2 * dlam))

        def kind_between(a: SlopeEnd, b: SlopeEnd) -> str | None:
            return turns_over(b.probes[name] - a.probes[name], a.rate, b.rate, a.sense, b.sense)

        lo = SlopeEnd(0.0, last.load_factor, dict(last.probes), qa, sense(t))
        hi = SlopeEnd(1.0, state.load_factor, dict(state.probes), qb, sense(t_next))
        kind = kind_between(lo, hi)
        if kind is None:
            return
        found = located_in(lo, hi, name)
        h = self._increment(last, state)
        retry = None
        for _ in range(MAX_SUBSTEPS if self.opt.locate_critical_points and h > 0.0 else 0):
            w = hi.f - lo.f
            aim = found[0] if found is not None else 0.5 * (lo.f + hi.f)
            f = retry if retry is not None else min(max(aim, lo.f + SAFEGUARD * w),
                                                    hi.f - SAFEGUARD * w)
            trial = self._inside_step(f * h, last, t)
            tangent = None
            if trial is not None:
                try:
                    tangent = np.asarray(trial.factorization.solve(self.f_ref), dtype=float)
                except RECOVERABLE_ERRORS:
                    tangent = None
            rate = None if tangent is None else self._probe_rate(tangent)
            retry = None if rate is not None else lo.f + 0.5 * (f - lo.f)
            if rate is None:
                continue
            mid = SlopeEnd(f, trial.load_factor, self.probes(trial.u), rate, sense(tangent))
            if not min(lo.probes[name], hi.probes[name]) < mid.probes[name] < \
                    max(lo.probes[name], hi.probes[name]):
                break  # not between the bracket's ends in w: keep the bracket
            if kind_between(lo, mid) == kind:
                lo_next, hi_next = lo, mid
            elif kind_between(mid, hi) == kind:
                lo_next, hi_next = mid, hi
            else:  # the try's tangent fits neither side: keep the bracket
                break
            located = located_in(lo_next, hi_next, name)
            lo, hi = lo_next, hi_next
            previous, found = found, located
            if found is None or previous is None:
                continue
            if abs(found[1] - previous[1]) <= LOCATE_RTOL * abs(found[1]):
                break
        if found is None:
            return
        f, lam = found
        s = (f - lo.f) / (hi.f - lo.f)  # linear in the probe between the bracket's ends
        probes = {n: v + s * (hi.probes[n] - v) for n, v in lo.probes.items()}
        x = (probes[name] - last.probes[name]) / (state.probes[name] - last.probes[name])
        state.extremum = Extremum(kind, x, lam, probes, (lo.load_factor, hi.load_factor))

    def _returned(self, state: PathState) -> str:
        """Why the path ending at ``state`` is retracing its own branch (``""`` if it is not).

        A regular equilibrium curve does not come back to a point it passed; a path that does
        has turned onto its own branch and follows it back (fig. 7 c2's 2D path after its
        core crushed: a loop through crushed states, then the loading branch retraced through
        λ = 0 to λ = −117, every step turning by a small angle, so the retrace guard on
        consecutive steps never saw it). ``state`` lies on the path already followed when it
        is within RETURN_FRACTION of an earlier step's length from that step's chord, in
        ‖(u, ψλ)‖, counting only steps the path has since travelled away from by at least
        their length (a run of short steps right after a long one stays near its chord
        without returning). A single such state can be a near pass of another part of the
        path (fig. 4's crushed 2D core: one state within 0.09, the next ones 0.1-0.4 away);
        RETURN_STATES of them in a row are a retrace: the path stops. A step whose λ range
        lies farther from the state than the fraction is skipped without a dot product
        (|ψ Δλ| bounds the distance from below).
        """
        psi = self.psi
        chords, travelled = self._chord_lengths2, self._path_length
        while len(chords) < len(self.states) - 1:
            a, b = self.states[len(chords)], self.states[len(chords) + 1]
            du = b.u - a.u
            chords.append(self.dot(du, du) + (psi * (b.load_factor - a.load_factor)) ** 2)
            travelled.append(travelled[-1] + math.sqrt(chords[-1]))
        n = len(self.states) - 1  # the state's index; its own step is chord n − 1
        x_l = psi * state.load_factor
        on = None
        for k in range(max(n - 1, 0)):
            length2 = chords[k]
            if length2 == 0.0 or (travelled[n] - travelled[k + 1]) ** 2 < length2:
                continue  # not travelled away from it by its length yet
            a, b = self.states[k], self.states[k + 1]
            lo, hi = sorted((psi * a.load_factor, psi * b.load_factor))
            gap_l = max(lo - x_l, x_l - hi, 0.0)
            if gap_l * gap_l > RETURN_FRACTION**2 * length2:
                continue
            dl = psi * (b.load_factor - a.load_factor)
            du = b.u - a.u
            xu, xl = state.u - a.u, x_l - psi * a.load_factor
            s = min(max((self.dot(xu, du) + xl * dl) / length2, 0.0), 1.0)
            ru, rl = xu - s * du, xl - s * dl
            d2 = self.dot(ru, ru) + rl * rl
            if d2 <= RETURN_FRACTION**2 * length2:
                on = (k, math.sqrt(d2 / length2))
                break
        self._returns = [*self._returns, on][-RETURN_STATES:] if on else []
        if len(self._returns) < RETURN_STATES:
            return ""
        first = n - RETURN_STATES + 1
        (k0, r0), (k, _) = self._returns[0], self._returns[-1]
        return (f"step {state.step}: the path is retracing its own branch — steps {first}-{n} "
                f"lie on the path it followed before (step {first} within {r0:.2g} of step "
                f"{k0 + 1}'s length from it, λ {self.states[k0].load_factor:.6g} → "
                f"{self.states[k0 + 1].load_factor:.6g}; step {n} on step {k + 1}), turned by "
                f"steps of small angle after a fold; stopped there, the states kept")

    def _jumped(self, last: PathState, state: PathState, t: np.ndarray) -> bool:
        """Whether the step ``last`` → ``state`` may have landed on another branch past a snap.

        The step's change Δ = (Δu, Δλ) against the path's tangent (t, 1) at ``last`` (``t``
        its load tangent), in the arc's norm: Δ leaves the tangent's line by more than
        :data:`JUMP_CORRECTION` × its projection on it, or its load change falls short of the
        projection's by more than :data:`JUMP_LOSS` of it, the tangent's inertia the same at
        both ends (a crossing is :meth:`_locate_crossing`'s). For an arc step the first is the
        corrector's distance from the predictor over the predictor's length; measured on the
        knock-down study's off-centre debonds, whose faces snap at about their clamped-strip
        Euler loads: 0.29-0.97 and −0.10..−0.45 on the steps that jump the snap, at most 0.1 and
        ±0.1 on the steps of either branch. Any step is measured so (a kept bent half, a
        target's). Large also where the path bends at a load maximum (whose extremum, located
        first, skips the walk) or on a step that only bends: the walk then finds no end, or an
        end without a loss of load, and reports nothing, at the cost of its correctors.
        """
        neg = last.negative_pivots
        if neg is None or state.negative_pivots != neg or self.opt.control != "arc-length":
            return False
        du, dlam = state.u - last.u, state.load_factor - last.load_factor
        along = self.wnorm(t, 1.0)
        if not along > 0.0 or not math.isfinite(along):
            return False
        p = (self.dot(du, t) + self.psi**2 * dlam) / along  # Δ's projection on the tangent
        length = self.wnorm(du, dlam)
        if p == 0.0 or not math.isfinite(p):
            return False
        off = math.sqrt(max(length**2 - p**2, 0.0)) / abs(p)
        predicted = p / along  # the tangent's load change over that projection
        return off > JUMP_CORRECTION or (dlam - predicted) / predicted < -JUMP_LOSS

    def _walk_branch_left(self, state: PathState, last: PathState, t: np.ndarray) -> None:
        """The furthest load on the branch a step jumped from: a bound of its top.

        A probe rescue (:meth:`_probe_rescue`) is taken where the arc collapsed, and an arc step
        may converge past a snap (:meth:`_jumped`); in both the branch from ``last`` may end
        inside the step (the debonded face snaps: fig. 6 as shipped, the knock-down study's
        off-centre debonds). Its top then lies inside the step, and neither the step's states
        nor their slopes see it: both tangents rise, the one at ``state`` on the branch the step
        landed on.

        The branch is walked from ``last`` under control of the until probe, the way λ rose at
        ``last`` towards the target (fell: a minimum): steps of half the probe change of the
        step before ``last`` (at most 1/4 of this step's), each from the walk's last
        equilibrium with its load tangent as predictor, its correctors as the path's at the
        walk's start with at most ``desired_iterations`` iterations (:meth:`_walk_try`). A step
        is halved where it is refused — its corrector fails or leaves the branch, the tangent's
        inertia changes, or λ turns back (the top is passed: a limit point where the inertia
        changed by one, else where λ fell by more than :data:`WALK_LOSS`). The walk may go on
        past ``state``'s probe value by one more step's change (the branch left can reach
        beyond the state the step landed on: knock-down 35 mm at x = 50), not past the path's
        target; a step past that limit goes half way to it. The branch ends where the halving
        runs below :data:`WALK_MIN_FRACTION` of the first step on refusals; a walk that runs
        out of its :data:`WALK_TRIES` correctors or reaches the limit still rising finds no
        top, and so does one that passes ``state``'s probe value on ``state`` itself (within
        :data:`WALK_LOSS`: the step did not leave the branch; the snap-back truss, whose arc
        steps bend hard near its minimum). Where the branch ended or λ turned back, the
        walk's highest (lowest) equilibrium —
        ``last`` itself where none converged — is the step's located extremum (its fraction
        of the step at most 1), a bound of the top from below (above), the top lying within
        the last refused step of it in the probe, if one of these shows that load was lost
        beyond it:

        * ``state`` lies below the branch by more than :data:`WALK_LOSS` of its load: below
          the walk's top, or, where the walk passed ``state``'s probe value, below the branch
          there (fig. 6 as shipped, 1915.3 after 1975.8);
        * λ turned back on the branch (above);
        * the branch ended, and one corrector from its end under the path's own settings
          (any branch), as far in the probe as the step before ``last`` went (short of
          ``state``), converges below the top by more than :data:`WALK_LOSS` of it (the
          knock-down study's 10-mm debond at x = 110, whose rescue went on to the target:
          2023.4 there, 2060.0 at the end — the top and the state after it its mirror image at
          x = 190 shows);
        * the walk ended short of ``state``'s probe value, its slope dw/dλ there still at
          least :data:`WALK_SLOPE_KEPT` of the one at ``last`` (no turn of w ahead), and
          ``state`` lies below the branch continued
          to its probe value by more than :data:`WALK_LOSS` of the end's load — continued
          quadratically in the probe with the curvature of the step before ``last``, where
          concave (a concave branch that goes on lies below its tangent line:
          tests/solver/test_solver_probe_rescue.py).

        Otherwise nothing is reported (fig. 7 c4: its arc collapsed on a branch that goes on
        rising). The walk's equilibria are not path states; the path's settings are left as
        they were.
        """
        name, rate = self.opt.until_probe, last.probe_rate
        if state.extremum is not None or name is None or name != self.rate_probe \
                or rate is None or rate == 0.0 or len(self.states) < 3:
            return
        v0, v1 = last.probes[name], state.probes[name]
        before = self.states[-3].probes[name]
        if v1 == v0:
            return
        direction = math.copysign(1.0, v1 - v0)
        sign = math.copysign(1.0, direction / rate)  # dλ = dw / (dw/dλ): +1 rising, a max
        first = min(0.5 * abs(v0 - before), abs(v1 - v0) / 4.0)
        if not first > 0.0:
            return
        failed_once, sigma = self.failed_once, self.sigma
        try:
            settings = dataclasses.replace(  # as the path's correctors are at the walk's start
                self._newton_settings(self.divergence_rises, self.limit_corrections),
                max_iterations=self.opt.desired_iterations)
            u, lam, tangent, v, rate_end = last.u, last.load_factor, t, v0, rate
            far = v1 + (v1 - v0)  # the branch left may go on past ``state``'s probe value ...
            if self.opt.until_value is not None and direction * (far - self.opt.until_value) > 0.0:
                far = self.opt.until_value  # ... but not past the path's target
            at_end = None  # λ of the branch left at ``state``'s probe value, once walked past it
            best = None
            delta, tries = first, 0
            refused = False  # a try was refused since the walk's last equilibrium
            turned = False  # λ turned back on the branch (beyond WALK_LOSS)
            ended = False  # the halving ran out on refusals: the branch ends there
            while tries < WALK_TRIES:
                if delta < WALK_MIN_FRACTION * first:
                    ended = refused
                    break
                goal = v + direction * delta
                if direction * (far - goal) <= 0.0:  # not past a step beyond: half the way to it
                    half = 0.5 * abs(far - v)
                    if not half < delta:
                        break
                    delta = half
                    continue
                tries += 1
                trial, change = self._walk_try(name, goal, u, lam, tangent, last.negative_pivots,
                                               settings)
                if trial is not None and sign * (trial.load_factor - lam) < 0.0:
                    # past a top of the branch: a limit point where the tangent's inertia changed
                    # by one, else where λ fell by more than WALK_LOSS (no noise)
                    turned = turned or abs(change) == 1 or \
                        sign * (trial.load_factor - lam) < -WALK_LOSS * abs(lam)
                    trial = None  # nearer
                elif change:
                    trial = None  # another inertia, λ still rising: off the branch
                if trial is None:
                    refused = True
                    delta *= 0.5
                    continue
                try:
                    tangent = np.asarray(trial.factorization.solve(self.f_ref), dtype=float)
                except RECOVERABLE_ERRORS:
                    break
                if at_end is None and direction * (goal - v1) >= 0.0:  # (linear between the two)
                    at_end = lam + (trial.load_factor - lam) * (v1 - v) / (goal - v)
                u, lam, v, best, rate_end = trial.u, trial.load_factor, goal, trial, \
                    self._probe_rate(tangent)
                refused = False
            if not (ended or turned):
                return  # the branch goes on (or the walk ran out of tries): no top found on it
            # no step of the walk converged but the branch ended: it ends within its smallest
            # step of ``last`` itself (knock-down 40 mm at x = 70: 0.06 % below the fine path's top)
            top, top_u = (best.load_factor, best.u) if best is not None else (lam, last.u)
            lost = WALK_LOSS * abs(top)
            if at_end is not None and abs(at_end - state.load_factor) <= lost:
                return  # ``state`` lies on the branch walked: the step did not leave it
            # the branch left above ``state`` at its probe value (or its top, short of it)
            dropped = sign * ((top if at_end is None else at_end) - state.load_factor) > lost
            abrupt = False
            if ended and at_end is None and rate_end is not None and \
                    rate_end / rate >= WALK_SLOPE_KEPT:
                # the step's end state below the branch continued to its probe value by more than
                # WALK_LOSS: continued quadratically in w with the curvature of the step before
                # (from ``before``'s and ``last``'s slopes), if concave (the walk's own slopes,
                # a few thousandths of a mm apart at a snap, do not measure it)
                rate_before = self.states[-3].probe_rate
                bend = 0.0
                if rate_before:
                    bend = (1.0 / rate - 1.0 / rate_before) / (v0 - before)
                    bend = bend if sign * bend < 0.0 else 0.0
                on_branch = top + (v1 - v) / rate_end + 0.5 * bend * (v1 - v) ** 2
                abrupt = sign * (on_branch - state.load_factor) > lost
            if ended and not (dropped or turned or abrupt):
                # one corrector past the end as the path's own (any branch), as far as the step
                # before ``last`` went: an equilibrium there below the top shows the load lost
                # (knock-down 10 mm at x = 110, whose rescue went on to the target: 2023.4 at
                # 0.25 mm past the end, as its mirror's rescue found at x = 190)
                goal = v + direction * abs(v0 - before)
                if direction * (v1 - goal) > 0.0:
                    beyond = self._control_to(name, goal, u, lam, tangent)
                    dropped = beyond is not None and sign * (top - beyond.load_factor) > lost
            if not (dropped or turned or abrupt):
                return
            ends = (last.load_factor, state.load_factor)
            probes = self.probes(top_u)
            fraction = min(1.0, max(0.0, (probes[name] - v0) / (v1 - v0)))  # (a top past it: 1)
            state.extremum = Extremum("max" if sign > 0 else "min", fraction, top, probes, ends)
        finally:  # the walk's correctors are not the path's
            self.failed_once, self.sigma = failed_once, sigma

    def _walk_try(self, name: str, goal: float, u: np.ndarray, lam: float, t: np.ndarray,
                  negative_pivots: int | None,
                  settings: NewtonSettings) -> tuple[_Trial | None, int]:
        """One corrector of :meth:`_walk_branch_left` to ``value(name) = goal``.

        Returns the equilibrium (None: off the branch) and the change of the tangent's
        negative pivots from ``negative_pivots`` (0 where either is unknown).

        :meth:`_control_to` from ``(u, λ)`` with the load tangent ``t``; ``settings`` are the path's
        corrector settings at the walk's start (rising test, contact-limited corrections) with
        at most ``desired_iterations`` iterations (the walk's steps are short: on fig. 6 those
        that converge take 3-6 iterations, while those that do not ran to the 25 allowed).
        Off the branch: a failed corrector, a corrector that moved more than
        ``max_correction_ratio`` × the predictor from it (a jump to another branch), an
        inadmissible state.
        """
        try:
            trial = self._control_to(name, goal, u, lam, t, settings)
        except RECOVERABLE_ERRORS:
            trial = None
        if trial is None:
            return None, 0
        c = self.c[name]
        dlam = (goal - self.dot(c, u)) / self.dot(c, t)  # the predictor's (_control_to's)
        reach = self.wnorm(dlam * t, dlam)
        if self.wnorm(trial.u - u - dlam * t, trial.load_factor - lam - dlam) > \
                self.opt.max_correction_ratio * reach:
            return None, 0
        if self.admissible is not None and self.admissible(trial.u):
            return None, 0
        neg = trial.factorization.negative_pivots
        change = 0 if negative_pivots is None or neg is None else neg - negative_pivots
        return trial, change

    def _inside_step(self, h: float, last: PathState, t: np.ndarray) -> _Trial | None:
        """A step of ``h`` from ``last`` whose equilibrium is not a path state (or None).

        For narrowing a critical point: the path's settings (contact-limited corrections, the
        arc's sense) are left as they were, whatever the corrector does.
        """
        failed_once, sigma = self.failed_once, self.sigma
        try:
            trial, _ = self._attempt(h, last, t)
        except RECOVERABLE_ERRORS:
            trial = None
        self.failed_once, self.sigma = failed_once, sigma
        return trial

    def _increment(self, last: PathState, trial: _Trial | PathState) -> float:
        """The step from ``last`` to ``trial`` in the units of the control (h's)."""
        dl = trial.load_factor - last.load_factor
        if self.opt.control == "load":
            return abs(dl)
        if self.opt.control == "displacement":
            name = self.opt.driven_probe
            return abs(self._value(name, trial.u, 0.0) - last.probes[name])
        return self.wnorm(trial.u - last.u, dl)

    def _hard_across_target(self, last: PathState, trial: _Trial) -> bool:
        """Whether ``trial`` crossed a critical point and a stopping target, the hard way.

        The tangent's inertia changed between ``last`` and ``trial``, the step passed the
        ``until`` target, and the corrector needed more than ``desired_iterations``. Such a
        step is shortened (:meth:`_converge_step`, at most ``CRITICAL_TARGET_CUTS`` times)
        instead of being handed to :meth:`_hit_crossed_target`, whose target control from
        ``last`` — before the critical point — can land on another equilibrium: fig. 7 c1 at
        the paper's core, 120 elements, stepped from λ 556 (w −23.2 mm) to the target in one
        step of 15 iterations and ended at λ 735.38, where the path in steps of at most 15
        reaches −40 mm at λ 860.66 (and so does it with this cut, in 8 steps); at 40-480
        elements the default steps and the short ones agree.
        """
        neg = last.negative_pivots
        return (neg is not None and trial.factorization.negative_pivots != neg
                and trial.iterations > self.opt.desired_iterations
                and bool(self._crossings(last, trial)))

    def _finish_crossed(self, crossed: str) -> PathResult:
        """End of a path whose step crossed the target on ``crossed`` without hitting it."""
        s = self.states[-1]
        near = self._near_target(crossed, s)
        if near:
            return self.finish(True, near)
        return self.finish(False, (
            f"step {s.step}: the target on {crossed} was crossed but could not be hit "
            f"within target_tol = {self.opt.target_tol:g} (stopped at λ = "
            f"{s.load_factor:.6g}, {_fmt_probes(s.probes)})"))

    # -- pieces ------------------------------------------------------------------------------
    def _target_load_estimate(self, t: np.ndarray) -> float:
        """Load factor of the target, estimated from the linear solution (1 if none)."""
        ests = []
        if self.opt.until_load_factor is not None:
            ests.append(self.opt.until_load_factor)
        if self.opt.until_probe is not None:
            ct = self.dot(self.c[self.opt.until_probe], t)
            if ct != 0.0:
                ests.append(self.opt.until_value / ct)
        return min(ests, key=abs) if ests else 1.0

    def _curve_probe(self, t: np.ndarray) -> tuple[str | None, float]:
        """The load curve's probe and its linear value at the target's estimated load.

        The until probe, else the first probe asked for; (None, 0) without a probe or where
        that value is 0.
        """
        names = [n for n in (self.opt.until_probe,) if n] or list(self.c)
        if not names:
            return None, 0.0
        scale = abs(self.dot(self.c[names[0]], t) * self.lam_est)
        return (names[0], scale) if scale > 0.0 and math.isfinite(scale) else (None, 0.0)

    def _auto_increment(self, t: np.ndarray) -> float:
        """1/20 of the (linearly estimated) distance to the target, in control units."""
        lam = abs(self.lam_est)
        if self.opt.control == "load":
            return lam / 20.0
        if self.opt.control == "displacement":
            name = self.opt.driven_probe
            if name == self.opt.until_probe:
                return abs(self.opt.until_value) / 20.0
            return abs(self.dot(self.c[name], t)) * lam / 20.0 or lam / 20.0
        return lam * math.sqrt(self.dot(t, t) + self.psi**2) / 20.0

    def _clip_to_target(self, h: float, last: PathState) -> tuple[float, bool, float | None]:
        """Shorten ``h`` so that a directly controlled target is hit exactly.

        Returns the increment, whether the target of the control variable is hit by it, and the
        sign of the control's direction towards that target (``None`` when the control has no
        target of its own: the sign is then the follower's).
        """
        opt = self.opt
        if opt.control == "load" and opt.until_load_factor is not None:
            rem = abs(opt.until_load_factor - last.load_factor)
            sign = math.copysign(1.0, opt.until_load_factor - last.load_factor)
            return (rem, True, sign) if h >= rem else (h, False, sign)
        if (opt.control == "displacement" and opt.until_probe is not None
                and opt.driven_probe == opt.until_probe):
            v = last.probes[opt.until_probe]
            rem = abs(opt.until_value - v)
            sign = math.copysign(1.0, opt.until_value - v)
            return (rem, True, sign) if h >= rem else (h, False, sign)
        return h, False, None

    def _arc_direction(self, t: np.ndarray, last: PathState) -> float:
        """Sign of the arc-length predictor: forward along the path.

        The predictor ``σ(t, 1)`` must make an acute angle with the previous step. When that angle
        is within ~84° of a right angle (|cos| < 0.1) the test is unreliable and the sign of the
        previous Δλ is flipped on each change of the negative-pivot count (det K changes sign).
        """
        if self.prev_step is None:
            return self.sigma
        du, dl = self.prev_step
        dot = self.dot(t, du) + self.psi**2 * dl
        denom = self.wnorm(t, 1.0) * self.wnorm(du, dl)
        prev = self.states[-2] if len(self.states) >= 2 else None
        if denom > 0.0 and abs(dot) >= 0.1 * denom:
            return math.copysign(1.0, dot)
        if prev is not None and None not in (prev.negative_pivots, last.negative_pivots):
            flips = abs(last.negative_pivots - prev.negative_pivots) % 2
            return math.copysign(1.0, dl) * (-1.0 if flips else 1.0)
        return math.copysign(1.0, dot) if dot != 0.0 else self.sigma

    def _attempt(self, h: float, last: PathState, t: np.ndarray, rises: int = 0,
                 limit: bool | None = None) -> tuple[_Trial | None, str]:
        """One predictor–corrector step of size ``h`` from ``last``.

        ``rises``: the corrector's ``divergence_rises`` (0: off, as for the target's and the
        rescue's correctors, whose failure ends their search). ``limit``: contact-limited
        corrections (default: the path's :attr:`limit_corrections`).
        """
        opt = self.opt
        if opt.control == "load":
            target = (opt.until_load_factor if opt.until_load_factor is not None
                      and h == abs(opt.until_load_factor - last.load_factor)
                      else last.load_factor + self.sigma * h)
            dlam = target - last.load_factor
            constraint = LoadConstraint(target)
        elif opt.control == "displacement":
            name = opt.driven_probe
            c = self.c[name]
            ct = self.dot(c, t)
            v0 = last.probes[name]
            target = (opt.until_value if name == opt.until_probe
                      and h == abs(opt.until_value - v0) else v0 + self.sigma * h)
            if ct == 0.0 or not math.isfinite(ct):
                return None, f"probe {name} does not respond to the load"
            dlam = (target - v0) / ct
            constraint = ProbeConstraint(c, target, self.dot)
        else:
            dlam = self.sigma * h / self.wnorm(t, 1.0)
            constraint = ArcLengthConstraint(h, self.psi, self.dot)
        du_pred = dlam * t
        pred_len = self.wnorm(du_pred, dlam)
        if self.prev_step is not None:
            prev_len = self.wnorm(*self.prev_step)
            if pred_len > opt.max_predictor_growth * prev_len:
                return None, (f"predictor {pred_len:.3g} longer than {opt.max_predictor_growth}"
                              f" × the previous step {prev_len:.3g}")
        res = self._correct(last.u + du_pred, last.load_factor + dlam, constraint,
                            self._newton_settings(rises, limit), last.u, last.load_factor)
        if not res.converged or res.factorization is None:
            return None, res.reason
        dist = self.wnorm(res.u - last.u - du_pred, res.load_factor - last.load_factor - dlam)
        if dist > opt.max_correction_ratio * pred_len:
            return None, (f"corrector moved {dist:.3g} from a predictor of length {pred_len:.3g}"
                          f" (jump to another branch?)")
        why = self._turns_back(res.u - last.u, du_pred)
        if why:
            return None, why
        if self.admissible is not None:
            why = self.admissible(res.u)
            if why:
                return None, f"{INADMISSIBLE}: {why}"
        return _Trial(res.u, res.load_factor, res.iterations, res.factorization,
                      res.rises, res.increment_iterations), "converged"

    def _newton_settings(self, rises: int = 0, limit: bool | None = None) -> NewtonSettings:
        """Corrector settings; the force floor is ‖f_ref‖ × the largest |λ| reached so far.

        ``rises``: the rising test's ``divergence_rises`` (0: off). ``limit``: contact-limited
        corrections; by default as the path has them (on once a corrector of this path has
        failed, :meth:`_correct`).
        """
        floor = (math.sqrt(self.dot(self.f_ref, self.f_ref))
                 * max(abs(s.load_factor) for s in self.states))
        return NewtonSettings(tol=self.opt.tol, max_iterations=self.opt.max_iterations,
                              psi=self.psi, force_floor=floor, divergence_rises=rises,
                              limit_corrections=(self.limit_corrections if limit is None
                                                 else limit))

    def _correct(self, u: np.ndarray, lam: float, constraint: object, settings: NewtonSettings,
                 u_start: np.ndarray, lam_start: float) -> NewtonResult:
        """:func:`~sandwich.solver.newton.newton_correct` on this path's system.

        The first corrector that fails turns contact-limited corrections on for the rest of
        the path (``LIMIT_AFTER_FAILURE``): a path whose corrector has failed once is one
        whose contact pairs open and close under it (fig. 7 c3/c4, fig. 6), and on the paths
        where no corrector fails (most of fig. 9, fig. 4, the paper's core on fig. 5) the
        correctors stay as they were.
        """
        res = newton_correct(self.system, u, lam, constraint, settings, u_start, lam_start)
        if not res.converged:
            self.failed_once = True
        return res

    def _weighed_iterations(self, trial: _Trial) -> int:
        """The iterations the step-size controller weighs a converged step by.

        All of them, unless :attr:`PathOptions.settling_allowance` is set, no corrector of
        this path has failed and the load curve's last two steps turn by less than
        :data:`SETTLING_BEND` (:meth:`_straight`): then at most the iterations until the
        increment test first passed plus that allowance (the others settle a residual while
        the state no longer moves — the beam's contact pairs in the penalty law's knee — and
        do not shrink with the step). A step so grown is checked for a bend within it
        (:meth:`_bends_within`).
        """
        k = self.opt.settling_allowance
        if k is None or self.failed_once or trial.increment_iterations is None:
            return trial.iterations
        if not self._straight():
            return trial.iterations
        return min(trial.iterations, trial.increment_iterations + k)

    def _bends_within(self, last: PathState, trial: _Trial, t: np.ndarray) -> bool:
        """Whether a step's secant turns from its predictor by more than SETTLING_BEND.

        In the load curve's plane (:meth:`_straight`), the predictor along the tangent
        K⁻¹ f_ref at ``last``, either sense: a knee the step has crossed (the debonded face's
        buckling, a crushing) that the steps before it could not announce.
        """
        name = self.curve_probe[0]
        if name is None:
            return False
        p = self._in_curve_plane(self.dot(self.c[name], t), 1.0)
        d = self._in_curve_plane(self._value(name, trial.u, 0.0) - last.probes[name],
                                 trial.load_factor - last.load_factor)
        cos = _cosine(p, d)
        return cos is not None and abs(cos) < math.cos(SETTLING_BEND)

    def _straight(self) -> bool:
        """Whether the path's last two steps turn by less than :data:`SETTLING_BEND`.

        Measured in the plane of the load curve a user plots: (probe / its linear value at the
        target's load, λ / the target's load), the probe being the until probe, else the first
        probe asked for (:attr:`curve_probe`). False with fewer than two steps, without a
        probe, or where the probe's linear value is zero.
        """
        name = self.curve_probe[0]
        if name is None or len(self.states) < 3:
            return False
        a, b, c = self.states[-3:]
        d1 = self._in_curve_plane(b.probes[name] - a.probes[name], b.load_factor - a.load_factor)
        d2 = self._in_curve_plane(c.probes[name] - b.probes[name], c.load_factor - b.load_factor)
        cos = _cosine(d1, d2)
        return cos is not None and cos >= math.cos(SETTLING_BEND)

    def _in_curve_plane(self, dv: float, dlam: float) -> tuple[float, float]:
        """A change (probe ``dv``, λ ``dlam``) in the scaled plane of :meth:`_straight`."""
        return dv / self.curve_probe[1], dlam / (abs(self.lam_est) or 1.0)

    def _turns_back(self, du: np.ndarray, du_pred: np.ndarray) -> str:
        """Retrace / branch-jump guard on a converged increment ``du`` (``""`` if it is fine).

        Crisfield's angle criterion, used by the arc-length root choice *within* a step, applied
        to the converged step against the previous one: along a regular equilibrium curve the
        displacement increments of consecutive steps turn by a small angle (→ 0 with the step
        length), whatever the sign of Δλ, since ``K du = dλ f_ref`` never gives ``du = 0`` on
        the path. A step whose ``Δu`` makes an obtuse angle with the previous ``Δu`` went back
        along the path or onto another branch. The displacement part only is compared (Feng,
        Perić & Owen 1996): at a limit point Δλ changes sign legitimately, and with a large λ
        weight ψ the weighted angle would turn by ~180° there. If the predictor itself pointed
        backwards (``Δu_pred · Δu_prev < 0``, a wrong arc-length sign), the sign is flipped for
        the retry.
        """
        if self.prev_step is None or self.opt.min_step_cosine <= -1.0:
            return ""
        prev = self.prev_step[0]
        cos = self._step_cosine(du, prev)
        if cos is None or cos >= self.opt.min_step_cosine:
            return ""
        pred_back = self.dot(du_pred, prev) < 0.0
        if pred_back and self.opt.control == "arc-length":
            self.sigma = -self.sigma
        return (f"{RETRACE}: its displacement increment makes an angle of "
                f"{math.degrees(math.acos(max(-1.0, min(1.0, cos)))):.0f}° with the previous "
                f"step's (retrace or jump to another branch"
                f"{'; predictor pointed backwards, sign flipped' if pred_back else ''})")

    def _step_cosine(self, du: np.ndarray, prev: np.ndarray) -> float | None:
        """The cosine of the angle between two displacement increments (None if one is zero)."""
        denom = math.sqrt(self.dot(du, du) * self.dot(prev, prev))
        return self.dot(du, prev) / denom if denom > 0.0 else None

    def _crossings(self, last: PathState, trial: _Trial) -> list[tuple[float, str, float]]:
        """Targets crossed between ``last`` and ``trial``: (linear fraction, name, target)."""
        out = []
        pairs = []
        if self.opt.until_load_factor is not None:
            pairs.append(("λ", self.opt.until_load_factor, last.load_factor, trial.load_factor))
        if self.opt.until_probe is not None:
            c = self.c[self.opt.until_probe]
            pairs.append((self.opt.until_probe, self.opt.until_value,
                          last.probes[self.opt.until_probe], self.dot(c, trial.u)))
        for name, target, a, b in pairs:
            if (a - target) * (b - target) <= 0.0 and a != b:
                out.append(((target - a) / (b - a), name, target))
        return sorted(out)

    def _value(self, name: str, u: np.ndarray, lam: float) -> float:
        return lam if name == "λ" else self.dot(self.c[name], u)

    def _hit_crossed_target(
        self, trial: _Trial, h: float, last: PathState, t: np.ndarray
    ) -> tuple[_Trial, float, str]:
        """If ``trial`` overshoots a stopping target, shorten the step to hit it.

        A regular step (the tangent's inertia the same at ``last`` and ``trial``): first one
        corrector from the chord's point on the target (:meth:`_chord_target`). A step across a
        critical point (the inertia changed): first the target under its own control from
        ``last``, in sub-increments (:meth:`_attempt_target`) — the arc passed a load maximum
        or a bifurcation on the way and may have landed on another equilibrium (fig. 7 c1 at
        the paper's core: its long last arc ends beyond the target on an equilibrium the path
        followed in short steps does not reach), and shortened arcs from ``last`` then search
        along it (c1: five correctors, three failing at 25 iterations, before this same
        control found λ 758.4, the short-step path's value; c2: regula falsi's λ 736.843 to
        5e-9). If these fail or are refused, the step size ``x ∈ (0, h)`` is found by regula
        falsi with the Illinois modification on ``g(x) = value(step of size x) − target``,
        each evaluation a full corrector run from ``last``. Returns the step to accept, its
        size and the crossed target's name ("" if none was crossed).
        """
        crossed = self._crossings(last, trial)
        if not crossed:
            return trial, h, ""
        frac, name, target = crossed[0]
        neg = last.negative_pivots
        across = neg is not None and trial.factorization.negative_pivots not in (neg, None)
        first = (self._attempt_target(name, target, last, t, 0.5) if across
                 else self._chord_target(name, target, frac, last, trial))
        if first is not None:
            return first, self.wnorm(first.u - last.u, first.load_factor - last.load_factor), name
        scale = max(abs(target), *(abs(self._value(name, s.u, s.load_factor))
                                   for s in self.states))
        tol = self.opt.target_tol * scale
        a, fa = 0.0, self._value(name, last.u, last.load_factor) - target
        b, fb = h, self._value(name, trial.u, trial.load_factor) - target
        best, best_h, best_g = trial, h, fb
        side = 0
        for _ in range(40):
            if abs(best_g) <= tol or fa == fb:
                break
            x = (a * fb - b * fa) / (fb - fa)
            if not (min(a, b) < x < max(a, b)):
                x = 0.5 * (a + b)
            cand, _ = self._attempt(x, last, t)
            if cand is None and not math.isclose(x, 0.5 * (a + b)):
                # a very short step can trip the jump guard (corrector longer than predictor):
                # fall back to the middle of the bracket once before giving up
                x = 0.5 * (a + b)
                cand, _ = self._attempt(x, last, t)
            if cand is None:
                break
            fx = self._value(name, cand.u, cand.load_factor) - target
            if abs(fx) < abs(best_g):
                best, best_h, best_g = cand, x, fx
            if fx * fb > 0.0:
                b, fb = x, fx
                if side == -1:
                    fa *= 0.5
                side = -1
            else:
                a, fa = x, fx
                if side == 1:
                    fb *= 0.5
                side = 1
        if abs(best_g) > tol and not across:
            # The arc through the bracket can lose its real roots on short arcs (Crisfield's
            # quadratic); the target itself is then a better control equation: one corrector
            # from ``last`` with "value(name) = target" (load or displacement control).
            direct = self._attempt_target(name, target, last, t)
            if direct is not None:
                return direct, self.wnorm(direct.u - last.u,
                                          direct.load_factor - last.load_factor), name
        return best, best_h, name

    def _rescue_due(self, cuts: int, h: float) -> bool:
        """Whether the arc has collapsed enough to try :meth:`_probe_rescue`."""
        opt = self.opt
        if not (opt.probe_rescue and opt.control == "arc-length" and opt.until_probe
                and self.recent and cuts >= 1):
            return False
        return h < RESCUE_FRACTION * self.peak

    def _probe_rescue(self, last: PathState, t: np.ndarray) -> tuple[_Trial | None, bool]:
        """One step under control of the until probe across a critical point.

        Size: the largest recent change of the probe, towards the target (clipped to it).
        Returns the step (None if it fails or turns back) and whether it hit the target.
        """
        name, goal = self.opt.until_probe, self.opt.until_value
        v = last.probes[name]
        size = max(abs(dv) for _, dv in self.recent)
        if size == 0.0:
            return None, False
        direct = size >= abs(goal - v)
        target = goal if direct else v + math.copysign(size, goal - v)
        return self._attempt_target(name, target, last, t), direct

    def _chord_target(self, name: str, target: float, frac: float, last: PathState,
                      trial: _Trial) -> _Trial | None:
        """The crossed target hit by one corrector from the chord's point on it (None: failed).

        ``trial`` overshot ``value(name) = target``, which the chord from ``last`` to ``trial``
        meets at ``frac`` (values are linear in u and λ: the chord's point is on the target).
        From that point, a corrector with the target as control equation (load or displacement
        control) — in one go what regula falsi on the arc's length approaches by a corrector
        per trial (fig. 5: two; fig. 7 c1, whose correctors near the target hunt for their
        contact set: five, three of them failing, then the sub-incremented target control).
        Accepted under the step's guards with the chord as predictor: the corrector moves at
        most ``max_correction_ratio`` × the chord's part from it, does not turn back, stays
        admissible; else :meth:`_hit_crossed_target` goes on by regula falsi as before.

        Tried only on a regular step: the tangent's inertia (negative pivots) the same at
        ``last``, ``trial`` and the result, and the result's λ between ``last``'s and
        ``trial``'s. A step across a critical point is no chord: fig. 7 c1 at the paper's core,
        whose long last arc (24 iterations) passes the load maximum (0 → 1 negative pivots) and
        lands on another equilibrium beyond the target; from its chord the corrector converges
        at λ 691.6, on that other equilibrium, while the path followed in short steps reaches
        the target at λ 758.4, as the sub-incremented target control does (which
        :meth:`_hit_crossed_target` tries first on such a step). fig. 4's auto pass at levels
        {1: 150, 2: 90} steps from λ 1436.5 (w −7.7 mm, a load maximum) to λ 1246 beyond
        −15 mm with the inertia unchanged; its chord's corrector converges at λ 1198.0, outside
        that bracket, where regula falsi (as before) ends at λ 1880.7, the end state auto's
        check found: two equilibria at the target, one step apart, and no reason to prefer the
        chord's.
        """
        neg = last.negative_pivots
        if neg is None or trial.factorization.negative_pivots != neg:
            return None
        u0 = last.u + frac * (trial.u - last.u)
        lam0 = last.load_factor + frac * (trial.load_factor - last.load_factor)
        constraint = (LoadConstraint(target) if name == "λ"
                      else ProbeConstraint(self.c[name], target, self.dot))
        res = self._correct(u0, lam0, constraint, self._newton_settings(), last.u,
                            last.load_factor)
        if not res.converged or res.factorization is None:
            return None
        reach = self.wnorm(u0 - last.u, lam0 - last.load_factor)
        if self.wnorm(res.u - u0, res.load_factor - lam0) > self.opt.max_correction_ratio * reach:
            return None
        sigma = self.sigma
        back = self._turns_back(res.u - last.u, u0 - last.u)
        self.sigma = sigma  # refused, not retried: keep the arc's sign
        low, high = sorted((last.load_factor, trial.load_factor))
        if back or res.factorization.negative_pivots != neg or not low <= res.load_factor <= high \
                or (self.admissible is not None and self.admissible(res.u)):
            return None
        return _Trial(res.u, res.load_factor, res.iterations, res.factorization, res.rises)

    def _attempt_target(self, name: str, target: float, last: PathState,
                        t: np.ndarray, first: float = 1.0) -> _Trial | None:
        """Reach ``value(name) = target`` from ``last`` under that control (None if it fails).

        Load or displacement control of the crossed quantity, in sub-increments halved on a
        failure (at most ``TARGET_SUBSTEP_CUTS`` times) and doubled after a success: a corrector
        from the linear predictor over the whole remaining distance can fail where a contact
        state changes within it (fig. 7 c4 at 40 elements). The sub-increments are corrector
        internals; the accepted step goes from ``last`` to the target. ``first``: the fraction
        of the distance the first sub-increment covers (½ on a step across a critical point,
        :meth:`_hit_crossed_target`: ``last``'s tangent predicts poorly beyond it — fig. 7 c1
        at the paper's core: over the whole distance the corrector fails after 25 iterations,
        over half of it it converges in 4; the same end state, 135 → 110 iterations).
        """
        v0 = self._value(name, last.u, last.load_factor)
        u, lam, tangent, done, frac, cuts, iters = last.u, last.load_factor, t, v0, first, 0, 0
        trial = None
        while True:
            goal = done + frac * (target - done)
            trial = self._control_to(name, goal, u, lam, tangent)
            if trial is None:
                cuts += 1
                frac *= 0.5
                if cuts > TARGET_SUBSTEP_CUTS:
                    return None
                continue
            iters += trial.iterations
            u, lam, done = trial.u, trial.load_factor, goal
            if frac == 1.0:
                break
            tangent = np.asarray(trial.factorization.solve(self.f_ref), dtype=float)
            frac = min(1.0, 2.0 * frac)
        sigma = self.sigma
        back = self._turns_back(u - last.u, u - last.u)
        self.sigma = sigma  # the step is refused, not retried: keep the arc's sign
        if back:
            return None
        if self.admissible is not None and self.admissible(u):
            return None
        return _Trial(u, lam, iters, trial.factorization)

    def _control_to(self, name: str, goal: float, u: np.ndarray, lam: float,
                    t: np.ndarray, settings: NewtonSettings | None = None) -> _Trial | None:
        """One corrector from (u, λ) with ``value(name) = goal`` as control equation.

        The predictor is the load tangent ``t`` scaled to the goal; ``settings`` default to
        the path's (:meth:`_newton_settings`).
        """
        if name == "λ":
            dlam, constraint = goal - lam, LoadConstraint(goal)
        else:
            c = self.c[name]
            ct = self.dot(c, t)
            if ct == 0.0 or not math.isfinite(ct):
                return None
            dlam = (goal - self.dot(c, u)) / ct
            constraint = ProbeConstraint(c, goal, self.dot)
        res = self._correct(u + dlam * t, lam + dlam, constraint,
                            settings or self._newton_settings(), u, lam)
        if not res.converged or res.factorization is None:
            return None
        return _Trial(res.u, res.load_factor, res.iterations, res.factorization)

    def _near_target(self, name: str, s: PathState) -> str:
        """Message if a crossed target was missed by at most ``target_accept`` (relative)."""
        opt = self.opt
        if name == opt.until_probe:
            v, target = s.probes[name], opt.until_value
        elif opt.until_load_factor is not None:
            v, target = s.load_factor, opt.until_load_factor
        else:
            return ""
        if abs(v - target) <= opt.target_accept * abs(target):
            return (f"reached {name} = {v:.6g} (target {target:.6g}, hit within "
                    f"{abs(v - target) / abs(target):.1e} relative, not within target_tol = "
                    f"{opt.target_tol:g}) at step {s.step}, λ = {s.load_factor:.6g}")
        return ""

    def _target_reached(self) -> str:
        """Message if the last state satisfies a stopping target, else ``""``."""
        s = self.states[-1]
        opt = self.opt
        if opt.until_load_factor is not None:
            tol = opt.target_tol * abs(opt.until_load_factor)
            if abs(s.load_factor - opt.until_load_factor) <= tol:
                return (f"reached λ = {s.load_factor:.6g} (target {opt.until_load_factor:.6g}) "
                        f"at step {s.step}")
        if opt.until_probe is not None:
            v = s.probes[opt.until_probe]
            scale = max(abs(opt.until_value), *(abs(x.probes[opt.until_probe])
                                                for x in self.states))
            if abs(v - opt.until_value) <= opt.target_tol * scale:
                return (f"reached {opt.until_probe} = {v:.6g} (target {opt.until_value:.6g}) "
                        f"at step {s.step}, λ = {s.load_factor:.6g}")
        return ""


def follow_path(
    system: DiscreteSystem,
    options: PathOptions,
    probe_names: Sequence[str],
    progress: Callable[[PathState], None] | None = None,
) -> PathResult:
    """Follow the equilibrium path of ``system`` from the unloaded state.

    Parameters
    ----------
    system
        The model (see :class:`~sandwich.solver.system.DiscreteSystem`).
    options
        Control, stopping rules and tolerances.
    probe_names
        Probes recorded in every state (the until and driven probes are always added).
    progress
        Called with every converged state (state 0 included), after ``system.commit``.

    Returns
    -------
    PathResult
        All converged states (never NaN), whether a target was reached, a message saying where
        and why the path stopped, and the limit points / bifurcations found along it.
    """
    return _Follower(system, options, probe_names, progress).run()
