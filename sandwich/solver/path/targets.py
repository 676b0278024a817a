"""Stopping targets: hitting a crossed one, the hard step across a critical point and it.

A step whose control is not the target's own (arc-length, or a driven probe other than the
until probe) may overshoot the target. :meth:`TargetSteps.hit_crossed_target` then shortens it
onto the target: one corrector from the chord's point on it (a regular step,
:meth:`~TargetSteps.chord_target`), the target under its own control in sub-increments (a step
across a critical point, :meth:`~TargetSteps.attempt_target`), else regula falsi on the step's
length. A directly controlled target is hit exactly by clipping the increment
(:meth:`~TargetSteps.clip_to_target`). A converged step across both a critical point and the
target that needed more than ``desired_iterations`` is cut instead
(:meth:`~TargetSteps.hard_across_target`).
"""

from __future__ import annotations

import math

import numpy as np

from sandwich.solver.controls import LoadConstraint, ProbeConstraint
from sandwich.solver.path.attempts import StepAttempts
from sandwich.solver.path.records import PathResult, PathState, Trial, format_probes

__all__ = ["CRITICAL_TARGET", "CRITICAL_TARGET_CUTS", "TARGET_SUBSTEP_CUTS", "TargetSteps"]

TARGET_SUBSTEP_CUTS = 6  # halvings of the sub-increment when a crossed target is hit directly
#: A step that crosses both a critical point and a stopping target, converging only after more
#: than ``desired_iterations``, is cut and retried up to this many times (then accepted): the
#: target is then approached by ordinary steps past the critical point (docs/solver.md, "The
#: last step across a critical point").
CRITICAL_TARGET_CUTS = 2
CRITICAL_TARGET = "a hard step across a critical point and the target"  # that cut's reason


class TargetSteps(StepAttempts):
    """The stopping targets: clipping to them, hitting a crossed one, telling one reached."""

    def clip_to_target(self, h: float, last: PathState) -> tuple[float, bool, float | None]:
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

    def hit_crossed_target(
        self, trial: Trial, h: float, last: PathState, t: np.ndarray
    ) -> tuple[Trial, float, str]:
        """If ``trial`` overshoots a stopping target, shorten the step to hit it.

        A regular step (the tangent's inertia the same at ``last`` and ``trial``): first one
        corrector from the chord's point on the target (:meth:`chord_target`). A step across a
        critical point (the inertia changed): first the target under its own control from
        ``last``, in sub-increments (:meth:`attempt_target`) — the arc passed a load maximum
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
        crossed = self.crossings(last, trial)
        if not crossed:
            return trial, h, ""
        frac, name, target = crossed[0]
        neg = last.negative_pivots
        across = neg is not None and trial.factorization.negative_pivots not in (neg, None)
        first = (self.attempt_target(name, target, last, t, 0.5) if across
                 else self.chord_target(name, target, frac, last, trial))
        if first is not None:
            return first, self.wnorm(first.u - last.u, first.load_factor - last.load_factor), name
        scale = max(abs(target), *(abs(self.value(name, s.u, s.load_factor))
                                   for s in self.states))
        tol = self.opt.target_tol * scale
        a, fa = 0.0, self.value(name, last.u, last.load_factor) - target
        b, fb = h, self.value(name, trial.u, trial.load_factor) - target
        best, best_h, best_g = trial, h, fb
        side = 0
        for _ in range(40):
            if abs(best_g) <= tol or fa == fb:
                break
            x = (a * fb - b * fa) / (fb - fa)
            if not (min(a, b) < x < max(a, b)):
                x = 0.5 * (a + b)
            cand, _ = self.attempt(x, last, t)
            if cand is None and not math.isclose(x, 0.5 * (a + b)):
                # a very short step can trip the jump guard (corrector longer than predictor):
                # fall back to the middle of the bracket once before giving up
                x = 0.5 * (a + b)
                cand, _ = self.attempt(x, last, t)
            if cand is None:
                break
            fx = self.value(name, cand.u, cand.load_factor) - target
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
            direct = self.attempt_target(name, target, last, t)
            if direct is not None:
                return direct, self.wnorm(direct.u - last.u,
                                          direct.load_factor - last.load_factor), name
        return best, best_h, name

    def chord_target(self, name: str, target: float, frac: float, last: PathState,
                     trial: Trial) -> Trial | None:
        """The crossed target hit by one corrector from the chord's point on it (None: failed).

        ``trial`` overshot ``value(name) = target``, which the chord from ``last`` to ``trial``
        meets at ``frac`` (values are linear in u and λ: the chord's point is on the target).
        From that point, a corrector with the target as control equation (load or displacement
        control) — in one go what regula falsi on the arc's length approaches by a corrector
        per trial (fig. 5: two; fig. 7 c1, whose correctors near the target hunt for their
        contact set: five, three of them failing, then the sub-incremented target control).
        Accepted under the step's guards with the chord as predictor: the corrector moves at
        most ``max_correction_ratio`` × the chord's part from it, does not turn back, stays
        admissible; else :meth:`hit_crossed_target` goes on by regula falsi as before.

        Tried only on a regular step: the tangent's inertia (negative pivots) the same at
        ``last``, ``trial`` and the result, and the result's λ between ``last``'s and
        ``trial``'s. A step across a critical point is no chord: fig. 7 c1 at the paper's core,
        whose long last arc (24 iterations) passes the load maximum (0 → 1 negative pivots) and
        lands on another equilibrium beyond the target; from its chord the corrector converges
        at λ 691.6, on that other equilibrium, while the path followed in short steps reaches
        the target at λ 758.4, as the sub-incremented target control does (which
        :meth:`hit_crossed_target` tries first on such a step). fig. 4's auto pass at levels
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
        res = self.correct(u0, lam0, constraint, self.newton_settings(), last.u,
                            last.load_factor)
        if not res.converged or res.factorization is None:
            return None
        reach = self.wnorm(u0 - last.u, lam0 - last.load_factor)
        if self.wnorm(res.u - u0, res.load_factor - lam0) > self.opt.max_correction_ratio * reach:
            return None
        sigma = self.sigma
        back = self.turns_back(res.u - last.u, u0 - last.u)
        self.sigma = sigma  # refused, not retried: keep the arc's sign
        low, high = sorted((last.load_factor, trial.load_factor))
        if back or res.factorization.negative_pivots != neg or not low <= res.load_factor <= high \
                or self.inadmissible(res.u):
            return None
        return Trial(res.u, res.load_factor, res.iterations, res.factorization, res.rises)

    def attempt_target(self, name: str, target: float, last: PathState,
                       t: np.ndarray, first: float = 1.0) -> Trial | None:
        """Reach ``value(name) = target`` from ``last`` under that control (None if it fails).

        Load or displacement control of the crossed quantity, in sub-increments halved on a
        failure (at most ``TARGET_SUBSTEP_CUTS`` times) and doubled after a success: a corrector
        from the linear predictor over the whole remaining distance can fail where a contact
        state changes within it (fig. 7 c4 at 40 elements). The sub-increments are corrector
        internals; the accepted step goes from ``last`` to the target. ``first``: the fraction
        of the distance the first sub-increment covers (½ on a step across a critical point,
        :meth:`hit_crossed_target`: ``last``'s tangent predicts poorly beyond it — fig. 7 c1
        at the paper's core: over the whole distance the corrector fails after 25 iterations,
        over half of it it converges in 4; the same end state, 135 → 110 iterations).
        """
        v0 = self.value(name, last.u, last.load_factor)
        u, lam, tangent, done, frac, cuts, iters = last.u, last.load_factor, t, v0, first, 0, 0
        trial = None
        while True:
            goal = done + frac * (target - done)
            trial = self.control_to(name, goal, u, lam, tangent)
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
        back = self.turns_back(u - last.u, u - last.u)
        self.sigma = sigma  # the step is refused, not retried: keep the arc's sign
        if back:
            return None
        if self.inadmissible(u):
            return None
        return Trial(u, lam, iters, trial.factorization)

    def hard_across_target(self, last: PathState, trial: Trial) -> bool:
        """Whether ``trial`` crossed a critical point and a stopping target, the hard way.

        The tangent's inertia changed between ``last`` and ``trial``, the step passed the ``until``
        target, and the corrector needed more than ``desired_iterations``. Such a step is shortened
        (:meth:`~.follower.PathFollower.converge_step`, at most ``CRITICAL_TARGET_CUTS`` times)
        instead of being handed to :meth:`hit_crossed_target`, whose target control from ``last`` —
        before the critical point — can land on another equilibrium: fig. 7 c1 at the paper's core,
        120 elements, stepped from λ 556 (w −23.2 mm) to the target in one step of 15 iterations and
        ended at λ 735.38, where the path in steps of at most 15 reaches −40 mm at λ 860.66 (and so
        does it with this cut, in 8 steps); at 40-480 elements the default steps and the short ones
        agree.
        """
        neg = last.negative_pivots
        return (neg is not None and trial.factorization.negative_pivots != neg
                and trial.iterations > self.opt.desired_iterations
                and bool(self.crossings(last, trial)))

    def target_reached(self) -> str:
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

    def finish_crossed(self, crossed: str) -> PathResult:
        """End of a path whose step crossed the target on ``crossed`` without hitting it."""
        s = self.states[-1]
        near = self._near_target(crossed, s)
        if near:
            return self.finish(True, near)
        return self.finish(False, (
            f"step {s.step}: the target on {crossed} was crossed but could not be hit "
            f"within target_tol = {self.opt.target_tol:g} (stopped at λ = "
            f"{s.load_factor:.6g}, {format_probes(s.probes)})"))

    # -- pieces ------------------------------------------------------------------------------
