"""How accurate the 2D mesh is: the answer at the target against the next coarser level.

The resolution levels are nested (``sandwich.meshes.levels``: "medium" splits every element of
"coarse" along x and through the core in two, "fine" those of "medium", and each ``refine``
halves every size). With an error e ∝ h^p, the change δ of a quantity from the next coarser
level to this one is e (2^p − 1), so the error of this level is δ / (2^p − 1). The rates differ
from quantity to quantity and scene to scene (benchmarks/results/reference2d/mesh_error.md):
p ≈ 1 for the load of a peel couple (its crack tip's singularity governs it), about 1.4-1.7 for
G and G_II/G at fig. 5's tip, about 3 for fig. 5's end load. The estimate takes the slowest,
p = 1: δ itself (:func:`estimate_factor` = 1). It is then the true error where the rate is 1 and
errs on the safe side where the rate is higher (7 × the true error at p = 3, where that error
is small). The 5-mm averaged peak of the interface σzz sits at a crack tip or a support, where
σzz is singular (r^−½); its average converges at p = ½ (the peel couple: 0.52), so its
estimate is δ / (√2 − 1) = 2.4 δ (``RATES``).

The coarser level follows the whole path again (about a quarter of the cells, a quarter to a
third of the time): the two answers are compared at the target both reach. Level "coarse" and
level "explicit" at ``refine = 0`` have no coarser level: no estimate (the summary says so).
"""

from __future__ import annotations

from sandwich.meshes.levels import Coarser, coarser_level
from sandwich.results import Solution
from sandwich.results.changes import (
    STRESS_TOLERANCE,
    answer_change,
    averaged_peaks,
    release_changes,
    stress_changes,
    tolerances,
)
from sandwich.scene import Accuracy, Scene

__all__ = ["Coarser", "coarser_level", "estimate_factor", "mesh_estimate", "mesh_warnings",
           "not_measured", "plane2d_tolerances"]

RATE = 1.0  # the slowest convergence rate measured (a peel couple's load)
#: the rate taken for a quantity where it is not ``RATE``: the averaged peak of a stress singular
#: at a crack tip or support
RATES = {"interface sigma_zz": 0.5}
#: what each kind of quantity is held to where the scene's ``[accuracy]`` does not say (relative;
#: G_II/G absolute): G tighter than the beam's 3 %, the reference it is checked against
DEFAULTS = {"load": 0.01, "G": 0.02, "stresses": STRESS_TOLERANCE}
#: ... by quantity, every quantity estimated
TOLERANCES = tolerances(Accuracy(), DEFAULTS)


def plane2d_tolerances(scene: Scene) -> dict[str, float]:
    """What the 2D model holds each quantity it estimates to: the scene's, else ``DEFAULTS``."""
    return tolerances(scene.accuracy, DEFAULTS)


def estimate_factor(name: str) -> float:
    """The estimate of ``name``'s error over its change from the coarser level: 1 / (2^p − 1)."""
    return 1.0 / (2.0 ** RATES.get(name, RATE) - 1.0)


def not_measured(reason: str, against: Coarser | None = None,
                 held: dict[str, float] = TOLERANCES) -> dict[str, object]:
    """The summary entry of an estimate that could not be made, and why."""
    return {"how": "change from the next coarser mesh level",
            "against": None if against is None else str(against),
            "estimated_error": None, "quantities": {}, "tolerances": dict(held),
            "not_measured": reason}


def mesh_estimate(solution: Solution, coarse: Solution, against: Coarser,
                  held: dict[str, float] = TOLERANCES) -> dict[str, object]:
    """The summary entry ``mesh_error``: ``solution``'s answer at its target against ``coarse``.

    Both must have reached the scene's target (their last states are then the same point of
    the path); otherwise the estimate is not measured. The quantities: the load and probes, G
    and G_II/G at the debond tips, and the 5-mm averaged peaks of the interface σzz and the
    core τ (:mod:`sandwich.results.changes`). Each gets ``change`` (the change from the coarser
    level), ``estimated_error`` (:func:`estimate_factor` × it) and ``tolerance`` (``held``:
    by quantity, those estimated; :func:`plane2d_tolerances`).
    """
    if not solution.history:
        return not_measured("the path has no converged state", against, held)
    if not coarse.converged or not coarse.history:
        return not_measured(f"the path at level {against} did not reach the target "
                            f"({coarse.message})", against, held)
    mine, theirs = solution.history[-1], coarse.history[-1]
    changes: dict[str, float] = {}
    answer = answer_change(mine.load_factor, dict(mine.probes), theirs.load_factor,
                           dict(theirs.probes))
    if answer is not None:
        changes["load and probes"] = answer
    if "G" in held:
        changes.update(release_changes(_releases(mine.extra), _releases(theirs.extra)))
    mine_profile, their_profile = _target_profile(solution), _target_profile(coarse)
    if mine_profile is not None and their_profile is not None and "core tau" in held:
        changes.update(stress_changes(mine_profile, their_profile))  # the 5-mm averaged peaks
    if not changes:
        return not_measured("nothing to compare at the target (no load, no probe moved)",
                            against, held)
    quantities = {name: {"change": float(change),
                         "estimated_error": float(estimate_factor(name) * change),
                         "tolerance": held[name]}
                  for name, change in changes.items()}
    return {"how": "change from the next coarser mesh level",
            "against": str(against),
            "estimated_error": quantities.get("load and probes", {}).get("estimated_error"),
            "quantities": quantities, "tolerances": dict(held),
            "rates": {name: RATES.get(name, RATE) for name in quantities},
            "coarser_answer": {"load_factor": float(theirs.load_factor),
                               "probes": {k: float(v) for k, v in theirs.probes.items()},
                               "extra": _releases(theirs.extra),
                               "stress_peaks": ({} if their_profile is None
                                                else averaged_peaks(their_profile))},
            "coarser_cells": coarse.extra.get("cells"),
            "coarser_seconds": float(coarse.wall_seconds)}


def mesh_warnings(entry: dict[str, object], level: str, refine: int) -> list[str]:
    """One warning per quantity whose estimate exceeds its tolerance, saying what would help."""
    out = []
    here = str(Coarser(level, refine))
    finer = "level fine" if level in ("coarse", "medium") and refine == 0 else \
        f"refine = {refine + 1}"
    for name, q in (entry.get("quantities") or {}).items():
        if q["estimated_error"] > q["tolerance"]:
            out.append(f"2D mesh: the estimated error of {name} at the target, "
                       f"{100 * q['estimated_error']:.2g} %, exceeds "
                       f"{100 * q['tolerance']:.2g} % (level {here} against "
                       f"{entry['against']}); a finer mesh ({finer}) would lower it")
    return out


def _releases(extra: dict[str, object]) -> dict[str, float | None]:
    """The G columns of a history row's extra columns."""
    return {k: (None if v is None else float(v)) for k, v in extra.items()
            if k.startswith(("G_", "GI_", "GII_"))}


def _target_profile(solution: Solution) -> dict | None:
    """The profile columns of ``solution``'s last state, None where it has none."""
    if solution.profiles and solution.profiles[-1].step == solution.history[-1].step:
        return solution.profiles[-1].columns
    return None
