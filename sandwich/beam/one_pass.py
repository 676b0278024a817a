"""``auto`` core levels in one pass: raised along the path where a raise changes the answer.

The path starts at the linear step's levels (:mod:`sandwich.beam.core_choice`). At a few of its
converged states — half-way to the target (``CHECK_FRACTIONS``), right after a located critical
point, and at the target — :class:`OnePass` (the path follower's ``refine`` hook,
:mod:`sandwich.solver.path.switching`) continues the state into raised levels
(:func:`~sandwich.beam.core_controller.raised_levels`: the state's residual shares and every
debonded stretch and load patch) and re-converges it there by Newton at the same value of the
until probe (the same load where the scene has no probe target).
The change of the answer is the estimate (:func:`answer_change`: the load and every probe,
relative to the largest): where ``BELOW_FACTOR ×`` it is within the tolerance, the path goes on
at its levels with that estimate; else it goes on from the re-converged state at the raised
levels, checked again at once. The core basis is hierarchical, so the old state is exactly a
state of the raised model (:func:`~sandwich.beam.core_levels.transfer`). The path is followed
once; the states before a raise stay at the levels they were computed with.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from sandwich.beam.build import build_model, scene_gauss_orders
from sandwich.beam.core_controller import (
    BELOW_FACTOR,
    END_STATE_BACKTRACKS,
    END_STATE_ITERATIONS,
    raised_levels,
)
from sandwich.beam.core_levels import LevelChoice, level_counts, transfer
from sandwich.beam.model import BeamModel
from sandwich.beam.path_pass import max_penetration
from sandwich.results import PathNote
from sandwich.solver import PathState
from sandwich.solver.controls import LoadConstraint, ProbeConstraint
from sandwich.solver.newton import NewtonSettings, newton_correct
from sandwich.solver.path import Refinement
from sandwich.solver.system import inner_product

#: Fractions of the way to the target (the until probe's value, else the load) at which the
#: levels are checked besides critical points and the target itself.
CHECK_FRACTIONS = (0.25, 0.5, 0.75)
#: Raises at one check at most (each one level on the raised elements).
RAISES_PER_CHECK = 3
#: Earlier states a rewind at a critical point may go back to.
REWIND_STATES = 3
#: A state is at its target within this relative distance (the follower's own test is tighter).
AT_TARGET = 1e-4


class OnePass:
    """The follower's ``refine`` hook of an ``auto`` path: checks, raises, the estimate.

    ``choice`` (the linear step's) is updated in place: its levels, estimate and passes are the
    answer's. :attr:`model` is the model the path is on; :attr:`capped` says a check wanted to
    raise where the debond and load zones are at ``max_core_level``; :attr:`checked_at_target`
    that the last estimate was made at the target.
    """

    def __init__(self, scene: object, elements: int | None, options: dict, choice: LevelChoice,
                 model: BeamModel, progress: Callable[[object], None] | None = None) -> None:
        self.scene, self.elements, self.options = scene, elements, options
        self.choice, self.model, self.progress = choice, model, progress
        self.capped = False
        self.checked_at_target = False
        self._fractions = list(CHECK_FRACTIONS)
        self._recent: list[PathState] = []  # the last states on the present model
        self._unreached: np.ndarray | None = None  # levels a check found no equilibrium at
        self._raises: dict[bytes, np.ndarray | None] = {}  # levels → the raise above them
        self._kept_step = -1  # the step of the last check that kept the levels
        # the model and levels before the last raise
        self._below: tuple[BeamModel, np.ndarray] | None = None
        bm = scene.beam_model
        self.tolerance, self.top = float(bm.tolerance), int(bm.max_core_level)

    def __call__(self, state: PathState, system: object) -> Refinement | None:
        """The raised model continued from ``state`` where a check asks for it, else None.

        At a critical point located within the step ending at ``state``, the state before it
        is checked, and a raise there takes the step again at the raised levels (a rewind):
        the critical load is located on the model the path goes on with. Where the raised
        model has no equilibrium near the checked state, or one whose tangent has another
        inertia (its critical point lies before), up to ``REWIND_STATES`` earlier states are
        tried (:meth:`_walk_back`): the raised model has left this path's branch, and the path
        goes on at the raised levels from the latest state where it had not.
        """
        recent = [s for s in self._recent if s.step < state.step and s.step > 0]
        self._recent = [*recent[-REWIND_STATES:], state]
        at_target = self._at_target(state)
        critical = self._critical(state) and bool(recent)
        if not (at_target or critical or self._passed_fraction(state)):
            return None
        if not at_target and self._raises.get(self.choice.levels.tobytes(), 0) is None:
            return None  # at the cap: only the target's estimate is left to make
        checked = recent[-1] if critical else state
        earlier = recent[:-1] if critical else recent
        if critical and not at_target and checked.step == self._kept_step:
            return None  # checked at these levels already
        start = self.model
        self._unreached = None
        found = self.check(checked)
        if found is None and self._unreached is not None and earlier:
            levels = self._unreached
            checked, res = self._walk_back(start, earlier, levels, checked, None)
            found = None if res is None else (levels, res)
        elif found is not None and critical:
            checked, res = self._walk_back(start, earlier, found[0], checked, found[1])
            found = found[0], res
        self.checked_at_target = at_target and checked is state
        if found is None:
            self._kept_step = checked.step
            return None
        levels, res = found
        self.choice.levels = levels
        self._recent = [PathState(checked.step, res.u, float(res.load_factor), 0,
                                  _probes(self.model, res.u), res.factorization.negative_pivots)]
        if self.progress is not None:
            self.progress(PathNote(f"core levels raised at step {checked.step}: elements per "
                                   f"core level {level_counts(levels)}", restart=False))
        return Refinement(self.model, lambda v, old=start: transfer(v, old, self.model),
                          res.u, float(res.load_factor), res.iterations, res.factorization,
                          rewind=state.step - checked.step)

    def _walk_back(self, start: BeamModel, earlier: list[PathState], levels: np.ndarray,
                   checked: PathState, res: object | None) -> tuple[PathState, object | None]:
        """The latest state where the model at ``levels`` is on this path's branch, raised.

        ``checked`` raised to ``res`` (None: the raise found no equilibrium near it); while
        that is so or the raised state's tangent has another inertia than the checked one's,
        the states of ``earlier`` (latest first) are re-converged at ``levels``. The earliest
        tried where none qualifies; :attr:`model` is the model at ``levels`` if any raised.
        """
        up = self.model if res is not None else None
        for older in reversed(earlier):
            if res is not None and (None in (checked.negative_pivots,
                                             res.factorization.negative_pivots)
                                    or checked.negative_pivots
                                    == res.factorization.negative_pivots):
                break
            lifted = self.lift(start, older.u, older.load_factor, dict(older.probes), levels, up)
            entry = {"stage": f"check at step {older.step} (going back)",
                     "elements_per_level": level_counts(levels),
                     "load_factor": older.load_factor, "reached": lifted is not None,
                     "estimate": None}
            self.choice.passes.append(entry)
            if lifted is None:
                continue
            up, raised = lifted
            checked, res = older, raised
            entry["load_factor"] = float(raised.load_factor)
            entry["estimate"] = self.choice.estimate = answer_change(
                older.load_factor, older.probes, float(raised.load_factor), _probes(up, raised.u))
        if res is not None:
            self.model = up
        return checked, res

    def check(self, state: PathState) -> tuple[np.ndarray, object] | None:
        """Raise while the change of ``state``'s answer asks for it; the raised state, or None.

        Each raise re-converges the state at :func:`raised_levels` (:meth:`lift`); its change
        δ (:func:`answer_change`) with ``BELOW_FACTOR × δ`` within the tolerance ends the
        check at the levels below it, with that estimate, unless the raised state's tangent
        has another inertia (the raised model has crossed a critical point this path has not:
        fig. 6's wrinkling maximum, which level 1 does not have). Else the raised state is
        kept, its own change the estimate until a later check. Where the levels cannot be raised any
        further, the change from the levels below the last raise is the estimate
        (:meth:`_change_from_below`). The choice's estimate is set; :attr:`model` is the
        raised one.
        """
        levels = self.choice.levels.copy()
        u, lam, probes = state.u, state.load_factor, dict(state.probes)
        neg = state.negative_pivots
        raised = None
        estimate: float | None = None
        for _ in range(RAISES_PER_CHECK):
            higher = self._raise_of(levels, PathState(state.step, u, lam, 0, probes, None))
            if higher is None:
                self.capped = True
                if raised is None:
                    estimate = self._change_from_below(state.step, u, lam, probes)
                break
            lifted = self.lift(self.model, u, lam, probes, higher)
            entry = {"stage": f"check at step {state.step}",
                     "elements_per_level": level_counts(higher), "load_factor": lam,
                     "reached": lifted is not None, "estimate": None}
            self.choice.passes.append(entry)
            if lifted is None:  # the raised model has no equilibrium near this one
                self._unreached = higher
                break
            up, res = lifted
            new_probes = _probes(up, res.u)
            change = answer_change(lam, probes, float(res.load_factor), new_probes)
            entry["load_factor"] = float(res.load_factor)
            entry["estimate"] = change
            crossed = None not in (neg, res.factorization.negative_pivots) and (
                res.factorization.negative_pivots != neg)
            entry["inertia_changed"] = crossed
            if change is not None and BELOW_FACTOR * change <= self.tolerance and not crossed:
                estimate = BELOW_FACTOR * change
                entry["levels_below_kept"] = True
                break
            self._below = (self.model, levels)
            self.model, levels, raised = up, higher, res
            u, lam, probes = res.u, float(res.load_factor), new_probes
            neg = res.factorization.negative_pivots
            estimate = change  # the raise's own change, until a check of the raised levels
            if not np.any(levels < self.top):
                self.capped = True
                break
        self.choice.estimate = estimate
        return None if raised is None else (levels, raised)

    def _raise_of(self, levels: np.ndarray, state: PathState) -> np.ndarray | None:
        """The levels above ``levels`` (:func:`raised_levels` at the first state checked there).

        Kept for the path's later checks at the same levels: the residual shares cost a model
        at one level more everywhere, and the debond and load zones, raised at every check,
        carry the error (:func:`~sandwich.beam.core_controller.raised_levels`).
        """
        key = levels.tobytes()
        if key not in self._raises:
            self._raises[key] = raised_levels(self.scene, self.elements, self.options,
                                              self.model, state, levels, self.top)
        return self._raises[key]

    def _change_from_below(self, step: int, u: np.ndarray, lam: float,
                           probes: dict[str, float]) -> float | None:
        """The change of the answer from the levels below the last raise to the present ones.

        The state re-converged on the model before the last raise (:meth:`lift` downwards:
        the enrichment amplitudes it lacks dropped); before any raise, on the levels one below
        the present ones. None where all are at level 1, or where that Newton fails.
        """
        if self._below is None:  # no raise on this path: one level lower where above 1
            levels = np.maximum(self.choice.levels - 1, 1)
            if np.array_equal(levels, self.choice.levels):
                return None
            model = None
        else:
            model, levels = self._below
        lifted = self.lift(self.model, u, lam, probes, levels, model)
        entry = {"stage": f"check at step {step} (levels below)",
                 "elements_per_level": level_counts(levels), "load_factor": lam,
                 "reached": lifted is not None, "estimate": None}
        self.choice.passes.append(entry)
        if lifted is None:
            return None
        model, res = lifted
        entry["load_factor"] = float(res.load_factor)
        entry["estimate"] = answer_change(lam, probes, float(res.load_factor),
                                          _probes(model, res.u))
        return entry["estimate"]

    def lift(self, model: BeamModel, u: np.ndarray, lam: float, probes: dict[str, float],
             levels: np.ndarray, up: BeamModel | None = None) -> tuple[BeamModel, object] | None:
        """The state ``(u, λ)`` of ``model`` re-converged on the model at ``levels``, or None.

        Newton with a backtracking line search from the carried-over state (new enrichment
        amplitudes zero), at the same value of the until probe where the scene has one, else at
        the same load. None where Newton fails or the state penetrates deeper than the model's
        bound. ``up``: the model at ``levels`` if built already.
        """
        a = self.scene.analysis
        if up is None:
            up = build_model(self.scene, elements=self.elements,
                             gauss=scene_gauss_orders(self.scene),
                             **{**self.options, "core_level": levels})
        name = self._held_probe(probes)
        if name is None:
            constraint = LoadConstraint(lam)
        else:
            constraint = ProbeConstraint(np.asarray(up.probe_vector(name), dtype=float),
                                         float(probes[name]), inner_product(up))
        settings = NewtonSettings(
            tol=float(a.tol), max_iterations=END_STATE_ITERATIONS,
            force_floor=float(np.linalg.norm(up.f_ref)) * abs(lam),
            backtracks=END_STATE_BACKTRACKS)
        res = newton_correct(up, transfer(u, model, up), lam, constraint, settings)
        if not res.converged or res.load_factor == 0.0 or res.factorization is None:
            return None
        if max_penetration(up, [res.u]) > up.penetration_bound():
            return None
        return up, res

    def _held_probe(self, probes: dict[str, float]) -> str | None:
        """The probe a lift holds: the until probe (None without one, or at 0: the load)."""
        name = self.scene.analysis.until_probe
        return name if name and probes.get(name, 0.0) != 0.0 else None

    def _at_target(self, state: PathState) -> bool:
        a = self.scene.analysis
        if a.until_probe is not None and a.until_probe in state.probes:
            target = float(a.until_value)
            if abs(state.probes[a.until_probe] - target) <= AT_TARGET * max(abs(target), 1e-12):
                return True
        if a.until_load_factor is not None:
            target = float(a.until_load_factor)
            return abs(state.load_factor - target) <= AT_TARGET * max(abs(target), 1e-12)
        return False

    def _passed_fraction(self, state: PathState) -> bool:
        """Whether ``state`` is past the next check fraction of the way (that one then done)."""
        a = self.scene.analysis
        ways = []
        if a.until_probe is not None and a.until_probe in state.probes and a.until_value:
            ways.append(state.probes[a.until_probe] / float(a.until_value))
        if a.until_load_factor:
            ways.append(state.load_factor / float(a.until_load_factor))
        way = max(ways, default=0.0)
        passed = False
        while self._fractions and way >= self._fractions[0]:
            self._fractions.pop(0)
            passed = True
        return passed

    @staticmethod
    def _critical(state: PathState) -> bool:
        """Whether a bifurcation or load extremum was located within the step ending here."""
        return state.crossing is not None or state.extremum is not None


def answer_change(load_factor: float, probes: dict[str, float], new_load_factor: float,
                  new_probes: dict[str, float]) -> float | None:
    """The relative change of a state's answer: the load, and every probe.

    The load relative to itself, the probes relative to the largest probe magnitude (a probe
    that barely moves is not divided by its own near-zero value); the larger of the two. None
    where nothing can be compared (no load, no probe moved).
    """
    changes = []
    if load_factor != 0.0:
        changes.append(abs(new_load_factor - load_factor) / abs(load_factor))
    scale = max((abs(v) for v in probes.values()), default=0.0)
    common = [n for n in probes if n in new_probes]
    if scale > 0.0 and common:
        changes.append(max(abs(new_probes[n] - probes[n]) for n in common) / scale)
    return max(changes) if changes else None


def _probes(model: BeamModel, u: np.ndarray) -> dict[str, float]:
    return {n: float(np.asarray(model.probe_vector(n)) @ u) for n in model.probe_rows}
