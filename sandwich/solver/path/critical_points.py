"""Critical points inside a step: a bifurcation crossed, a load extremum passed.

After each accepted step the follower locates, within it, where the tangent's inertia changed
(a bifurcation or a limit point, :meth:`CriticalPoints.locate_crossing`) and where the load
curve turned over (:meth:`CriticalPoints.locate_extremum`): from the step's two states alone,
or, with ``locate_critical_points``, narrowed by equilibria solved inside the step from its
first state (the path's own predictor and corrector, :meth:`CriticalPoints._inside_step`),
which are not path states: the path is the same with or without them.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from sandwich.solver.critical import (
    LOCATE_RTOL,
    MAX_CROSSINGS,
    MAX_SUBSTEPS,
    SAFEGUARD,
    BracketEnd,
    crossed_eigenvalue,
    crossing_in,
    halved,
    next_fraction,
)
from sandwich.solver.critical import locate_crossing as crossing_from_factorizations
from sandwich.solver.extrema import Extremum, SlopeEnd, located_in, turns_over
from sandwich.solver.newton import RECOVERABLE_ERRORS
from sandwich.solver.path.attempts import StepAttempts
from sandwich.solver.path.records import PathState, Trial

__all__ = ["CriticalPoints"]


class CriticalPoints(StepAttempts):
    """The bifurcation and the load extremum located within an accepted step."""

    def locate_crossing(self, state: PathState, last: PathState, fac_before: object,
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
        by one on a step with a located load extremum (:meth:`locate_extremum`, run first),
        which :func:`~sandwich.solver.limits.find_limit_points` reads as that extremum's.
        """
        a, b = last.negative_pivots, state.negative_pivots
        if a is None or b is None or a == b:
            return
        h = self.increment(last, state)
        try:
            c = crossing_from_factorizations(fac_before, fac, b - a, self.system.size,
                                             self.dot, state.u - last.u)
        except RECOVERABLE_ERRORS:  # a solve that fails: no crossing located at the state
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

    def locate_extremum(self, state: PathState, last: PathState, t: np.ndarray,
                        t_next: np.ndarray) -> None:
        """Locate a load extremum within the step ``last`` → ``state``.

        :mod:`sandwich.solver.extrema`, from the two states' loads, probes and load tangents alone
        (``t`` at ``last``, ``t_next`` at ``state``; no solve): where the path's tangent, oriented
        forward along the step (the sense of t·Δu + ψ²Δλ), turns its λ component over while w keeps
        moving the step's way, the stationary point of λ's cubic Hermite interpolant in w. Then,
        with ``locate_critical_points``, steps from ``last`` under the path's control aimed at that
        point (the middle of the bracket where the interpolant is refused) narrow the bracket, each
        equilibrium's tangent from one solve with its factorisation, as :meth:`locate_crossing`
        narrows a bifurcation.
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
        h = self.increment(last, state)
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
            rate = None if tangent is None else self.probe_rate(tangent)
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

    def _inside_step(self, h: float, last: PathState, t: np.ndarray) -> Trial | None:
        """A step of ``h`` from ``last`` whose equilibrium is not a path state (or None).

        For narrowing a critical point: the path's settings (contact-limited corrections, the
        arc's sense) are left as they were, whatever the corrector does.
        """
        failed_once, sigma = self.failed_once, self.sigma
        try:
            trial, _ = self.attempt(h, last, t)
        except RECOVERABLE_ERRORS:
            trial = None
        self.failed_once, self.sigma = failed_once, sigma
        return trial
