"""``auto`` core levels along a nonlinear path: rerun at raised levels while the end moves.

The linear step chose the first levels (:mod:`sandwich.beam.core_choice`). After the path at
those levels, the last converged state says where the core wants more levels
(:func:`sandwich.beam.core_levels.state_shares`); the levels are raised there and over every
debonded stretch and load patch, and the change of the path's end is the estimate (the end load
at a probe target, the probes at a load target: :func:`end_change`). Each raise is
first tried on the checked pass's end state alone (:meth:`CoreController.end_state`), and the
path is followed at the levels the checks end at; reruns continue while the estimate exceeds the
tolerance, at most ``rechecks`` times (:class:`AutoSettings`). :class:`CoreController` holds
where the raises stand between passes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from sandwich.beam.build import build_model, scene_gauss_orders
from sandwich.beam.core_levels import (
    DORFLER_FRACTION,
    LevelChoice,
    level_counts,
    lookahead_levels,
    raise_levels,
    state_shares,
    transfer,
)
from sandwich.beam.fracture import beam_tips, uniform_tip_levels
from sandwich.beam.model import BeamModel
from sandwich.beam.path_pass import PathPass, follow_penalised, max_penetration
from sandwich.results import PathNote
from sandwich.solver import PathState

# A rerun may take at most RERUN_STEP_FACTOR times the steps of the pass it checks (at least
# RERUN_MIN_STEPS): a raised model that needs far more steps has met a path the checked pass did
# not see (default scene, level 4 over the debond: a limit point at −6 mm the 2D model does not
# have, 240+ steps), and the kept answer is then the checked pass, said so.
CORE_RECHECKS = 3
RERUN_STEP_FACTOR = 4
RERUN_MIN_STEPS = 30
# Each raise is first tried on the checked pass's end state alone (CoreController.end_state):
# Newton with up to END_STATE_BACKTRACKS halvings per correction, END_STATE_ITERATIONS
# corrections.
END_STATE_CHECKS = True
END_STATE_MATCH = 1e-5  # relative: the pass at the checked levels must end at the check's load
END_STATE_ITERATIONS = 40
END_STATE_BACKTRACKS = 20
# A check whose change δ is at most BELOW_FRACTION × the tolerance says the levels below it are
# within the tolerance themselves: those levels are reported, with the estimate BELOW_FACTOR × δ
# (≈ δ / (1 − ρ) for a raise that halves the error, ρ = ½ — an estimate, not a bound: what it
# reads against level 4: docs/beam_element.md), and the path at the raised ones is not followed.
BELOW_FRACTION = 0.25
BELOW_FACTOR = 2.0


@dataclass(frozen=True)
class AutoSettings:
    """How ``auto`` re-checks the core levels along a path (defaults: the module constants).

    ``one_pass`` (the default): the levels are checked and raised along one path
    (:mod:`sandwich.beam.one_pass`); the other fields are the reruns' (:class:`CoreController`),
    which follow the path again after each raise.
    """

    one_pass: bool = True
    rechecks: int = CORE_RECHECKS  # raises at most
    rerun_step_factor: int = RERUN_STEP_FACTOR
    rerun_min_steps: int = RERUN_MIN_STEPS
    end_state_checks: bool = END_STATE_CHECKS  # False: follow the path after every raise
    end_state_match: float = END_STATE_MATCH
    end_state_iterations: int = END_STATE_ITERATIONS
    end_state_backtracks: int = END_STATE_BACKTRACKS
    below_fraction: float = BELOW_FRACTION
    below_factor: float = BELOW_FACTOR


class CheckedPass(NamedTuple):
    """A pass that reached the target, kept while the path at raised levels checks it."""

    path: PathPass
    levels: np.ndarray
    estimate: float | None


class Restart(NamedTuple):
    """Where the reruns resume if the end-state checks are not confirmed by the path."""

    kept: CheckedPass  # the pass the checks started from
    levels: np.ndarray  # its first raise
    previous: float  # its end load
    raises: int  # raises made with the first


class EndStateFinding(NamedTuple):
    """The last end-state check that converged: the path at ``levels`` must end at its load."""

    levels: np.ndarray
    previous: float  # the end load at the levels below ``levels``
    raises: int
    load_factor: float  # the check's end load


class EndStateChecks(NamedTuple):
    """What a series of end-state checks found (:meth:`CoreController.check_end_states`)."""

    found: EndStateFinding | None  # None: the first check failed
    complete: bool  # no check failed
    below_estimate: float | None  # the estimate of the levels below a check within the rule


class PendingCheck(NamedTuple):
    """An end-state check the next pass must confirm by ending at its load."""

    load_factor: float
    restart: Restart


class CoreController:
    """Follows the path at ``auto`` core levels, raising them while the end load changes.

    ``choice`` (the linear step's, :func:`~sandwich.beam.core_choice.choose_core_levels`) is
    updated in place: its levels, estimate and passes are the answer's. After :meth:`follow`,
    :attr:`capped` says the debond and load zones reached ``max_core_level`` and
    :attr:`stopped_rerun` holds the message of a rerun that stopped short ("" if none).
    """

    def __init__(self, scene: object, elements: int | None, options: dict, choice: LevelChoice,
                 progress: Callable[[object], None] | None = None,
                 settings: AutoSettings | None = None) -> None:
        self.scene, self.elements, self.options = scene, elements, options
        self.choice, self.progress = choice, progress
        self.settings = settings or AutoSettings()
        self.capped = False
        self.stopped_rerun = ""
        self.previous: float | None = None  # end load at the levels the current ones raised
        self.previous_probes: dict[str, float] = {}  # and its probes (load targets: the answer)
        self.kept: CheckedPass | None = None  # the last pass that reached the target
        self.raises = 0
        self.checks = self.settings.end_state_checks and scene.analysis.until_probe is not None
        self.pending: PendingCheck | None = None
        self.below_estimate: float | None = None  # of the levels below a check within the rule

    def run(self) -> PathPass:
        """The path at the levels ``auto`` ends at, its message with what the reruns met.

        :meth:`follow`; a rerun that stopped short is said so, and a path that stopped short
        at the chosen levels falls back to level 1 (:meth:`fallback`).
        """
        path = self.follow()
        if self.stopped_rerun:
            path = dataclasses.replace(path, warnings=[*path.warnings, (
                f"the rerun with raised core levels stopped ({self.stopped_rerun}); "
                "this is the pass it was checking")])
        return self.fallback(path)

    def follow(self) -> PathPass:
        """The path at the chosen levels: the last pass, or the pass a stopped rerun checked."""
        a, choice = self.scene.analysis, self.choice
        while True:
            path = follow_penalised(self.scene, self.elements,
                                    {**self.options, "core_level": choice.levels},
                                    self.progress, max_steps=self._rerun_budget())
            last = path.last
            if last.load_factor == 0.0:
                return path
            if self.pending is not None and self._restarted(path):
                continue
            if not path.converged and self.kept is not None:
                # The raised path stopped short of the target: keep the pass it was checking.
                choice.passes.append(self._pass_entry(path, reached=False, estimate=None,
                                                      stopped=path.message))
                self.stopped_rerun = path.message
                kept, choice.levels, choice.estimate = self.kept
                return kept
            if self.previous is not None:  # the change the last raise made is the estimate
                choice.estimate = (end_change(a, last, self.previous, self.previous_probes)
                                   if path.converged else None)
            if self.below_estimate is not None:  # confirmed: the levels below a check within it
                choice.estimate = self.below_estimate
            choice.passes.append(self._pass_entry(
                path, reached=path.converged,
                estimate=choice.estimate if self.previous is not None else None))
            bm = self.scene.beam_model
            tol, top = float(bm.tolerance), int(bm.max_core_level)
            if not path.converged or not np.any(choice.levels < top) or (
                    self.raises >= self.settings.rechecks) or (
                    choice.estimate is not None and self.previous is not None
                    and choice.estimate <= tol):
                return path
            self.kept = CheckedPass(path, choice.levels.copy(), choice.estimate)
            levels = self._raised_levels(path.model, last, choice.levels, top)
            if levels is None:
                self.capped = True
                return path
            self.raises += 1
            self.previous, self.previous_probes = last.load_factor, dict(last.probes)
            choice.levels = levels
            if self.checks and _at_probe_target(a, last):
                # Before following the path at the raised levels, continue its end state into
                # them: where the path at those levels ends there (the pass that follows
                # confirms it, else the checks are dropped), a raise that proves too small
                # costs one Newton solve instead of a path.
                start = Restart(self.kept, levels, self.previous, self.raises)
                found, complete, below = self.check_end_states(path, levels, tol, top)
                # A check that does not converge says the raised path ends far from the checked
                # one (c2: 736.8 → 268.3); the later raises' checks failed as well on every
                # shipped scene (c2, fig. 4), so none is tried after it.
                self.checks = complete
                if below is not None and found is None:
                    # this pass's own levels are within the tolerance: it is the answer
                    choice.levels, choice.estimate = self.kept.levels, below
                    return path
                if found is not None:
                    choice.levels, self.previous, self.raises, checked_load = found
                    self.pending = PendingCheck(checked_load, start)
                    self.below_estimate = below
            if self.progress is not None:
                self.progress(PathNote("checking the core levels: rerunning the path with "
                                       f"elements per core level {level_counts(choice.levels)}"))

    def _rerun_budget(self) -> int | None:
        """The steps a rerun may take: a multiple of the checked pass's (None: the first pass)."""
        if self.kept is None:
            return None
        s = self.settings
        return min(int(self.scene.analysis.max_steps),
                   max(s.rerun_min_steps, s.rerun_step_factor * (len(self.kept.path.states) - 1)))

    def _pass_entry(self, path: PathPass, **entry: object) -> dict:
        """The passes' entry of a path at the current levels."""
        return {"stage": f"path step {path.last.step}",
                "elements_per_level": level_counts(self.choice.levels),
                "load_factor": path.last.load_factor, **entry}

    def _restarted(self, path: PathPass) -> bool:
        """Settle the pending end-state check with ``path``; True: follow the path again.

        The path at the checked levels must end at the continued end state's load; where it
        does not (another equilibrium at the same deflection: fig. 6, fig. 4's rerun stopping
        short) the checks are not the paths' ends here: from the pass they started at, the path
        is followed after every raise, as without them.
        """
        pending, self.pending = self.pending, None
        last = path.last
        if not (not path.converged or abs(last.load_factor - pending.load_factor)
                > self.settings.end_state_match * abs(last.load_factor)):
            return False
        self.checks, self.below_estimate = False, None
        self.kept, first, self.previous, self.raises = pending.restart
        if np.array_equal(first, self.choice.levels):
            return False
        self.choice.passes.append(self._pass_entry(path, reached=path.converged, estimate=None,
                                                   end_state_confirmed=False))
        self.choice.levels = first
        return True

    def _raised_levels(self, model: BeamModel, last: PathState, levels: np.ndarray,
                       top: int) -> np.ndarray | None:
        """The levels a rerun checks after ``last`` (:func:`raised_levels`)."""
        return raised_levels(self.scene, self.elements, self.options, model, last, levels, top)

    def check_end_states(self, path: PathPass, levels: np.ndarray, tol: float,
                         top: int) -> EndStateChecks:
        """Raise on end states alone while the change they show exceeds ``tol``.

        From ``path``'s end (at the levels below ``levels``, end load :attr:`previous`), each
        check continues the end state into the raised levels (:meth:`end_state`); while its
        change exceeds ``tol`` (and raises remain, the zones are not at the cap) the levels are
        raised again from it. Found: the levels of the last check that converged, the end load
        at the levels below them, the raises count and the check's end load — the pass that
        follows must end there — or None if the first check fails. Where the last check's change
        δ is at most ``below_fraction × tol``, the estimate ``below_factor × δ`` of the levels
        below it, which are then the ones found (None: the checked pass's own levels, no path
        to follow). Each check is listed in the choice's passes.
        """
        s = self.settings
        found = None
        cur, state, last = path.model, path.last, path.last
        previous, raises = self.previous, self.raises
        while True:
            checked = self.end_state(cur, state, levels)
            if checked is None:
                return EndStateChecks(found, False, None)
            up, state = checked
            estimate = abs(state.load_factor - previous) / abs(state.load_factor)
            entry = {"stage": f"end state at step {last.step}",
                     "elements_per_level": level_counts(levels),
                     "load_factor": state.load_factor, "reached": True,
                     "estimate": estimate, "iterations": state.iterations}
            self.choice.passes.append(entry)
            if estimate <= s.below_fraction * tol:
                entry["levels_below_reported"] = True
                return EndStateChecks(found, True, s.below_factor * estimate)
            found = EndStateFinding(levels, previous, raises, state.load_factor)
            if estimate <= tol or not np.any(levels < top) or raises >= s.rechecks:
                return EndStateChecks(found, True, None)
            higher = self._raised_levels(up, state, levels, top)
            if higher is None:
                return EndStateChecks(found, True, None)
            cur, previous, levels, raises = up, state.load_factor, higher, raises + 1

    def end_state(self, model: BeamModel, state: PathState,
                  levels: np.ndarray) -> tuple[BeamModel, PathState] | None:
        """``state`` (at the until target) continued into the model at ``levels``, or None.

        The state is carried over (new enrichment amplitudes zero) and re-equilibrated at the
        same value of the until probe by Newton with a backtracking line search
        (:func:`sandwich.solver.newton.newton_correct`, ``backtracks``): the equilibrium of the
        raised model nearest the checked one, which is where the raised path ends when it stays
        on the same branch. None if that Newton fails or the state penetrates deeper than the
        bound.
        """
        from sandwich.solver.controls import ProbeConstraint
        from sandwich.solver.newton import NewtonSettings, newton_correct
        from sandwich.solver.system import inner_product

        a = self.scene.analysis
        up = build_model(self.scene, elements=self.elements, gauss=scene_gauss_orders(self.scene),
                         **{**self.options, "core_level": levels})
        c = np.asarray(up.probe_vector(a.until_probe), dtype=float)
        settings = NewtonSettings(
            tol=float(a.tol), max_iterations=self.settings.end_state_iterations,
            force_floor=float(np.linalg.norm(up.f_ref)) * abs(state.load_factor),
            backtracks=self.settings.end_state_backtracks)
        res = newton_correct(up, transfer(state.u, model, up), state.load_factor,
                             ProbeConstraint(c, float(a.until_value), inner_product(up)), settings)
        if not res.converged or res.load_factor == 0.0:
            return None
        if max_penetration(up, [res.u]) > up.penetration_bound():
            return None
        probes = {n: float(np.asarray(up.probe_vector(n)) @ res.u) for n in up.probe_rows}
        return up, PathState(state.step, res.u, float(res.load_factor), res.iterations, probes,
                             None)

    def fallback(self, path: PathPass) -> PathPass:
        """``path``, or the path at level 1 where it stopped short (:func:`level_1_fallback`)."""
        return level_1_fallback(self.scene, self.elements, self.options, self.choice, path,
                                self.progress)


def level_1_fallback(scene: object, elements: int | None, options: dict, choice: LevelChoice,
                     path: PathPass, progress: Callable[[object], None] | None) -> PathPass:
    """``path``, or the path at level 1 where the one at the chosen levels stopped short.

    The paper's element is the fallback (extremes map: thin faces, L/h = 5 and load x2
    reach their target only at level 1); the choice and the message say so.
    """
    if path.converged or not np.any(choice.levels > 1):
        return path
    stopped = path.message
    if progress is not None:
        progress(PathNote(f"the path at auto core levels stopped ({stopped}); following it "
                          "again at core level 1"))
    level_1 = follow_penalised(scene, elements, {**options, "core_level": 1}, progress)
    if not level_1.converged:
        return path
    choice.levels = np.ones_like(choice.levels)
    choice.estimate = None
    choice.passes.append({"stage": "fallback to level 1",
                          "elements_per_level": level_counts(choice.levels),
                          "load_factor": level_1.last.load_factor, "reached": True,
                          "estimate": None})
    return dataclasses.replace(level_1, warnings=[*level_1.warnings, (
        f"with auto core levels the path stopped ({stopped}); this is the "
        "paper's element (core level 1), its error not estimated")])


def raised_levels(scene: object, elements: int | None, options: dict, model: BeamModel,
                  last: PathState, levels: np.ndarray, top: int) -> np.ndarray | None:
    """The levels a check raises to after ``last``, or None where the zones are at the cap.

    The elements carrying DORFLER_FRACTION of the state shares (:func:`state_shares`) are
    raised, and so is every element over a debond or a load patch
    (:func:`local_zone_elements`): the residual points at singular spots (debond tips, point
    supports), where a raise hardly moves the load, while the load error of a buckled
    debond lives in the contact strip all along it (fig. 5: residual shares 81 % at the
    tips, load change there 0.5 %, true error 12 %). None when those zones cannot be raised:
    a check would raise only elements where the load error does not live, and its small
    change would read as convergence (demo scene: 0.05 % for a true 4.8 %).
    """
    inside = local_zone_elements(scene, model)
    if np.any(inside) and np.all(levels[inside] >= top):
        return None  # the zones are at the cap: what follows could not raise them
    up = build_model(scene, elements=elements, gauss=scene_gauss_orders(scene),
                     **{**options, "core_level": lookahead_levels(levels)})
    shares = state_shares(model, last.u, last.load_factor, up)
    marked = raise_levels(levels, shares, DORFLER_FRACTION * shares.sum(), top)
    zone = np.minimum(levels + 1, top)
    # no level change next to a debond tip: it biases G (docs/fracture.md)
    raised = uniform_tip_levels(model, beam_tips(scene, model),
                                np.where(inside, np.maximum(marked, zone), marked))
    if np.any(inside) and not np.any(raised[inside] > levels[inside]):
        return None
    return raised


def end_change(analysis: object, state: PathState, load_factor: float,
               probes: dict[str, float]) -> float | None:
    """The relative change of a path's end between two passes: what the scene asks for there.

    At a probe target the load factor is the answer (its relative change); at a load target the
    load is fixed and the probes are the answer: their largest change relative to the largest
    probe magnitude (a probe that barely moves is not divided by its own near-zero value).
    None where nothing can be compared (no probe moved).
    """
    if analysis.until_probe is not None and _at_probe_target(analysis, state):
        return abs(state.load_factor - load_factor) / abs(state.load_factor)
    scale = max((abs(v) for v in state.probes.values()), default=0.0)
    common = [n for n in state.probes if n in probes]
    if scale == 0.0 or not common:
        return None
    return max(abs(state.probes[n] - probes[n]) for n in common) / scale


def _at_probe_target(analysis: object, state: PathState) -> bool:
    """Whether ``state`` ended the path at the until probe's target (not at a load target)."""
    target = float(analysis.until_value)
    return abs(state.probes[analysis.until_probe] - target) <= 1e-4 * max(abs(target), 1e-12)


def local_zone_elements(scene: object, model: BeamModel) -> np.ndarray:
    """Elements over a debonded stretch or a load patch, widened by a core thickness."""
    margin = scene.core.thickness
    spans = [(d.start, d.end) for d in scene.debonds if d.end > d.start]
    spans += [(ld.x - ld.width / 2, ld.x + ld.width / 2) for ld in scene.loads]
    a, b = model.mesh.x[:-1], model.mesh.x[1:]
    inside = np.zeros(model.mesh.n_elements, dtype=bool)
    for lo, hi in spans:
        inside |= (b > lo - margin) & (a < hi + margin)
    return inside


def path_passes(choice: LevelChoice) -> int:
    """How many times auto followed the path (its passes after the linear-step ones)."""
    return sum(p["stage"].startswith("path step") for p in choice.passes)
