"""``auto`` core levels in one pass: checked and raised along the path, never rerun.

The path starts at the linear step's levels (:mod:`sandwich.beam.core_choice`). At a few of its
converged states — a tenth, a quarter, half and three quarters of the way to the target
(``CHECK_FRACTIONS``), after a located critical point (the state before it) and at the target —
:class:`OnePass`, the path follower's ``refine`` hook (:mod:`sandwich.solver.path.switching`),
estimates the error of the answer there (:meth:`OnePass.estimate`): the state re-converged by
Newton one core level higher everywhere, at the same value of the until probe (the same load
where the scene has no probe target), and the change of the answer (:func:`answer_change`: the
load and every probe), doubled for the levels above (``ESTIMATE_FACTOR``). The core basis
is hierarchical, so the state is exactly a state of the higher model
(:func:`~sandwich.beam.core_levels.transfer`). Along the way one Newton correction of that
state decides where its change is clear of the tolerance (``ONE_STEP_MARGIN``); the target's
estimate, the run's, is always re-converged, and only there are G, G_II/G and the averaged
stress peaks estimated.

Within the tolerance (the scene's for the load and probes; at the target also its ``[accuracy] G``,
by default ``G_TOLERANCE``, for G and G_II/G at the debond tips), the path goes on. Beyond it, the
levels are raised where the error lives (:func:`~sandwich.beam.core_controller.raised_levels`:
every debonded stretch and load patch and the residual's share, up to ``max_core_level``), the
state is re-converged there and checked again, and the path goes on at the raised levels from the
last state a check kept, the steps after it taken again. The first raise, which has no such state,
takes the path again from its first step (where that lifts with the same inertia), and the retaken
state that gets as far as its check is then where later raises go back to: every state keeps the
accuracy a check found. A raised model with no equilibrium near the checked state, or with another
inertia there, has left this path's branch: the raise goes back to an earlier state. The estimate
at the target is the run's, with the element length's share added there: the state re-converged
with every element split in two at the same levels (:meth:`OnePass.length_estimate`), which only
advises more elements.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from sandwich.beam.bisection import bisected_levels, bisected_mesh, bisected_state
from sandwich.beam.build import build_model, scene_gauss_orders
from sandwich.beam.core_basis import MAX_LEVEL
from sandwich.beam.core_controller import raised_levels
from sandwich.beam.core_levels import LevelChoice, level_counts, transfer
from sandwich.beam.fields import profile_columns
from sandwich.beam.fracture import release_columns
from sandwich.beam.model import BeamModel
from sandwich.beam.reconverging import LIFT_BACKTRACKS, Reconverging, probes_of
from sandwich.results import PathNote
from sandwich.results.changes import (
    STRESS_TOLERANCE,
    answer_change,
    release_changes,
    stress_changes,
    tolerances,
)
from sandwich.solver import PathState
from sandwich.solver.path import Refinement

#: Fractions of the way to the target (the until probe's value, else the load) at which the
#: levels are checked besides critical points and the target itself; the first raise takes the
#: path again from its first step, so the first check comes early.
CHECK_FRACTIONS = (0.1, 0.25, 0.5, 0.75)
#: Raises at one check at most (each one level on the raised elements).
RAISES_PER_CHECK = 3
#: The estimate is this many times the change δ one level higher everywhere: δ / (1 − ρ) for
#: levels that converge at the rate ρ = ½ (the change to level 5 over δ, uniform levels on the
#: nonlinear bend at 40 elements: 1.4, 2.2, 1.7 from levels 1, 2, 3).
ESTIMATE_FACTOR = 2.0
#: Earlier states a rewind at a critical point may go back to.
REWIND_STATES = 3
#: What the estimate of G at the debond tips (relative) and of its mode mix G_II/G (absolute)
#: is held to: at the target the core levels are raised for it like for the load and probes
#: (fig. 5 under load control at 450 N: G −3.5 % → −0.1 % of the 2D Richardson value); the
#: element length's share is reported and said where it exceeds it.
G_TOLERANCE = 0.03
#: A raise goes back to the last state a check kept if that retakes at most this fraction of
#: the steps so far (or REWIND_STATES).
ANCHOR_REACH = 0.25
#: ... and of the state carried onto the bisected mesh (a start, not the same field): plain
#: Newton first, then with the line search. Its last iterations settle contact pairs in the
#: penalty law's knee, converging linearly: plain Newton converges in 25 on fig. 6 and 36 on
#: fig. 9 d20 (both at 6e-3 and 5e3 of residual after 22), fails fast on d30 (the residual grows
#: 1e6-fold in 10).
LENGTH_ITERATIONS = (40, 24)
#: Newton's tolerance of an estimate's state (the path's where that is looser): its answer to
#: ~1e-6, far below any tolerance a scene asks for.
ESTIMATE_TOL = 1e-6
#: Along the way (not at the target, whose estimate is the run's), a check first takes the
#: carried-over state one Newton correction into the model one level higher (its linearised
#: response, :meth:`OnePass.linearised`); that change decides where its estimate is below
#: 1 / ONE_STEP_MARGIN or above ONE_STEP_MARGIN times the tolerance, and the state is re-converged
#: only in between. Measured at every state of fig. 5 (60 elements), the demo scene, fig. 6,
#: fig. 7 c1 and c3 and fig. 9 d20 at the linear step's levels: where the correction was
#: accepted (reconverging.ONE_STEP_CONTRACTION), its change of the load was 0.90-1.03 × the
#: re-converged one (0.72-1.42 × at the states it was not), so a decision at 1.25 × is the
#: re-converged one's.
ONE_STEP_MARGIN = 1.25
#: A state is at its target within this relative distance (the follower's own test is tighter).
AT_TARGET = 1e-4


def beam_tolerances(scene: object) -> dict[str, float]:
    """What the beam holds each quantity it estimates to (:func:`tolerances`).

    The scene's ``[accuracy]``; where it gives none, ``[beam_model] tolerance`` for the load and
    probes, ``G_TOLERANCE`` for G and G_II/G, ``STRESS_TOLERANCE`` for the stress peaks.
    """
    return tolerances(scene.accuracy, {"load": float(scene.beam_model.tolerance),
                                       "G": G_TOLERANCE, "stresses": STRESS_TOLERANCE})


class OnePass(Reconverging):
    """The follower's ``refine`` hook of an ``auto`` path: checks, raises, the estimate.

    ``choice`` (the linear step's) is updated in place: its levels, estimate and passes are the
    answer's. :attr:`model` is the model the path is on; :attr:`capped` says a check wanted to
    raise where the debond and load zones are at ``max_core_level``; :attr:`checked_at_target`
    that the last estimate was made at the target; :attr:`quantities` holds its estimate per
    quantity (the load and probes, and G and the mode mix G_II/G at the debond tips,
    :func:`release_changes`, held to ``G_TOLERANCE`` at the target), :attr:`lengths`
    the element length's share of each at the target (:meth:`length_estimate`).
    """

    def __init__(self, scene: object, elements: int | None, options: dict, choice: LevelChoice,
                 model: BeamModel, progress: Callable[[object], None] | None = None) -> None:
        self.scene, self.elements, self.options = scene, elements, options
        self.choice, self.model, self.progress = choice, model, progress
        self.capped = False
        self.checked_at_target = False
        # the last estimate of each quantity: "load and probes", and "G", "G_II/G" at the tips
        self.quantities: dict[str, float] = {}
        # at the target: the element length's share of each (None: not measured)
        self.lengths: dict[str, float] | None = None
        self._fractions = list(CHECK_FRACTIONS)
        self._recent: list[PathState] = []  # the last states on the present model
        self._unreached: np.ndarray | None = None  # levels a check found no equilibrium at
        # the last state checked within the tolerance, or raised (after the first raise: the
        # retaken state at its check's position): where a raise goes back to
        self._anchor: PathState | None = None
        self._first: PathState | None = None  # the path's first step: the first raise's anchor
        # after the first raise: how far its check was (way to the target); the retaken state
        # that gets there is the anchor of later raises
        self._retaken_to: float | None = None
        self._raises: dict[bytes, np.ndarray | None] = {}  # levels → the raise above them
        self._kept_step = -1  # the step of the last check that kept the levels
        self._models: dict[bytes, BeamModel] = {}  # the higher models the checks use
        bm = scene.beam_model
        self.tolerance, self.top = float(bm.tolerance), int(bm.max_core_level)
        self.tolerances = beam_tolerances(scene)

    def __call__(self, state: PathState, system: object) -> Refinement | None:
        """The raised model continued from ``state`` where a check asks for it, else None.

        At a critical point located within the step ending at ``state``, the state before it
        is checked, and a raise there takes the step again at the raised levels (a rewind):
        the critical load is located on the model the path goes on with. Where the raised
        model has no equilibrium near the checked state, or one whose tangent has another
        inertia (its critical point lies before), up to ``REWIND_STATES`` earlier states are
        tried (:meth:`_walk_back`): the raised model has left this path's branch, and the path
        goes on at the raised levels from the latest state where it had not. Any raise goes
        back to the last state a check kept or raised, the first raise to the path's first step
        (:meth:`_back_to_anchor`).
        """
        if self._first is None and state.step == 1:
            self._first = state
        way = self._way(state)
        if self._retaken_to is not None and way is not None and way >= self._retaken_to:
            self._anchor, self._retaken_to = state, None
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
        found = self.check(checked, at_target=at_target and checked is state)
        if found is None and self._unreached is not None and earlier:
            levels = self._unreached
            checked, res = self._walk_back(start, earlier, levels, checked, None)
            found = None if res is None else (levels, res)
        elif found is not None and critical:
            checked, res = self._walk_back(start, earlier, found[0], checked, found[1])
            found = found[0], res
        if found is not None:
            raised_at = checked
            checked, found = self._back_to_anchor(start, checked, found)
            retaken = checked is self._first and raised_at is not checked
            self._retaken_to = self._way(raised_at) if retaken else None
        self.checked_at_target = at_target and checked is state
        if found is None:
            self._kept_step = checked.step
            self._anchor, self._retaken_to = checked, None
            if self.checked_at_target and self.choice.estimate is not None:
                self.lengths = self.length_estimate(state)
            return None
        levels, res = found
        self.choice.levels = levels
        self._recent = [PathState(checked.step, res.u, float(res.load_factor), 0,
                                  probes_of(self.model, res.u), res.factorization.negative_pivots)]
        self._anchor = self._recent[0]
        if self.checked_at_target and self.choice.estimate is not None:
            self.lengths = self.length_estimate(self._recent[0])
        # its raised state was checked in the raise loop (the first step, taken back to, was not)
        self._kept_step = -1 if retaken else checked.step
        if self.progress is not None:
            self.progress(PathNote(f"core levels raised at step {checked.step}: elements per "
                                   f"core level {level_counts(levels)}", restart=False))
        return Refinement(self.model, lambda v, old=start: transfer(v, old, self.model),
                          res.u, float(res.load_factor), res.iterations, res.factorization,
                          rewind=state.step - checked.step)

    def _back_to_anchor(self, start: BeamModel, checked: PathState,
                        found: tuple[np.ndarray, object]) -> tuple[PathState, tuple | None]:
        """Go back to the last state a check kept (the first raise: the first step), if it lifts.

        The states after it were followed at levels whose error grew past the tolerance
        before this check saw it; they are taken again at the raised levels, so that every
        state of the path keeps the accuracy its check found. The first raise has no such
        state and goes back to the path's first step (no state before it was checked: on c3 they
        were level 1's, and a debond's first growth load read from them was 3.0 % above the
        raised levels'). A later raise goes back only where that retakes at most
        ``ANCHOR_REACH`` of the steps so far (or ``REWIND_STATES``): a long path (fig. 7 c4, 34
        steps at the check, 16 at the anchor) keeps those states at the levels they were
        computed with, each within the raising check's estimate. ``found``: the raised levels and
        the checked state raised; kept where the anchor does not lift with the same inertia.
        """
        anchor, first = self._anchor, self._anchor is None
        if first:  # the first raise: no state before it was checked
            anchor = self._first
        if anchor is None or anchor.step >= checked.step or (not first and (
                checked.step - anchor.step > max(REWIND_STATES, ANCHOR_REACH * checked.step))):
            return checked, found
        levels = found[0]
        lifted = self.lift(start, anchor.u, anchor.load_factor, dict(anchor.probes), levels,
                           self.model)
        what = "back to the first step" if first else "back to the last check"
        self.choice.passes.append(self._entry(anchor, levels, lifted, what))
        if lifted is None or _same_inertia(anchor, lifted[1]) is not True:
            self.choice.passes[-1]["kept"] = False  # the path goes on from the checked state
            return checked, found
        return anchor, (levels, lifted[1])

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
            if res is not None and _same_inertia(checked, res) is not False:
                break
            lifted = self.lift(start, older.u, older.load_factor, dict(older.probes), levels, up)
            entry = self._entry(older, levels, lifted, "going back")
            self.choice.passes.append(entry)
            if lifted is None:
                continue
            up, raised = lifted
            checked, res = older, raised
            entry["change"] = answer_change(older.load_factor, older.probes,
                                            float(raised.load_factor), probes_of(up, raised.u))
        if res is not None:
            self.model = up
        return checked, res

    def check(self, state: PathState,
              at_target: bool = False) -> tuple[np.ndarray, object] | None:
        """Estimate the error of ``state``'s answer; raise while it exceeds the tolerance.

        The estimate (:meth:`estimate`): the state re-converged one level higher everywhere,
        its answer's change δ doubled for the levels above. Within
        the tolerance, and with the same inertia of the tangent there (else the higher model
        has crossed a critical point this path has not: fig. 6's wrinkling maximum, which
        level 1 does not have), the levels are kept. Else the state is re-converged at
        :func:`raised_levels` (the zones and the residual's share, up to ``max_core_level``)
        and checked again there. ``at_target``: the state is the path's target, where G and
        G_II/G are held to ``G_TOLERANCE`` too (:meth:`_within`). Returns the raised levels and
        state (None: none raised); the choice's estimate is the last one made; :attr:`model` is
        the raised model.
        """
        levels = self.choice.levels.copy()
        current = state
        raised = None
        self.choice.estimate = None
        for _ in range(RAISES_PER_CHECK + 1):
            found = self.estimate(current, levels, at_target)
            if found is None:
                break
            estimate, crossed, look, up_state = found
            self.choice.estimate = estimate
            if self._within(estimate, at_target) and not crossed:
                break
            higher = self._raise_of(levels, current)
            if higher is None:
                self.capped = True
                break
            if np.array_equal(higher, look[0]):  # converged to the path's tolerance from there
                up = look[1]
                lifted = self.lift(up, up_state.u, float(up_state.load_factor),
                                   probes_of(up, up_state.u), higher, up)
                if lifted is None:
                    self._unreached = higher
                    break
                res = lifted[1]
            else:
                lifted = self.lift(self.model, current.u, current.load_factor,
                                   dict(current.probes), higher)
                self.choice.passes.append(self._entry(current, higher, lifted, "raise"))
                if lifted is None:  # the raised model has no equilibrium near this one
                    self._unreached = higher
                    break
                up, res = lifted
            after = PathState(current.step, res.u, float(res.load_factor), 0,
                              probes_of(up, res.u), res.factorization.negative_pivots)
            self.model, levels, raised, current = up, higher, res, after
        return None if raised is None else (levels, raised)

    def _within(self, estimate: float, at_target: bool) -> bool:
        """Whether the last estimate meets its tolerances: the answer's, at the target G's too.

        At the target G and G_II/G are held to their tolerances (:func:`beam_tolerances`; not
        where the scene does not ask for them), there only: along the way, where
        a tip is still closed or barely open, its G's relative change one level higher is large
        (fig. 6 at a fifth of its load: 49 %) and says nothing of G where the scene asks for it.
        The averaged stress peaks are reported, not raised for: on fig. 9 d0 a raise for them
        took 2.2 × the time and left them above 5 % (9.2 → 7.8 %).
        """
        if estimate > self.tolerance:
            return False
        return not at_target or all(
            self.quantities.get(name, 0.0) <= self.tolerances[name]
            for name in ("G", "G_II/G") if name in self.tolerances)

    def estimate(self, state: PathState, levels: np.ndarray,
                 at_target: bool = False) -> tuple | None:
        """The estimated error of ``state`` at ``levels``, and what it found, or None.

        ``δ``: the change of the answer (:func:`answer_change`) with the state re-converged one
        level higher everywhere (up to the hierarchy's top, beyond ``max_core_level``: what the
        cap costs is measured too); the estimate ``ESTIMATE_FACTOR × δ``. Along the way the
        linearised change decides where it is clear of the tolerance (``ONE_STEP_MARGIN``,
        :meth:`linearised`); at the target the state is always re-converged, and G, G_II/G and
        the averaged stress peaks are estimated too. Returns (estimate, whether the higher
        state's tangent has another inertia, (higher levels, higher model), higher state); None
        where nothing is higher or its Newton fails (then :attr:`_unreached` is the levels a
        raise would go to).
        """
        self.quantities = {}
        look = np.minimum(levels + 1, MAX_LEVEL)
        if np.array_equal(look, levels):
            return None
        up = self._model_at(look)
        found = None if at_target else self._decided(state, up)
        if found is not None:
            lifted, (change, self.quantities) = found
        else:
            lifted = self.lift(self.model, state.u, state.load_factor, dict(state.probes), look,
                               up, max(float(self.scene.analysis.tol), ESTIMATE_TOL))
        entry = self._entry(state, look, lifted, "one level higher")
        self.choice.passes.append(entry)
        if lifted is None:
            self._unreached = self._raise_of(levels, state)
            self.choice.estimate = self._change_from_below(state, levels)
            if self.choice.estimate is not None:
                self.quantities = {"load and probes": self.choice.estimate}
            return None
        _, res = lifted
        if found is None:
            found = self._estimates(state, up, res, at_target)
            if found is None:
                return None
            change, self.quantities = found
        else:
            entry["linearised"] = True
        estimate = self.quantities["load and probes"]
        entry["quantities"] = dict(self.quantities)
        crossed = _same_inertia(state, res) is False
        entry.update(change=change, estimate=estimate, inertia_changed=crossed)
        return estimate, crossed, (look, up), res

    def _decided(self, state: PathState, up: BeamModel) -> tuple | None:
        """The linearised check (:meth:`linearised`) where it decides, else None.

        It decides where its estimate of the load and probes is at most 1 / ``ONE_STEP_MARGIN``
        or at least ``ONE_STEP_MARGIN`` times the tolerance and the tangent it was solved with
        has the state's inertia (near a critical point the state is re-converged). Returns the
        lifted pair and :meth:`_estimates`' answer.
        """
        lifted = self.linearised(up, state)
        if lifted is None or _same_inertia(state, lifted[1]) is False:
            return None
        found = self._estimates(state, up, lifted[1])
        if found is None:
            return None
        estimate = found[1]["load and probes"]
        if self.tolerance / ONE_STEP_MARGIN < estimate < ONE_STEP_MARGIN * self.tolerance:
            return None
        return lifted, found

    def _change_from_below(self, state: PathState, levels: np.ndarray) -> float | None:
        """The change of the answer from one level lower (above 1), or None.

        The estimate where the state does not re-converge one level higher: levels converging
        at the rate ½ put the error of ``levels`` at that change. None where all are at level
        1, or where it fails too.
        """
        below = np.maximum(levels - 1, 1)
        if np.array_equal(below, levels):
            return None
        lifted = self.lift(self.model, state.u, state.load_factor, dict(state.probes), below,
                           tol=max(float(self.scene.analysis.tol), ESTIMATE_TOL))
        entry = self._entry(state, below, lifted, "one level lower")
        self.choice.passes.append(entry)
        if lifted is None:
            return None
        model, res = lifted
        entry["change"] = entry["estimate"] = answer_change(
            state.load_factor, state.probes, float(res.load_factor), probes_of(model, res.u))
        return entry["estimate"]

    def _model_at(self, levels: np.ndarray) -> BeamModel:
        """The model at ``levels`` (kept: the checks come back to the same higher levels)."""
        key = levels.tobytes()
        if key not in self._models:
            self._models[key] = build_model(self.scene, elements=self.elements,
                                            gauss=scene_gauss_orders(self.scene),
                                            **{**self.options, "core_level": levels})
        return self._models[key]

    @staticmethod
    def _entry(state: PathState, levels: np.ndarray, lifted: tuple | None, what: str) -> dict:
        """The choice's passes entry of a state re-converged at ``levels``."""
        entry = {"stage": f"check at step {state.step} ({what})",
                 "elements_per_level": level_counts(levels), "load_factor": state.load_factor,
                 "reached": lifted is not None, "estimate": None}
        if lifted is not None:
            entry["load_factor"] = float(lifted[1].load_factor)
            entry["iterations"] = int(lifted[1].iterations)
        return entry

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

    def length_estimate(self, state: PathState) -> dict[str, float] | None:
        """The element length's share of the error of ``state`` (on :attr:`model`), or None.

        The state re-converged on the mesh with every element split in two, at the same core
        levels (:mod:`sandwich.beam.bisection`; plain Newton, then with the line search where
        that fails: the carried-over state is a start, not the same field, and its residual is
        large);
        ``ESTIMATE_FACTOR`` × each quantity's
        change (the load and probes, G and G_II/G at the tips). None where Newton fails.
        """
        fine = build_model(self.scene, gauss=scene_gauss_orders(self.scene),
                           **{**self.options,
                              "core_level": bisected_levels(self.choice.levels)},
                           mesh=bisected_mesh(self.model.mesh))
        start = bisected_state(state.u, self.model, fine)
        tol = max(float(self.scene.analysis.tol), ESTIMATE_TOL)
        found = None
        for backtracks, iterations in ((0, LENGTH_ITERATIONS[0]),
                                       (LIFT_BACKTRACKS, LENGTH_ITERATIONS[1])):
            found = self.reconverge(fine, start, state.load_factor, dict(state.probes), tol,
                                    backtracks, iterations)
            if found is not None:
                break
        entry = {"stage": f"check at step {state.step} (elements split in two)",
                 "elements_per_level": level_counts(bisected_levels(self.choice.levels)),
                 "load_factor": state.load_factor, "reached": found is not None,
                 "estimate": None}
        self.choice.passes.append(entry)
        if found is None:
            return None
        _, res = found
        estimated = self._estimates(state, fine, res, at_target=True)
        if estimated is None:
            return None
        change, out = estimated
        entry.update(load_factor=float(res.load_factor), iterations=int(res.iterations),
                     change=change, estimate=out["load and probes"], quantities=dict(out))
        return out

    def _estimates(self, state: PathState, other: BeamModel, res: object,
                   at_target: bool = False) -> tuple[float, dict[str, float]] | None:
        """``state`` against its re-converged ``res`` on ``other``: (δ, estimate per quantity).

        δ the change of the load and probes (:func:`answer_change`), and ``ESTIMATE_FACTOR`` ×
        each quantity's change; ``at_target`` also G and G_II/G at the tips
        (:func:`release_changes`) and the averaged stress peaks (:func:`stress_changes`), those
        the scene's ``[accuracy]`` asks for: the quantities the run reports, which are held (G)
        or said (stresses) there only. None where nothing can be compared.
        """
        change = answer_change(state.load_factor, state.probes, float(res.load_factor),
                               probes_of(other, res.u))
        if change is None:
            return None
        out = {"load and probes": ESTIMATE_FACTOR * change}
        if not at_target:
            return change, out
        if self.model.fracture_tips and "G" in self.tolerances:
            releases = release_changes(
                release_columns(self.model, state.u, self.model.fracture_tips),
                release_columns(other, res.u, other.fracture_tips))
            out.update({k: ESTIMATE_FACTOR * v for k, v in releases.items()})
        if "core tau" in self.tolerances:
            stresses = stress_changes(profile_columns(self.model, state.u),
                                      profile_columns(other, res.u))
            out.update({k: ESTIMATE_FACTOR * v for k, v in stresses.items()})
        return change, out

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

    def _way(self, state: PathState) -> float | None:
        """How far ``state`` is on the way to the target (the until probe's value, or load).

        None where the analysis has no target to measure it by.
        """
        a = self.scene.analysis
        ways = []
        if a.until_probe is not None and a.until_probe in state.probes and a.until_value:
            ways.append(state.probes[a.until_probe] / float(a.until_value))
        if a.until_load_factor:
            ways.append(state.load_factor / float(a.until_load_factor))
        return max(ways) if ways else None

    def _passed_fraction(self, state: PathState) -> bool:
        """Whether ``state`` is past the next check fraction of the way (that one then done)."""
        way = self._way(state) or 0.0
        passed = False
        while self._fractions and way >= self._fractions[0]:
            self._fractions.pop(0)
            passed = True
        return passed

    @staticmethod
    def _critical(state: PathState) -> bool:
        """Whether a bifurcation or load extremum was located within the step ending here."""
        return state.crossing is not None or state.extremum is not None


def _same_inertia(state: PathState, res: object) -> bool | None:
    """Whether ``res``'s factorised tangent has ``state``'s negative pivots (None: unknown)."""
    a, b = state.negative_pivots, res.factorization.negative_pivots
    return None if a is None or b is None else a == b
