"""The path follower: the step loop, and :func:`follow_path`.

:class:`PathFollower` is composed of one part per concern, each a class of its own module that
builds on the parts it uses (all on :class:`~.state.FollowerState`, the state they share):

- :class:`~.guards.StepGuards` — the retrace test, jump detection, admissibility;
- :class:`~.attempts.StepAttempts` — one predictor–corrector try, one corrector to a value;
- :class:`~.targets.TargetSteps` — the stopping targets: clipped to, hit when crossed, reached;
- :class:`~.step_size.StepSizeControl` — the first increment and the settling allowance
  (the increment itself: :class:`~.step_size.StepSize`);
- :class:`~.critical_points.CriticalPoints` — a bifurcation or load extremum inside a step;
- :class:`~.rescue.RescueSteps` — the probe rescue of a collapsed arc, the branch a step left;
- :class:`~.switching.SystemSwitch` — going on on a finer system (the caller's ``refine``).

The return guard is a collaborator (:class:`~.guards.ReturnGuard`). This module holds the loop
(:meth:`PathFollower.converged_states`) and a step's tries with their cuts
(:meth:`PathFollower.converge_step`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Sequence

import numpy as np

from sandwich.solver.newton import RECOVERABLE_ERRORS, RISING
from sandwich.solver.path.critical_points import CriticalPoints
from sandwich.solver.path.guards import INADMISSIBLE, ReturnGuard
from sandwich.solver.path.options import PathOptions
from sandwich.solver.path.records import PathResult, PathState, Trial, format_probes
from sandwich.solver.path.rescue import RESCUE_MEMORY, RescueSteps
from sandwich.solver.path.step_size import BENT, StepSize, StepSizeControl
from sandwich.solver.path.switching import RefineHook, SystemSwitch
from sandwich.solver.path.targets import CRITICAL_TARGET, CRITICAL_TARGET_CUTS
from sandwich.solver.system import DiscreteSystem

__all__ = ["DIVERGENCE_RISES", "PathFollower", "follow_path", "solve_linear"]

#: The corrector's rising test (``NewtonSettings.divergence_rises``) on a step's attempts until
#: one fails by it; the retries of that step, the target's and the rescue's correctors run without,
#: and the rest of the path once a corrector converged after rising so (docs/speed.md,
#: "Corrector attempts that diverge").
DIVERGENCE_RISES = 2


class PathFollower(RescueSteps, CriticalPoints, StepSizeControl, SystemSwitch):
    """State machine of :func:`follow_path` (one instance per call): the parts composed.

    Every method is defined in exactly one part (none overrides another), so the order of the
    bases decides nothing; each part's bases are the parts whose methods it calls.
    """

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

        One step is :meth:`converge_step` (predictor-corrector tries with cuts and the probe
        rescue), then the target strategies (:meth:`hit_crossed_target`,
        :meth:`target_reached`, :meth:`finish_crossed`), then the step-size controller
        (:class:`~.step_size.StepSize`). The follower's state (last states, previous step, arc
        sign, rescue memory) lives in this object (:class:`~.state.FollowerState`).
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
        size = self._start(first, t, tn)

        while len(self.states) - 1 < opt.max_steps:
            last = self.states[-1]
            step = last.step + 1
            if opt.control == "arc-length":
                self.sigma = self.arc_direction(t, last)
            outcome = self.converge_step(size, last, t, step)
            if isinstance(outcome, str):
                return self.finish(False, outcome)
            trial, h_try, direct, cuts = outcome
            crossed = ""
            if not direct:
                trial, h_try, crossed = self.hit_crossed_target(trial, h_try, last, t)
            self.prev_step = (trial.u - last.u, trial.load_factor - last.load_factor)
            if opt.until_probe is not None:
                dv = self.value(opt.until_probe, trial.u, 0.0) - last.probes[opt.until_probe]
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
            # a path-dependent system's states are not its (u, λ) alone: an unloading past a
            # snap-back passes near states it was at before, with another history
            back = ("" if getattr(self.system, "path_dependent", False)
                    else self.return_guard.retracing(self.states))
            if back:
                return self.finish(False, back)
            try:
                t_next = np.asarray(fac.solve(self.f_ref), dtype=float)
            except RECOVERABLE_ERRORS as exc:  # pragma: no cover - factorization succeeded
                return self.finish(False, f"step {step + 1}: load tangent failed ({exc})")
            state.probe_rate = self.probe_rate(t_next)
            self.locate_extremum(state, last, t, t_next)
            if (self.rescues and self.rescues[-1] == step) or self.jumped(last, state, t):
                self.walk_branch_left(state, last, t)
            self.locate_crossing(state, last, fac_before, fac, t)
            fac_before = None  # not needed again: the next step's corrector makes its own
            switched = self.switch_system(state)
            if switched is not None:  # the state re-converged on a finer system replaces it
                fac, t = switched
                yield self.states[-1]
                if self.states[-1].step < state.step:
                    continue  # rewound: the step is taken again on the new system
            else:
                t = t_next
            done = self.target_reached()
            if done:
                return self.finish(True, done)
            if crossed:
                return self.finish_crossed(crossed)
            kept, self.kept_half = self.kept_half, None
            if trial is kept:
                # its corrector's iterations were a whole bent step's, from the state before:
                # the increment stays as the retry's left it, not grown
                size.by_allowance = False
            else:
                size.after(h_try, self.weighed_iterations(trial), cuts, trial.iterations)
        s = self.states[-1]
        return self.finish(False, (
            f"max_steps = {opt.max_steps} reached at λ = {s.load_factor:.6g} "
            f"({format_probes(s.probes)}) before the target"))

    def converge_step(self, size: StepSize, last: PathState, t: np.ndarray,
                      step: int) -> tuple[Trial, float, bool, int] | str:
        """Try steps from ``last``, halving the increment on failure, with one probe rescue.

        A converged trial across a critical point and the stopping target that needed more than
        ``desired_iterations`` counts as a failure for its first ``CRITICAL_TARGET_CUTS`` tries
        (:meth:`hard_across_target`). Returns the converged trial, its increment, whether it
        hit a controlled target directly, and the number of cuts; or, when the increment would
        go below its floor, the message saying where and why the path stops.
        """
        opt = self.opt
        cuts = 0
        rescued = False
        rises = self.divergence_rises  # the corrector's rising test, until it has cut this step
        limited_failed = False  # a limited attempt of this step failed: the rest without
        while True:
            h_try, direct, sign = self.clip_to_target(size.h, last)
            if sign is not None:  # towards a directly controlled target
                self.sigma = sign
            limit = self.limit_corrections and not limited_failed
            kept = self.bent_half(last, h_try) if cuts == 0 and not direct else None
            if kept is not None:  # the far half of the last step's bent one: converged already
                self.kept_half = kept
                return kept, self.increment(last, kept), False, 0
            trial, reason = self.attempt(h_try, last, t, rises, limit)
            if (trial is not None and size.by_allowance and cuts == 0 and not direct
                    and self.bends_within(last, trial, t)):
                self.bent = (last.step, trial)  # its state may end the cut retry's next step
                trial, reason = None, BENT
            if trial is not None and cuts < CRITICAL_TARGET_CUTS and 0.5 * h_try >= size.h_min \
                    and self.hard_across_target(last, trial):
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
            if not rescued and self.rescue_due(cuts, size.h):
                rescued = True
                trial, direct = self.probe_rescue(last, t)
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
                        f"({format_probes(last.probes)}): the {opt.control} increment was cut "
                        f"{cuts} time(s), last to {h_try:.3g}, and may not go below "
                        f"min_increment = {size.h_min:.3g}; "
                        f"last reason: {reason}.{hint}")

    def _start(self, first: PathState, t: np.ndarray, tn: float) -> StepSize:
        """Fix what the linear solution ``t = K(0)⁻¹ f_ref`` (norm ``tn``) decides; the first size.

        ψ, the return guard, the target's load estimate, the load curve's probe and its rate at
        ``first``, the arc's first sign (towards the target's estimated load), and the rescue's
        memory and the corrector's rising test at their start.
        """
        opt = self.opt
        self.psi = opt.arc_load_weight * tn
        self.return_guard = ReturnGuard(self.dot, self.psi)
        self.lam_est = self._target_load_estimate(t)
        self.curve_probe = self._load_curve_probe(t)
        self.rate_probe = opt.driven_probe or self.curve_probe[0]
        first.probe_rate = self.probe_rate(t)
        size = StepSize.start(opt, lambda: self.auto_increment(t))
        self.prev_step: tuple[np.ndarray, float] | None = None
        self.recent: list[tuple[float, float]] = []  # (increment, until-probe change) accepted
        self.peak = 0.0  # largest accepted increment so far
        self.sigma = 1.0 if self.lam_est >= 0 else -1.0
        if opt.control == "displacement":  # move the probe the way the load would move it
            ct = self.dot(self.c[opt.driven_probe], t)
            self.sigma = math.copysign(1.0, ct * self.lam_est) if ct != 0.0 else 1.0
        self.divergence_rises = DIVERGENCE_RISES  # off once a corrector that rose so converged
        return size

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

    def _load_curve_probe(self, t: np.ndarray) -> tuple[str | None, float]:
        """The load curve's probe and its linear value at the target's estimated load.

        The until probe, else the first probe asked for; (None, 0) without a probe or where
        that value is 0.
        """
        names = [n for n in (self.opt.until_probe,) if n] or list(self.c)
        if not names:
            return None, 0.0
        scale = abs(self.dot(self.c[names[0]], t) * self.lam_est)
        return (names[0], scale) if scale > 0.0 and math.isfinite(scale) else (None, 0.0)


def solve_linear(system: DiscreteSystem, load_factor: float) -> np.ndarray:
    """Return the linear solution ``u = K(0)⁻¹ λ f_ref``."""
    fac = system.factorize(system.tangent(np.zeros(system.size)))
    return np.asarray(fac.solve(load_factor * np.asarray(system.f_ref, dtype=float)), dtype=float)


def follow_path(
    system: DiscreteSystem,
    options: PathOptions,
    probe_names: Sequence[str],
    progress: Callable[[PathState], None] | None = None,
    refine: RefineHook | None = None,
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
        Called with every converged state (state 0 included), after ``system.commit``; a
        state re-converged on a finer system comes again with its step number (the states
        after it are dropped).
    refine
        Asked at every converged state whether the path goes on on a finer system
        (:mod:`.switching`); None: never.

    Returns
    -------
    PathResult
        All converged states (never NaN), whether a target was reached, a message saying where
        and why the path stopped, and the limit points / bifurcations found along it.
    """
    follower = PathFollower(system, options, probe_names, progress)
    follower.refine = refine
    return follower.run()
