"""Guards on converged steps: the retrace test, jump detection, admissibility, the return guard.

A converged corrector is not yet a step of the path. :class:`StepGuards` refuses one that turns
back (Crisfield's angle criterion on the displacement increments, :meth:`~StepGuards.turns_back`)
or whose state the model declares inadmissible (:meth:`~StepGuards.inadmissible`), and tells an
accepted arc step that may have jumped to another branch past a snap
(:meth:`~StepGuards.jumped`). :class:`ReturnGuard` stops a path that has turned onto its own
branch and follows it back, which the step-to-step test cannot see.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from sandwich.solver.path.records import PathState
from sandwich.solver.path.state import FollowerState

__all__ = ["INADMISSIBLE", "JUMP_CORRECTION", "JUMP_LOSS", "RETRACE", "RETURN_FRACTION",
           "RETURN_STATES", "ReturnGuard", "StepGuards"]

INADMISSIBLE = "inadmissible state"  # prefix of the reason of a step rejected by admissible()
RETRACE = "the step turns back"  # prefix of the reason of a step rejected by the retrace guard
#: A step of an arc-length path whose load change falls short of its tangent's by more than
#: this fraction, with the tangent's inertia unchanged, may have jumped to another branch past
#: a snap: the branch it left is walked as a rescued step's is (:meth:`StepGuards.jumped`,
#: :meth:`~.rescue.RescueSteps.walk_branch_left`) ...
JUMP_LOSS = 0.3
#: ... or that leaves its tangent's line by more than this fraction of its projection on it
#: (an arc step: its corrector's distance over its predictor's length; the face's snapped
#: shape appears in the correction, at little loss of load).
JUMP_CORRECTION = 0.25
#: A converged state closer than this fraction of a passed step's length to that step's chord
#: (in the norm ‖(u, ψλ)‖; a step the path has since travelled away from by its length) lies on
#: the path already followed; RETURN_STATES such states in a row: the path is retracing its
#: branch (:meth:`ReturnGuard.retracing`).
RETURN_FRACTION = 0.1
RETURN_STATES = 3


class StepGuards(FollowerState):
    """The tests a converged step must pass, and the jump test on an accepted one."""

    def turns_back(self, du: np.ndarray, du_pred: np.ndarray) -> str:
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
        cos = self.step_cosine(du, prev)
        if cos is None or cos >= self.opt.min_step_cosine:
            return ""
        pred_back = self.dot(du_pred, prev) < 0.0
        if pred_back and self.opt.control == "arc-length":
            self.sigma = -self.sigma
        return (f"{RETRACE}: its displacement increment makes an angle of "
                f"{math.degrees(math.acos(max(-1.0, min(1.0, cos)))):.0f}° with the previous "
                f"step's (retrace or jump to another branch"
                f"{'; predictor pointed backwards, sign flipped' if pred_back else ''})")

    def step_cosine(self, du: np.ndarray, prev: np.ndarray) -> float | None:
        """The cosine of the angle between two displacement increments (None if one is zero)."""
        denom = math.sqrt(self.dot(du, du) * self.dot(prev, prev))
        return self.dot(du, prev) / denom if denom > 0.0 else None

    def jumped(self, last: PathState, state: PathState, t: np.ndarray) -> bool:
        """Whether the step ``last`` → ``state`` may have landed on another branch past a snap.

        The step's change Δ = (Δu, Δλ) against the path's tangent (t, 1) at ``last`` (``t``
        its load tangent), in the arc's norm: Δ leaves the tangent's line by more than
        :data:`JUMP_CORRECTION` × its projection on it, or its load change falls short of the
        projection's by more than :data:`JUMP_LOSS` of it, the tangent's inertia the same at
        both ends (a crossing is located by
        :meth:`~.critical_points.CriticalPoints.locate_crossing`). For an arc step the first is
        the corrector's distance from the predictor over the predictor's length; measured on the
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

    def inadmissible(self, u: np.ndarray) -> str:
        """Why the model declares ``u`` inadmissible (``""``: admissible, or no such hook).

        The system's optional ``admissible(u)``
        (:class:`~sandwich.solver.system.OptionalHooks`): a converged step whose state is
        inadmissible is refused like a failed one, so the path never leaves the model's domain
        of physical meaning.
        """
        return self.admissible(u) if self.admissible is not None else ""


class ReturnGuard:
    """Stops a path that retraces its own branch (:meth:`retracing`).

    Keeps, for the path it is asked about, every step's squared chord length in the norm
    ‖(Δu, ψΔλ)‖ (``dot`` the system's inner product) and the path's length up to each state,
    and the last states found on the path already followed.
    """

    def __init__(self, dot: Callable[[np.ndarray, np.ndarray], float], psi: float) -> None:
        self.dot, self.psi = dot, psi
        self._chord_lengths2: list[float] = []  # ‖(Δu, ψΔλ)‖² of each step
        self._path_length: list[float] = [0.0]  # the path's length up to each state
        self._returns: list[tuple[int, float]] = []  # the last states on the path followed

    def retracing(self, states: list[PathState]) -> str:
        """Why the path ``states`` is retracing its own branch at its last state (``""``: not).

        A regular equilibrium curve does not come back to a point it passed; a path that does
        has turned onto its own branch and follows it back (fig. 7 c2's 2D path after its
        core crushed: a loop through crushed states, then the loading branch retraced through
        λ = 0 to λ = −117, every step turning by a small angle, so the retrace guard on
        consecutive steps never saw it). The last state lies on the path already followed when it
        is within RETURN_FRACTION of an earlier step's length from that step's chord, in
        ‖(u, ψλ)‖, counting only steps the path has since travelled away from by at least
        their length (a run of short steps right after a long one stays near its chord
        without returning). A single such state can be a near pass of another part of the
        path (fig. 4's crushed 2D core: one state within 0.09, the next ones 0.1-0.4 away);
        RETURN_STATES of them in a row are a retrace: the path stops. A step whose λ range
        lies farther from the state than the fraction is skipped without a dot product
        (|ψ Δλ| bounds the distance from below).
        """
        state = states[-1]
        psi = self.psi
        chords, travelled = self._chord_lengths2, self._path_length
        while len(chords) < len(states) - 1:
            a, b = states[len(chords)], states[len(chords) + 1]
            du = b.u - a.u
            chords.append(self.dot(du, du) + (psi * (b.load_factor - a.load_factor)) ** 2)
            travelled.append(travelled[-1] + math.sqrt(chords[-1]))
        n = len(states) - 1  # the state's index; its own step is chord n − 1
        x_l = psi * state.load_factor
        on = None
        for k in range(max(n - 1, 0)):
            length2 = chords[k]
            if length2 == 0.0 or (travelled[n] - travelled[k + 1]) ** 2 < length2:
                continue  # not travelled away from it by its length yet
            a, b = states[k], states[k + 1]
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
                f"{k0 + 1}'s length from it, λ {states[k0].load_factor:.6g} → "
                f"{states[k0 + 1].load_factor:.6g}; step {n} on step {k + 1}), turned by "
                f"steps of small angle after a fold; stopped there, the states kept")
