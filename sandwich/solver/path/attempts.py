"""One step attempt: predictor along the load tangent, corrector under the path's control.

:meth:`StepAttempts.attempt` is one predictor–corrector try of a given increment from the last
state, under the guards against jumps (the predictor at most ``max_predictor_growth`` × the
previous step, the corrector at most ``max_correction_ratio`` × the predictor from it), the
retrace test and admissibility (:mod:`.guards`); :meth:`StepAttempts.control_to` is one
corrector to a given value of λ or a probe (the targets' and the walks' step). Every corrector
of the path runs through :meth:`StepAttempts.correct`, which turns contact-limited corrections
on for the rest of the path at the first failure (:data:`LIMIT_AFTER_FAILURE`).
"""

from __future__ import annotations

import math

import numpy as np

from sandwich.solver.controls import ArcLengthConstraint, LoadConstraint, ProbeConstraint
from sandwich.solver.newton import NewtonResult, NewtonSettings, newton_correct
from sandwich.solver.path.guards import INADMISSIBLE, StepGuards
from sandwich.solver.path.records import PathState, Trial

__all__ = ["LIMIT_AFTER_FAILURE", "StepAttempts"]

#: Contact-limited corrections (``NewtonSettings.limit_corrections``, for a system with
#: ``correction_limit``) from the first failed corrector of a path on (docs/solver.md,
#: "Contact-limited corrections").
LIMIT_AFTER_FAILURE = True


class StepAttempts(StepGuards):
    """Predictor–corrector tries from the last state, under the guards of :mod:`.guards`."""

    @property
    def limit_corrections(self) -> bool:
        """Contact-limited corrections: on once a corrector of this path has failed."""
        return self.failed_once and LIMIT_AFTER_FAILURE

    def arc_direction(self, t: np.ndarray, last: PathState) -> float:
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

    def attempt(self, h: float, last: PathState, t: np.ndarray, rises: int = 0,
                limit: bool | None = None) -> tuple[Trial | None, str]:
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
        res = self.correct(last.u + du_pred, last.load_factor + dlam, constraint,
                           self.newton_settings(rises, limit), last.u, last.load_factor)
        if not res.converged or res.factorization is None:
            return None, res.reason
        dist = self.wnorm(res.u - last.u - du_pred, res.load_factor - last.load_factor - dlam)
        if dist > opt.max_correction_ratio * pred_len:
            return None, (f"corrector moved {dist:.3g} from a predictor of length {pred_len:.3g}"
                          f" (jump to another branch?)")
        why = self.turns_back(res.u - last.u, du_pred)
        if why:
            return None, why
        why = self.inadmissible(res.u)
        if why:
            return None, f"{INADMISSIBLE}: {why}"
        return Trial(res.u, res.load_factor, res.iterations, res.factorization,
                     res.rises, res.increment_iterations), "converged"

    def control_to(self, name: str, goal: float, u: np.ndarray, lam: float,
                   t: np.ndarray, settings: NewtonSettings | None = None) -> Trial | None:
        """One corrector from (u, λ) with ``value(name) = goal`` as control equation.

        The predictor is the load tangent ``t`` scaled to the goal; ``settings`` default to
        the path's (:meth:`newton_settings`).
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
        res = self.correct(u + dlam * t, lam + dlam, constraint,
                           settings or self.newton_settings(), u, lam)
        if not res.converged or res.factorization is None:
            return None
        return Trial(res.u, res.load_factor, res.iterations, res.factorization)

    def newton_settings(self, rises: int = 0, limit: bool | None = None) -> NewtonSettings:
        """Corrector settings; the force floor is ‖f_ref‖ × the largest |λ| reached so far.

        ``rises``: the rising test's ``divergence_rises`` (0: off). ``limit``: contact-limited
        corrections; by default as the path has them (on once a corrector of this path has
        failed, :meth:`correct`).
        """
        floor = (math.sqrt(self.dot(self.f_ref, self.f_ref))
                 * max(abs(s.load_factor) for s in self.states))
        return NewtonSettings(tol=self.opt.tol, max_iterations=self.opt.max_iterations,
                              psi=self.psi, force_floor=floor, divergence_rises=rises,
                              limit_corrections=(self.limit_corrections if limit is None
                                                 else limit))

    def correct(self, u: np.ndarray, lam: float, constraint: object, settings: NewtonSettings,
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
