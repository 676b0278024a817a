"""Rescue and branch walking: a probe-controlled step where the arc collapses, the branch left.

Where an arc-length path with an ``until_probe`` has its arc cut far below the largest step so
far (a critical point it cannot pass), :meth:`RescueSteps.probe_rescue` tries one step under
control of that probe, as a testing machine driving that point would. Such a step, and an arc
step that may have jumped past a snap (:meth:`~.guards.StepGuards.jumped`), may leave a branch
that ends inside the step: :meth:`RescueSteps.walk_branch_left` walks it to bound its top.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from sandwich.solver.extrema import Extremum
from sandwich.solver.newton import RECOVERABLE_ERRORS, NewtonSettings
from sandwich.solver.path.records import PathState, Trial
from sandwich.solver.path.targets import TargetSteps

__all__ = ["RESCUE_FRACTION", "RESCUE_MEMORY", "WALK_LOSS", "WALK_MIN_FRACTION",
           "WALK_SLOPE_KEPT", "WALK_TRIES", "RescueSteps"]

RESCUE_FRACTION = 0.05  # probe rescue: tried once the arc is cut below this × its largest so far
RESCUE_MEMORY = 5  # accepted steps remembered for the rescue step's probe change
#: The walk along the branch a step jumped from (:meth:`RescueSteps.walk_branch_left`): its
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


class RescueSteps(TargetSteps):
    """The probe rescue of a collapsed arc, and the walk along the branch a step left."""

    def rescue_due(self, cuts: int, h: float) -> bool:
        """Whether the arc has collapsed enough to try :meth:`probe_rescue`."""
        opt = self.opt
        if not (opt.probe_rescue and opt.control == "arc-length" and opt.until_probe
                and self.recent and cuts >= 1):
            return False
        return h < RESCUE_FRACTION * self.peak

    def probe_rescue(self, last: PathState, t: np.ndarray) -> tuple[Trial | None, bool]:
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
        return self.attempt_target(name, target, last, t), direct

    def walk_branch_left(self, state: PathState, last: PathState, t: np.ndarray) -> None:
        """The furthest load on the branch a step jumped from: a bound of its top.

        A probe rescue (:meth:`probe_rescue`) is taken where the arc collapsed, and an arc step may
        converge past a snap (:meth:`~.guards.StepGuards.jumped`); in both the branch from ``last``
        may end inside the step (the debonded face snaps: fig. 6 as shipped, the knock-down study's
        off-centre debonds). Its top then lies inside the step, and neither the step's states nor
        their slopes see it: both tangents rise, the one at ``state`` on the branch the step
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
                self.newton_settings(self.divergence_rises, self.limit_corrections),
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
                    self.probe_rate(tangent)
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
                    beyond = self.control_to(name, goal, u, lam, tangent)
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
                  settings: NewtonSettings) -> tuple[Trial | None, int]:
        """One corrector of :meth:`walk_branch_left` to ``value(name) = goal``.

        Returns the equilibrium (None: off the branch) and the change of the tangent's
        negative pivots from ``negative_pivots`` (0 where either is unknown).

        :meth:`~.attempts.StepAttempts.control_to` from ``(u, λ)`` with the load tangent ``t``;
        ``settings`` are the path's corrector settings at the walk's start (rising test,
        contact-limited corrections) with at most ``desired_iterations`` iterations (the walk's
        steps are short: on fig. 6 those that converge take 3-6 iterations, while those that do not
        ran to the 25 allowed). Off the branch: a failed corrector, a corrector that moved more than
        ``max_correction_ratio`` × the predictor from it (a jump to another branch), an inadmissible
        state.
        """
        try:
            trial = self.control_to(name, goal, u, lam, t, settings)
        except RECOVERABLE_ERRORS:
            trial = None
        if trial is None:
            return None, 0
        c = self.c[name]
        dlam = (goal - self.dot(c, u)) / self.dot(c, t)  # the predictor of control_to
        reach = self.wnorm(dlam * t, dlam)
        if self.wnorm(trial.u - u - dlam * t, trial.load_factor - lam - dlam) > \
                self.opt.max_correction_ratio * reach:
            return None, 0
        if self.inadmissible(trial.u):
            return None, 0
        neg = trial.factorization.negative_pivots
        change = 0 if negative_pivots is None or neg is None else neg - negative_pivots
        return trial, change
