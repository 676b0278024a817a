"""The paper's claims (section 3) as small checks on comparison data.

Each check reads :class:`~sandwich.compare.compare.Comparison` objects (keyed by scene name) and
gives,
per model, a :class:`Verdict`: ``reproduced``, ``not reproduced`` (with the numbers), or
``not checked`` (with the reason: a scene, model, column or limit point is missing). A claim is
never marked reproduced on missing data. The thresholds that turn words such as "several-fold"
into numbers are the named constants below.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from sandwich.compare.compare import Comparison
from sandwich.compare.pair import BEAM, REFERENCE
from sandwich.compare.paths import LOAD, Curve, curve_error, path_curve, series

REPRODUCED, NOT_REPRODUCED, NOT_CHECKED = "reproduced", "not reproduced", "not checked"
BOTH = "beam vs 2d"

LINEAR_FRACTION = 0.10  # the "linear range": |until probe| ≤ 10 % of its target value
LINEAR_AGREEMENT = 0.03  # relative L2 of the load curves in the linear range
TIP_DISTANCE = 5.0  # mm: a peak "at the debond tip" lies within this of a tip
SIGN_FRACTION = 0.01  # a sign counts when |σ| exceeds 1 % of the peak |σzz_top|
NO_CONTACT_FRACTION = 0.01  # "no contact stress": |p| ≤ 1 % of the peak |σzz_top|
TIP_MARGIN = 1.0  # mm kept off the debond tips when looking inside the span
SEVERAL_FOLD = 2.0  # "several-fold": max / min of the local-buckling loads ≥ 2
SAME_LOAD = 0.10  # "c3 ≈ c4": local-buckling loads within 10 %
BONDED_LIKE = 0.02  # "behaves as bonded": relative L2 of load curves vs d = 0 ≤ 2 %
DEFLECTION_LOAD_FRACTION = 0.5  # deflections compared at 50 % of the smallest peak load
KNEE_FRACTION = 0.2  # a knee: the step's stiffness dλ/d|w| falls below 20 % of the first step's


@dataclass(frozen=True)
class Verdict:
    """The outcome of one claim for one model (or for the pair): status and numbers or reason."""

    status: str
    detail: str


@dataclass(frozen=True)
class ClaimResult:
    """A claim of the paper, the figure it comes from, and its verdict per model."""

    figure: str
    claim: str
    verdicts: dict[str, Verdict]


Comparisons = Mapping[str, Comparison]


def _ok(flag: bool, detail: str) -> Verdict:
    return Verdict(REPRODUCED if flag else NOT_REPRODUCED, detail)


def _skip(reason: str) -> Verdict:
    return Verdict(NOT_CHECKED, reason)


def _scenes(cmps: Comparisons, prefix: str) -> list[Comparison]:
    return [c for name, c in sorted(cmps.items()) if name.startswith(prefix)]


def _one(cmps: Comparisons, prefix: str) -> Comparison | None:
    found = _scenes(cmps, prefix)
    return found[0] if found else None


def _per_model(cmps: Comparisons, prefix: str,
               check: Callable[[Comparison, str], Verdict]) -> dict[str, Verdict]:
    cmp = _one(cmps, prefix)
    out = {}
    for model in (REFERENCE, BEAM):
        if cmp is None:
            out[model] = _skip(f"no scene {prefix}* in the gallery")
        elif model not in cmp.solutions or not cmp.solutions[model].history:
            out[model] = _skip(f"{model}: {cmp.missing.get(model, 'no converged step')}")
        else:
            out[model] = check(cmp, model)
    return out


def _first_limit(cmp: Comparison, model: str) -> float | None:
    lls = cmp.metrics.models[model].limit_loads
    return lls[0].load_factor if lls else None


def buckling_load(cmp: Comparison, model: str) -> tuple[float | None, str]:
    """The local-buckling load of a path: its first critical point, else maximum, else knee.

    A critical point the model reported (a bifurcation or a load maximum, located within its
    step where the model located it) comes first: the earliest on the path. Without one, the
    first load maximum detected on the history. A debonded face that buckles against a core
    it cannot penetrate may give a knee rather than a maximum (the load keeps rising on a much
    softer branch). The knee is the start of the first step whose stiffness Δλ/Δ|w| (w: the
    scene's until probe) falls below ``KNEE_FRACTION`` of
    the first step's; it depends on the step sizes, so it brackets the buckling load from below
    to within one step. Returns ``(λ, "bifurcation" | "max" | "knee")`` or ``(None, reason)``.
    """
    critical = cmp.metrics.models[model].critical_loads
    if critical:
        first = min(critical, key=lambda c: (c.step, c.load_factor))
        return first.load_factor, first.kind
    lim = _first_limit(cmp, model)
    if lim is not None:
        return lim, "max"
    probe = cmp.scene.analysis.until_probe
    sol = cmp.solutions.get(model)
    if probe is None or sol is None or len(sol.history) < 3:
        return None, "no maximum, and no until probe or too few steps for a knee"
    lam = np.array([h.load_factor for h in sol.history])
    w = np.abs(np.array([h.probes[probe] for h in sol.history]))
    dw = np.diff(w)
    if np.any(dw <= 0):  # the probe turned back: no knee definition on this path
        return None, f"no maximum, and |{probe}| is not monotonic"
    k = np.diff(lam) / dw
    soft = np.flatnonzero(k < KNEE_FRACTION * k[0])
    if soft.size == 0:
        return None, "no maximum and no knee"
    return float(lam[soft[0]]), "knee"


def _profile(cmp: Comparison, model: str, column: str) -> tuple[np.ndarray, np.ndarray] | None:
    chosen = cmp.chosen_profiles.get(model)
    if chosen is None or column not in chosen.profile.columns:
        return None
    x = np.asarray(chosen.profile.columns["x"], dtype=float)
    return x, np.asarray(chosen.profile.columns[column], dtype=float)


def _top_debond(cmp: Comparison) -> tuple[float, float] | None:
    top = [d for d in cmp.scene.debonds_on("top") if d.length > 0]
    return (top[0].start, top[0].end) if top else None


# --- Fig 4 ---------------------------------------------------------------------------------


def linear_agreement(cmps: Comparisons) -> ClaimResult:
    """Fig 4b: beam and 2D load curves agree in the linear range."""
    claim = "all models agree in the linear range"
    cmp = _one(cmps, "paper-fig4")
    if cmp is None:
        return ClaimResult("4b", claim, {BOTH: _skip("no paper-fig4 scene")})
    if cmp.missing:
        return ClaimResult("4b", claim, {BOTH: _skip("; ".join(cmp.missing.values()))})
    a = cmp.metrics.abscissa
    target = cmp.scene.analysis.until_value
    if a == LOAD or target is None:
        return ClaimResult("4b", claim, {BOTH: _skip("scene has no until probe")})
    cut = LINEAR_FRACTION * abs(target)
    ref, _ = path_curve(cmp.solutions[REFERENCE], a, LOAD)
    beam, _ = path_curve(cmp.solutions[BEAM], a, LOAD)
    keep = lambda c: Curve(c.label, c.x[c.x <= cut], c.y[c.x <= cut])  # noqa: E731
    err = curve_error(keep(ref), keep(beam), LOAD, a)
    if err.l2_relative is None:
        return ClaimResult("4b", claim, {BOTH: _skip(f"linear range |{a}| ≤ {cut:.3g} mm: "
                                                     f"{err.note}")})
    return ClaimResult("4b", claim, {BOTH: _ok(
        err.l2_relative <= LINEAR_AGREEMENT,
        f"load L2 error {100 * err.l2_relative:.2f} % (≤ {100 * LINEAR_AGREEMENT:g} %) "
        f"for |{a}| ≤ {cut:.3g} mm")})


def rise_then_fall(cmps: Comparisons) -> ClaimResult:
    """Fig 4b: the force rises, reaches a maximum and falls at large deflection."""

    def check(cmp: Comparison, model: str) -> Verdict:
        lim = _first_limit(cmp, model)
        final = cmp.solutions[model].final_load_factor
        if lim is None:
            return _ok(False, f"no load maximum on the path (final λ = {final:.4g})")
        return _ok(True, f"max λ = {lim:.4g}, final λ = {final:.4g}")

    return ClaimResult("4b", "force rises then falls at large deflection",
                       _per_model(cmps, "paper-fig4", check))


# --- Fig 5 ---------------------------------------------------------------------------------


def _inside(x: np.ndarray, span: tuple[float, float], margin: float = 0.0) -> np.ndarray:
    return (x >= span[0] + margin) & (x <= span[1] - margin)


def top_face_buckles_up(cmps: Comparisons) -> ClaimResult:
    """Fig 5: in the debond the top face moves up relative to the bottom face (w_top > w_bottom)."""

    def check(cmp: Comparison, model: str) -> Verdict:
        span, top, bot = _top_debond(cmp), _profile(cmp, model, "w_top"), \
            _profile(cmp, model, "w_bottom")
        if span is None or top is None or bot is None:
            return _skip("no top debond or no face deflection profile")
        inside = _inside(top[0], span)
        opening = np.max(top[1][inside] - np.interp(top[0][inside], *bot))
        return _ok(opening > 0, f"max(w_top − w_bottom) in the debond = {opening:.3g} mm")

    return ClaimResult("5", "the delaminated top face buckles upward",
                       _per_model(cmps, "paper-fig5", check))


def partly_in_contact(cmps: Comparisons) -> ClaimResult:
    """Fig 5: the debonded top face touches the core over part of the debond, not all of it."""

    def check(cmp: Comparison, model: str) -> Verdict:
        span, p = _top_debond(cmp), _profile(cmp, model, "p_contact_top")
        if span is None or p is None:
            return _skip("profiles have no p_contact_top column")
        inside = _inside(p[0], span, TIP_MARGIN)
        touching = np.abs(p[1][inside]) > 0
        share = float(np.mean(touching)) if touching.size else 0.0
        return _ok(0 < share < 1, f"contact over {100 * share:.0f} % of the debond stations")

    return ClaimResult("5", "the delaminated face stays partly in contact",
                       _per_model(cmps, "paper-fig5", check))


def extremes_at_tips(cmps: Comparisons) -> ClaimResult:
    """Fig 5: |τ core| and |σzz top| peak within ``TIP_DISTANCE`` of a debond tip."""

    def check(cmp: Comparison, model: str) -> Verdict:
        span = _top_debond(cmp)
        tau, sig = _profile(cmp, model, "tau_core"), _profile(cmp, model, "sigma_zz_top")
        if span is None or tau is None or sig is None:
            return _skip("no top debond or no stress profiles")
        where = {name: float(xv[np.argmax(np.abs(v))]) for name, (xv, v) in
                 (("τ", tau), ("σzz top", sig))}
        dist = {k: min(abs(x - span[0]), abs(x - span[1])) for k, x in where.items()}
        return _ok(all(d <= TIP_DISTANCE for d in dist.values()),
                   ", ".join(f"peak {k} at x = {where[k]:.1f} mm ({dist[k]:.1f} mm from a tip)"
                             for k in where))

    return ClaimResult("5c-d", "core shear and interface normal stress are extreme at the tips",
                       _per_model(cmps, "paper-fig5", check))


def sign_change_between_tips(cmps: Comparisons) -> ClaimResult:
    """Fig 5c: σzz at the top interface takes both signs between the debond tips."""

    def check(cmp: Comparison, model: str) -> Verdict:
        span, sig = _top_debond(cmp), _profile(cmp, model, "sigma_zz_top")
        if span is None or sig is None:
            return _skip("no top debond or no sigma_zz_top profile")
        level = SIGN_FRACTION * np.max(np.abs(sig[1]))
        inside = sig[1][_inside(sig[0], span)]
        hi, lo = float(inside.max()), float(inside.min())
        return _ok(hi > level and lo < -level,
                   f"σzz top between the tips from {lo:.3g} to {hi:.3g} MPa")

    return ClaimResult("5c", "top-interface σzz changes sign between the tips",
                       _per_model(cmps, "paper-fig5", check))


# --- Fig 6 ---------------------------------------------------------------------------------


def loaded_face_deflects_more(cmps: Comparisons) -> ClaimResult:
    """Fig 6: with the load on the bottom face, |w_bottom| > |w_top| at the load."""

    def check(cmp: Comparison, model: str) -> Verdict:
        last = cmp.solutions[model].history[-1].probes
        if not {"w_top_mid", "w_bottom_mid"} <= set(last):
            return _skip("probes w_top_mid / w_bottom_mid missing")
        top, bot = abs(last["w_top_mid"]), abs(last["w_bottom_mid"])
        return _ok(bot > top, f"|w_bottom_mid| = {bot:.4g} mm, |w_top_mid| = {top:.4g} mm")

    return ClaimResult("6", "the loaded (bottom) face deflects more",
                       _per_model(cmps, "paper-fig6", check))


def debond_without_contact(cmps: Comparisons) -> ClaimResult:
    """Fig 6: the debonded top interface carries no (contact) stress between its tips."""

    def check(cmp: Comparison, model: str) -> Verdict:
        span = _top_debond(cmp)
        sig = _profile(cmp, model, "sigma_zz_top")
        p = _profile(cmp, model, "p_contact_top")
        if span is None or sig is None:
            return _skip("no top debond or no sigma_zz_top profile")
        used, data = ("p_contact_top", p) if p is not None else ("σzz top", sig)
        inside = np.abs(data[1][_inside(data[0], span, TIP_MARGIN)])
        peak = float(np.max(np.abs(sig[1])))
        worst = float(inside.max()) if inside.size else 0.0
        return _ok(worst <= NO_CONTACT_FRACTION * peak,
                   f"max |{used}| in the debond = {worst:.3g} MPa vs peak |σzz top| "
                   f"{peak:.3g} MPa")

    return ClaimResult("6", "the debond carries no contact stress",
                       _per_model(cmps, "paper-fig6", check))


# --- Fig 7 ---------------------------------------------------------------------------------


def _limits(cmps: Comparisons, prefix: str, model: str) -> tuple[dict[str, float | None], str]:
    """Local-buckling loads (:func:`buckling_load`) per scene suffix, and how each was found."""
    out, how, why = {}, [], ""
    for cmp in _scenes(cmps, prefix):
        if model not in cmp.solutions:
            why = f"{cmp.scene.name}: {cmp.missing.get(model, 'no solution')}"
            continue
        key = cmp.scene.name.removeprefix(prefix)
        out[key], kind = buckling_load(cmp, model)
        if out[key] is not None:
            how.append(f"{key} {kind}")
    return out, (why or "; ".join(how))


def location_changes_buckling_load(cmps: Comparisons) -> ClaimResult:
    """Fig 7: the cantilever's local-buckling load varies several-fold with debond location."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        lims, why = _limits(cmps, "paper-fig7-cantilever-", model)
        found = {k: v for k, v in lims.items() if v is not None}
        listing = ", ".join(f"{k}: {v:.4g}" if v is not None else f"{k}: none"
                            for k, v in lims.items())
        if len(found) < 2:
            verdicts[model] = _skip(f"fewer than two load maxima or knees ({listing or why})")
            continue
        ratio = max(found.values()) / min(found.values())
        verdicts[model] = _ok(ratio >= SEVERAL_FOLD,
                              f"max/min = {ratio:.2f} ({listing}; found by: {why})")
    return ClaimResult("7", "debond location changes the local-buckling force several-fold",
                       verdicts)


def c3_equals_c4(cmps: Comparisons) -> ClaimResult:
    """Fig 7: configurations c3 and c4 buckle at about the same load."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        lims, why = _limits(cmps, "paper-fig7-cantilever-", model)
        c3, c4 = lims.get("c3"), lims.get("c4")
        if c3 is None or c4 is None:
            verdicts[model] = _skip(f"c3 or c4 has no load maximum or knee ({why or lims})")
            continue
        diff = abs(c3 - c4) / max(abs(c3), abs(c4))
        verdicts[model] = _ok(diff <= SAME_LOAD, f"c3 {c3:.4g}, c4 {c4:.4g} ({100 * diff:.1f} %; "
                              f"found by: {why})")
    return ClaimResult("7", "c3 ≈ c4", verdicts)


# --- Fig 9 ---------------------------------------------------------------------------------


def _debond_length(cmp: Comparison) -> float:
    return max((d.length for d in cmp.scene.debonds), default=0.0)


def _fig9(cmps: Comparisons, model: str) -> tuple[list[tuple[float, Comparison]], str]:
    rows, why = [], ""
    for cmp in _scenes(cmps, "paper-fig9"):
        if model in cmp.solutions and cmp.solutions[model].history:
            rows.append((_debond_length(cmp), cmp))
        else:
            why = f"{cmp.scene.name}: {cmp.missing.get(model, 'no converged step')}"
    return sorted(rows, key=lambda r: r[0]), why


def longer_debonds_deflect_more(cmps: Comparisons) -> ClaimResult:
    """Fig 9: at a common load, mid-span deflection grows with the periodic debond length."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        rows, why = _fig9(cmps, model)
        if len(rows) < 2:
            verdicts[model] = _skip(f"fewer than two fig9 scenes ({why})")
            continue
        peaks = [float(series(c.solutions[model], LOAD).max()) for _, c in rows]
        level = DEFLECTION_LOAD_FRACTION * min(peaks)
        w = []
        for _, c in rows:
            s = c.solutions[model]
            lam = series(s, LOAD)
            n = int(np.argmax(lam >= level))  # first step at or beyond the level
            wn = np.abs(series(s, "w_top_mid"))
            if n == 0:
                w.append(float(wn[0]))
                continue
            t = (level - lam[n - 1]) / (lam[n] - lam[n - 1])  # linear between steps n-1, n
            w.append(float(wn[n - 1] + t * (wn[n] - wn[n - 1])))
        ok = all(b >= a for a, b in zip(w, w[1:], strict=False))
        listing = ", ".join(f"d={d:g}: {v:.4g}" for (d, _), v in zip(rows, w, strict=True))
        verdicts[model] = _ok(ok, f"|w_top_mid| (mm) at λ = {level:.4g}: {listing}")
    return ClaimResult("9", "longer periodic debonds give larger deflections", verdicts)


def longer_debonds_buckle_earlier(cmps: Comparisons) -> ClaimResult:
    """Fig 9: the local-buckling load (first maximum, else knee) falls as debonds get longer."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        rows, why = _fig9(cmps, model)
        lims = [(d, buckling_load(c, model)[0]) for d, c in rows]
        found = [(d, v) for d, v in lims if v is not None]
        if len(found) < 2:
            verdicts[model] = _skip(f"fewer than two fig9 load maxima or knees ({why or lims})")
            continue
        # a scene without a maximum in its range buckles later than any that has one
        seq = [np.inf if v is None else v for _, v in lims]
        ok = all(b <= a for a, b in zip(seq, seq[1:], strict=False))
        listing = ", ".join(f"d={d:g}: {'none' if v is None else f'{v:.4g}'}" for d, v in lims)
        verdicts[model] = _ok(ok, f"first max or knee λ: {listing}")
    return ClaimResult("9", "longer periodic debonds give lower local-buckling loads", verdicts)


def short_debonds_as_bonded(cmps: Comparisons) -> ClaimResult:
    """Fig 9: debonds of d ≤ 10 mm give the bonded (d = 0) load curve."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        rows, why = _fig9(cmps, model)
        bonded = [c for d, c in rows if d == 0]
        short = [(d, c) for d, c in rows if 0 < d <= 10]
        if not bonded or not short:
            verdicts[model] = _skip(f"needs d = 0 and 0 < d ≤ 10 scenes ({why or 'absent'})")
            continue
        ref, _ = path_curve(bonded[0].solutions[model], "w_top_mid", LOAD)
        parts, ok = [], True
        for d, c in short:
            cur, _ = path_curve(c.solutions[model], "w_top_mid", LOAD)
            err = curve_error(ref, cur, LOAD, "w_top_mid")
            if err.l2_relative is None:
                verdicts[model] = _skip(f"d={d:g}: {err.note}")
                break
            ok &= err.l2_relative <= BONDED_LIKE
            parts.append(f"d={d:g}: {100 * err.l2_relative:.2f} %")
        else:
            verdicts[model] = _ok(ok, "load-curve L2 vs d=0: " + ", ".join(parts))
    return ClaimResult("9", "short debonds (d ≤ 10 mm) behave as bonded", verdicts)


def second_buckling(cmps: Comparisons) -> ClaimResult:
    """Fig 9: the longest periodic debonds show a second load drop (two maxima)."""
    verdicts = {}
    for model in (REFERENCE, BEAM):
        rows, why = _fig9(cmps, model)
        if not rows:
            verdicts[model] = _skip(f"no fig9 scene solved ({why})")
            continue
        longest = max(d for d, _ in rows)
        long_rows = [(d, c) for d, c in rows if d >= 0.75 * longest and d > 0]
        counts = [(d, len(c.metrics.models[model].limit_loads)) for d, c in long_rows]
        ok = bool(counts) and all(n >= 2 for _, n in counts)
        verdicts[model] = _ok(ok, "load maxima: " + ", ".join(f"d={d:g}: {n}"
                                                              for d, n in counts))
    return ClaimResult("9", "long debonds show a second buckling (a second drop in force)",
                       verdicts)


CLAIMS: tuple[Callable[[Comparisons], ClaimResult], ...] = (
    linear_agreement, rise_then_fall, top_face_buckles_up, partly_in_contact, extremes_at_tips,
    sign_change_between_tips, loaded_face_deflects_more, debond_without_contact,
    location_changes_buckling_load, c3_equals_c4, longer_debonds_deflect_more,
    longer_debonds_buckle_earlier, short_debonds_as_bonded, second_buckling,
)


def check_claims(cmps: Comparisons) -> list[ClaimResult]:
    """Evaluate every claim of :data:`CLAIMS` on the comparisons (keyed by scene name)."""
    return [claim(cmps) for claim in CLAIMS]
