"""Profiles along the beam: picking the ones to compare, their errors and their peaks.

The two models may have written profiles at different steps. The pair compared is taken at the
*last common level* of the path parameter: the largest ``|parameter|`` both models have a profile
at or beyond; each model contributes its profile closest to that level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.compare.paths import Curve, CurveError, curve_error, series
from sandwich.results import Profile, Solution
from sandwich.results.peaks import peak

DEFLECTIONS = ("w_top", "w_bottom")
STRESSES = ("sigma_zz_top", "sigma_zz_bottom", "tau_core")


@dataclass(frozen=True)
class ChosenProfile:
    """A model's profile picked for comparison and where on the path it lies."""

    model: str
    profile: Profile
    level: float  # |path parameter| at the profile's step
    load_factor: float


@dataclass(frozen=True)
class PeakError:
    """The extreme (largest magnitude, signed) of a profile column in both models.

    ``relative_error`` = (|peak| − |peak_ref|) / |peak_ref|; ``shift`` is the distance in x
    between the two peaks (mm).
    """

    column: str
    peak: float
    peak_x: float
    reference_peak: float
    reference_x: float
    relative_error: float | None
    same_sign: bool
    shift: float


def profile_level(solution: Solution, profile: Profile, abscissa: str) -> tuple[float, float]:
    """``(|abscissa|, load factor)`` at the step of ``profile``."""
    steps = [r.step for r in solution.history]
    if profile.step not in steps:
        raise ValueError(f"{solution.model}: profile at step {profile.step} has no history row")
    i = steps.index(profile.step)
    return float(abs(series(solution, abscissa)[i])), solution.history[i].load_factor


def choose_common(solutions: list[Solution], abscissa: str) -> list[ChosenProfile] | None:
    """One profile per solution, at the last path level they all reached; ``None`` if impossible."""
    levels = []
    for s in solutions:
        usable = [(profile_level(s, p, abscissa), p) for p in s.profiles
                  if p.step in {r.step for r in s.history}]
        if not usable:
            return None
        levels.append(usable)
    common = min(max(lv[0][0] for lv in usable) for usable in levels)
    chosen = []
    for s, usable in zip(solutions, levels, strict=True):
        (level, lf), p = min(usable, key=lambda item: abs(item[0][0] - common))
        chosen.append(ChosenProfile(s.model, p, level, lf))
    return chosen


def _sorted_curve(profile: Profile, column: str, label: str) -> Curve:
    x = np.asarray(profile.columns["x"], dtype=float)
    order = np.argsort(x, kind="stable")
    return Curve(label, x[order], np.asarray(profile.columns[column], dtype=float)[order])


def profile_error(reference: Profile, other: Profile, column: str) -> CurveError:
    """Relative L2/max error of ``other[column]`` against ``reference[column]`` along x."""
    if column not in reference.columns or column not in other.columns:
        return CurveError(column, "x", None, None, None, 0, note=f"no column {column}")
    return curve_error(_sorted_curve(reference, column, "ref"), _sorted_curve(other, column, "o"),
                       column, "x")


def peak_error(reference: Profile, other: Profile, column: str,
               window: float = 0.0) -> PeakError | None:
    """Compare the peaks of ``column`` (window-averaged if ``window`` > 0, mm)."""
    if column not in reference.columns or column not in other.columns:
        return None
    ref, ref_x = peak(reference, column, window)
    val, val_x = peak(other, column, window)
    rel = (abs(val) - abs(ref)) / abs(ref) if ref != 0.0 else None
    return PeakError(column, val, val_x, ref, ref_x, rel, bool(np.sign(val) == np.sign(ref)),
                     abs(val_x - ref_x))
