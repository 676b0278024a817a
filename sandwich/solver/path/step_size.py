"""Step size control: the increment after each step, weighed by its corrector's iterations.

:class:`StepSize` halves the increment on a failed try and, after a converged step, scales it
by ``√(desired_iterations / iterations)`` within [½, 2] (never grown after a cut step), clipped
to [min_increment, max_increment]. :class:`StepSizeControl` says which iterations a step is
weighed by: with ``settling_allowance`` k (off unless a model sets it; the beam sets 2), at
most those until the corrector's increment test first passed plus k, as long as no corrector
of the path has failed and the load curve's last two steps turn by less than
:data:`SETTLING_BEND`. A step so grown whose secant turns from its predictor by more is cut
(reason :data:`BENT`), and its converged state is then the step after the retry where it lies
ahead of the retry's state within :data:`HALF_REACH` × the increment the controller asks for
then (docs/solver.md, "Settling iterations").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sandwich.solver.path.guards import StepGuards
from sandwich.solver.path.options import PathOptions
from sandwich.solver.path.records import PathState, Trial

__all__ = ["BENT", "HALF_REACH", "SETTLING_BEND", "StepSize", "StepSizeControl"]

BENT = "the load curve bends within a step the settling allowance grew"  # that cut's reason
#: The settling allowance (``PathOptions.settling_allowance``) weighs a step only where the
#: path's last two steps turn by less than this angle (radians) in the plane of its load curve
#: (:meth:`StepSizeControl.weighed_iterations`; docs/solver.md, "Settling iterations").
SETTLING_BEND = math.radians(2.0)
#: A step cut as BENT: its converged state is the step after the retry where that step is at
#: most this many times the increment the step-size controller asks for then
#: (:meth:`StepSizeControl.bent_half`).
HALF_REACH = 1.25


@dataclass
class StepSize:
    """The step-size controller: the increment ``h`` in the units of the control and its bounds.

    Halved on a failed try (by :meth:`~.follower.PathFollower.converge_step`); after a
    converged step scaled by ``√(desired_iterations / iterations)`` within [½, 2], never grown
    after a cut, and kept in [``h_min``, ``h_max``].
    """

    h: float
    h_min: float
    h_max: float
    desired_iterations: int
    by_allowance: bool = False  # h was grown by the settling allowance's weighing

    @classmethod
    def start(cls, opt: PathOptions, h_auto: Callable[[], float]) -> StepSize:
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

        ``iterations``: those the step is weighed by
        (:meth:`StepSizeControl.weighed_iterations`), fewer than ``all_iterations`` where the
        settling allowance applied (:attr:`by_allowance`).
        """
        factor = math.sqrt(self.desired_iterations / max(iterations, 1))
        factor = min(max(factor, 0.5), 2.0)
        if cuts:
            factor = min(factor, 1.0)
        self.h = min(max(h_try * factor, self.h_min), self.h_max)
        self.by_allowance = iterations < all_iterations and not cuts


def _cosine(a: tuple[float, float], b: tuple[float, float]) -> float | None:
    """The cosine of the angle between two plane vectors; None if either is zero or not finite."""
    na, nb = math.hypot(*a), math.hypot(*b)
    if not (0.0 < na < math.inf and 0.0 < nb < math.inf):
        return None
    return float((a[0] * b[0] + a[1] * b[1]) / (na * nb))


class StepSizeControl(StepGuards):
    """The first increment, the iterations a step is weighed by, a bent step's kept state."""

    def auto_increment(self, t: np.ndarray) -> float:
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

    def weighed_iterations(self, trial: Trial) -> int:
        """The iterations the step-size controller weighs a converged step by.

        All of them, unless :attr:`PathOptions.settling_allowance` is set, no corrector of
        this path has failed and the load curve's last two steps turn by less than
        :data:`SETTLING_BEND` (:meth:`_straight`): then at most the iterations until the
        increment test first passed plus that allowance (the others settle a residual while
        the state no longer moves — the beam's contact pairs in the penalty law's knee — and
        do not shrink with the step). A step so grown is checked for a bend within it
        (:meth:`bends_within`).
        """
        k = self.opt.settling_allowance
        if k is None or self.failed_once or trial.increment_iterations is None:
            return trial.iterations
        if not self._straight():
            return trial.iterations
        return min(trial.iterations, trial.increment_iterations + k)

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

    def bends_within(self, last: PathState, trial: Trial, t: np.ndarray) -> bool:
        """Whether a step's secant turns from its predictor by more than SETTLING_BEND.

        In the load curve's plane (:meth:`_straight`), the predictor along the tangent
        K⁻¹ f_ref at ``last``, either sense: a knee the step has crossed (the debonded face's
        buckling, a crushing) that the steps before it could not announce.
        """
        name = self.curve_probe[0]
        if name is None:
            return False
        p = self._in_curve_plane(self.dot(self.c[name], t), 1.0)
        d = self._in_curve_plane(self.value(name, trial.u, 0.0) - last.probes[name],
                                 trial.load_factor - last.load_factor)
        cos = _cosine(p, d)
        return cos is not None and abs(cos) < math.cos(SETTLING_BEND)

    def bent_half(self, last: PathState, h: float) -> Trial | None:
        """The converged state of a step cut as ``BENT``, as the step after its retry.

        A step the settling allowance grew converged at X but bent within it (:data:`BENT`);
        it was cut, and its retry from the same start at half the length converged at
        ``last``. X is an equilibrium of the same path (the corrector converged there, under
        the same guards) ahead of ``last``: it is taken as the next step where that step is no
        longer than :data:`HALF_REACH` × the increment ``h`` the controller asks for now (in
        the units of the control, :meth:`~.state.FollowerState.increment`: the path is sampled
        as finely as the controller's own step would sample it), its displacement increment
        makes an angle of at most 90° with the retry's (the test of
        :meth:`~.guards.StepGuards.turns_back`, with ``min_step_cosine``) and no stopping
        target lies between (:meth:`~.state.FollowerState.crossings`); else the path steps on
        as usual. Saves the corrector that repeats the second half (fig. 5 at the paper's core:
        107 corrector iterations in all instead of 115). The increment after it is the one the
        retry left (X's iterations were a whole step's, from the bent step's start). Taken
        once: the kept state is dropped at any other step.
        """
        kept, self.bent = self.bent, None
        if kept is None or len(self.states) < 2 or self.states[-2].step != kept[0]:
            return None  # nothing kept, or not right after the retry from the bent step's start
        trial, start = kept[1], self.states[-2]
        cos = self.step_cosine(trial.u - last.u, last.u - start.u)
        if (cos is None or cos < self.opt.min_step_cosine
                or not 0.0 < self.increment(last, trial) <= HALF_REACH * h
                or self.crossings(last, trial)):
            return None
        return trial
