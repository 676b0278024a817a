"""Equilibrium paths as curves: the path parameter, limit loads, common ranges, curve errors.

Both models' paths are compared as functions of one monotone *path parameter*: the scene's
``analysis.until_probe`` (the displacement the analysis drives to its target; its magnitude grows
along the path even past a limit load), or the load factor when the scene stops at a load factor.
Pure data handling: nothing here knows any mechanics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.results import Solution, StepRecord

LOAD = "load_factor"
LIMIT_DROP_RTOL = 0.005  # a load maximum counts when the load then falls by ≥ 0.5 % of it
CORE_ELLIPTICITY = "core_ellipticity"  # history column of the 2D core's crushing diagnostic


@dataclass(frozen=True)
class Curve:
    """A labelled sampled curve ``y(x)``."""

    label: str
    x: np.ndarray
    y: np.ndarray


@dataclass(frozen=True)
class CurveError:
    """Relative error of a curve against its reference over their common range.

    ``l2_relative`` = ‖y − y_ref‖₂ / ‖y_ref‖₂ and ``max_relative`` = max|y − y_ref| / max|y_ref|,
    both over ``common_range`` of the abscissa (trapezoidal L2 on the reference's samples there).
    ``None`` (with ``note``) when there is no common range.
    """

    quantity: str
    abscissa: str
    common_range: tuple[float, float] | None
    l2_relative: float | None
    max_relative: float | None
    samples: int
    note: str = ""


def series(solution: Solution, name: str) -> np.ndarray:
    """The load factor or one probe along the history of ``solution``."""
    if name == LOAD:
        return np.array([r.load_factor for r in solution.history], dtype=float)
    return np.array([r.probes[name] for r in solution.history], dtype=float)


def crushed_state(solution: Solution) -> StepRecord | None:
    """The first state whose core lost ellipticity (``core_ellipticity`` ≤ 0), else None.

    The 2D model writes the column (``sandwich/plane2d/core_crushing.py``); without it, None.
    """
    for r in solution.history:
        q = r.extra.get(CORE_ELLIPTICITY)
        if isinstance(q, int | float) and not isinstance(q, bool) and q <= 0:
            return r
    return None


def monotone_prefix(t: np.ndarray) -> int:
    """Length of the leading stretch of ``|t|`` that strictly increases (≥ 1 if non-empty)."""
    a = np.abs(t)
    if a.size == 0:
        return 0
    steps = np.diff(a) <= 0
    return int(np.argmax(steps)) + 1 if steps.any() else a.size


def limit_loads(load: np.ndarray, rtol: float = LIMIT_DROP_RTOL) -> list[int]:
    """Indices of load maxima along a path that the load afterwards falls from.

    A step ``i`` is kept when ``load[i]`` is a local maximum and, before the load climbs above
    ``load[i]`` again (or the path ends), it drops by at least ``rtol·|load[i]|``.
    """
    found = []
    n = load.size
    for i in range(1, n - 1):
        if not (load[i] >= load[i - 1] and load[i] > load[i + 1]):
            continue
        j, low = i + 1, load[i + 1]
        while j < n and load[j] <= load[i]:
            low = min(low, load[j])
            j += 1
        if load[i] - low >= rtol * abs(load[i]):
            found.append(i)
    return found


def curve_error(reference: Curve, other: Curve, quantity: str, abscissa: str) -> CurveError:
    """Relative L2 and max error of ``other`` against ``reference`` over the common abscissa range.

    Both abscissae must increase; ``other`` is interpolated linearly onto the reference samples
    in the common range (plus the range ends).
    """
    lo = max(reference.x.min(initial=np.inf), other.x.min(initial=np.inf))
    hi = min(reference.x.max(initial=-np.inf), other.x.max(initial=-np.inf))
    if reference.x.size < 2 or other.x.size < 2 or not hi > lo:
        return CurveError(quantity, abscissa, None, None, None, 0,
                          note="no common range of the abscissa")
    inner = reference.x[(reference.x > lo) & (reference.x < hi)]
    x = np.concatenate(([lo], inner, [hi]))
    y_ref = np.interp(x, reference.x, reference.y)
    y = np.interp(x, other.x, other.y)
    ref_norm = np.sqrt(np.trapz(y_ref**2, x))
    ref_max = np.max(np.abs(y_ref))
    if ref_norm == 0.0 or ref_max == 0.0:
        return CurveError(quantity, abscissa, (float(lo), float(hi)), None, None, x.size,
                          note="reference is zero over the common range")
    l2 = np.sqrt(np.trapz((y - y_ref) ** 2, x)) / ref_norm
    mx = np.max(np.abs(y - y_ref)) / ref_max
    return CurveError(quantity, abscissa, (float(lo), float(hi)), float(l2), float(mx), x.size)


def path_curve(solution: Solution, abscissa: str, quantity: str) -> tuple[Curve, str]:
    """``quantity`` along the path as a function of ``|abscissa|`` (its monotone prefix).

    Returns the curve and a note saying where the path was cut if ``|abscissa|`` stops growing.
    """
    t = series(solution, abscissa)
    n = monotone_prefix(t)
    note = "" if n == t.size else (f"{solution.model}: |{abscissa}| stops growing at step "
                                   f"{solution.history[n].step}; compared up to there")
    return Curve(solution.model, np.abs(t[:n]), series(solution, quantity)[:n]), note


def path_parameter(until_probe: str | None, solutions: list[Solution]) -> str:
    """The abscissa paths are compared on: the until probe if every path records it, else λ."""
    if until_probe and all(s.history and until_probe in s.history[0].probes for s in solutions):
        return until_probe
    return LOAD
