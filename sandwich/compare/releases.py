"""Energy release rate G along the path in both models: curves and their agreement.

Both models write, per converged step and debond tip, ``G_<debond>_<tip>``, ``GI_…``, ``GII_…``
(N/mm) into the history (docs/fracture.md). Here they become curves of G against the magnitude
of the path parameter (:func:`sandwich.compare.paths.path_parameter`, its monotone prefix), and the
beam's G is compared with the 2D one where both have it:

- ``l2_relative``, ``max_relative``: :func:`sandwich.compare.paths.curve_error` of G over the common
  range of the path parameter, both curves interpolated in √G onto the 2D steps;
- ``ratio_at_end``: G_beam / G_2D at the end of the common range, each interpolated in √G
  between its converged steps (G grows ~ quadratically with the load: √G is nearly linear);
- ``mode_ii_share_at_end``: G_II / G of each model there (each model's own split, docs;
  G_II and G linearly interpolated).

An empty G cell (not evaluated, the model's ``G_warning`` says why) is left out of the curve.
Pure data handling: the mechanics is the models'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sandwich.compare.paths import Curve, CurveError, curve_error, monotone_prefix, series
from sandwich.results import Solution

PARTS = ("G", "GI", "GII")


@dataclass(frozen=True)
class ReleaseAgreement:
    """How far the beam's G at one tip is from the 2D one (``None`` where not computable)."""

    tip: str  # "<debond>_<tip>", e.g. "0_end"
    abscissa: str
    common_range: tuple[float, float] | None
    l2_relative: float | None
    max_relative: float | None
    ratio_at_end: float | None
    mode_ii_share_at_end: dict[str, float | None] = field(default_factory=dict)
    G_at_end: dict[str, float | None] = field(default_factory=dict)
    samples: int = 0
    note: str = ""


def tips(solution: Solution | None) -> list[str]:
    """The tips ``"<debond>_<tip>"`` whose G columns ``solution`` holds."""
    if solution is None:
        return []
    names = {k for r in solution.history for k in r.extra if k.startswith("G_")}
    return sorted(n[2:] for n in names)


def release_curve(solution: Solution, abscissa: str, tip: str, part: str = "G") -> Curve:
    """``part`` (G, GI or GII, N/mm) at ``tip`` against |abscissa| (monotone prefix, no blanks)."""
    t = series(solution, abscissa)
    n = monotone_prefix(t)
    name = f"{part}_{tip}"
    values = [r.extra.get(name) for r in solution.history[:n]]
    keep = np.array([v is not None and math.isfinite(v) for v in values], dtype=bool)
    y = np.array([v if k else 0.0 for v, k in zip(values, keep, strict=True)], dtype=float)
    return Curve(solution.model, np.abs(t[:n])[keep], y[keep])


def _sqrt_interp(c: Curve, x: float) -> float:
    return float(np.interp(x, c.x, np.sqrt(np.maximum(c.y, 0.0))) ** 2)


def _sqrt_curve_error(ref: Curve, other: Curve, quantity: str, abscissa: str) -> CurveError:
    """:func:`~sandwich.compare.paths.curve_error` with both curves interpolated in √G.

    G grows about quadratically along a path: interpolating G linearly between a model's
    steps would count its step size as an error; √G is nearly linear, so the curves are
    interpolated in √G onto the reference's samples (plus the ends of the common range).
    """
    lo = max(ref.x.min(initial=np.inf), other.x.min(initial=np.inf))
    hi = min(ref.x.max(initial=-np.inf), other.x.max(initial=-np.inf))
    if ref.x.size < 2 or other.x.size < 2 or not hi > lo:
        return curve_error(ref, other, quantity, abscissa)  # its "no common range" answer
    x = np.concatenate(([lo], ref.x[(ref.x > lo) & (ref.x < hi)], [hi]))
    fine = Curve(ref.label, x, np.array([_sqrt_interp(ref, v) for v in x]))
    return curve_error(fine, Curve(other.label, x, np.array([_sqrt_interp(other, v) for v in x])),
                       quantity, abscissa)


def release_agreement(beam: Solution, ref: Solution, abscissa: str, tip: str
                      ) -> ReleaseAgreement:
    """The agreement of the beam's G at ``tip`` with the 2D reference's."""
    g_ref, g_beam = (release_curve(s, abscissa, tip) for s in (ref, beam))
    err = _sqrt_curve_error(g_ref, g_beam, f"G_{tip}", f"|{abscissa}|")
    if err.common_range is None:
        return ReleaseAgreement(tip, f"|{abscissa}|", None, None, None, None,
                                note=err.note or "no common range")
    hi = err.common_range[1]
    at_end = {s.model: _sqrt_interp(release_curve(s, abscissa, tip), hi) for s in (ref, beam)}
    share: dict[str, float | None] = {}
    for s in (ref, beam):  # both parts linearly interpolated at the end of the range
        g = release_curve(s, abscissa, tip)
        gii = release_curve(s, abscissa, tip, "GII")
        g_hi = float(np.interp(hi, g.x, g.y))
        share[s.model] = float(np.interp(hi, gii.x, gii.y)) / g_hi if g_hi > 0 else None
    ratio = at_end[beam.model] / at_end[ref.model] if at_end[ref.model] > 0 else None
    return ReleaseAgreement(tip, f"|{abscissa}|", err.common_range, err.l2_relative,
                            err.max_relative, ratio, share, at_end, err.samples, err.note)


def release_agreements(beam: Solution | None, ref: Solution | None, abscissa: str
                       ) -> list[ReleaseAgreement]:
    """One :class:`ReleaseAgreement` per tip both models report G at."""
    if beam is None or ref is None or not beam.history or not ref.history:
        return []
    both = sorted(set(tips(beam)) & set(tips(ref)))
    return [release_agreement(beam, ref, abscissa, t) for t in both]
