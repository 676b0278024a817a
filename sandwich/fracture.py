"""Will a debond grow? The mixed-mode criterion on the G columns of a solution's history.

Both models write, per converged step and debond tip, ``G_<debond>_<tip>``, ``GI_…`` and
``GII_…`` (N/mm) into the history. A debond with ``toughness = { GIc, GIIc, eta }`` is judged
by the Benzeggagh–Kenane criterion (Compos. Sci. Technol. 56, 1996):

    G ≥ G_c(ψ) = GIc + (GIIc − GIc) (G_II / G)^eta,

eta the BK exponent (scene key ``eta``, default 2). The summary reports, per tip, the first
converged step where it is reached (or none, with the largest G/G_c of the path).
"""

from __future__ import annotations

import math

from sandwich.results import LimitPoint, StepRecord
from sandwich.results.fracture import column_names, is_release_column
from sandwich.scene import Scene, Toughness

CRITERION = "Benzeggagh-Kenane"
TIPS = ("start", "end")


def bk_toughness(t: Toughness, gi: float, gii: float) -> float:
    """G_c (N/mm) of the mode mix G_II / (G_I + G_II); pure mode I when G = 0."""
    g = gi + gii
    ratio = min(max(gii / g, 0.0), 1.0) if g > 0 else 0.0
    return t.GIc + (t.GIIc - t.GIc) * ratio**t.eta


def growth_onset(scene: Scene, history: list[StepRecord]) -> dict[str, dict[str, object]]:
    """Per tip of every debond with a toughness: the first step where G ≥ G_c, or none.

    Keys ``"<debond>_<tip>"``; values hold the criterion, eta, and either the step, load factor,
    G, G_c and G_II/G there (or ``step = None``), and the largest G/G_c along the path.
    """
    out: dict[str, dict[str, object]] = {}
    for i, d in enumerate(scene.debonds):
        if d.toughness is None:
            continue
        for tip in TIPS:
            g_name = f"G_{i}_{tip}"
            if not any(g_name in r.extra for r in history):
                continue  # an open mouth, or a tip outside the meshed stretch
            entry: dict[str, object] = {"criterion": CRITERION, "eta": d.toughness.eta,
                                        "GIc": d.toughness.GIc, "GIIc": d.toughness.GIIc,
                                        "step": None}
            worst = 0.0
            for r in history:
                values = [r.extra.get(n) for n in column_names(i, tip)]
                if any(v is None for v in values):
                    continue  # an empty cell: G not evaluated at this step (G_warning says why)
                g, gi, gii = (float(v) for v in values)
                gc = bk_toughness(d.toughness, gi, gii)
                worst = max(worst, g / gc)
                if g >= gc and entry["step"] is None:
                    entry.update(step=r.step, load_factor=r.load_factor, G=g, Gc=gc,
                                 GII_over_G=gii / g if g > 0 else 0.0)
            entry["max_G_over_Gc"] = worst
            out[f"{i}_{tip}"] = entry
    return out


def missing_releases(history: list[StepRecord]) -> str:
    """Where G columns are empty (``None``): ``"<column> at step(s) …"`` joined, or ``""``."""
    where: dict[str, list[int]] = {}
    names = sorted({k for r in history for k in r.extra
                    if is_release_column(k) and k.startswith("G_")})
    for r in history:
        for n in names:
            if r.extra.get(n) is None:
                where.setdefault(n, []).append(r.step)
    return "; ".join(f"{n} at step(s) {_steps(s)}" for n, s in where.items())


NEAR_CRITICAL = 0.9  # G at a load at least this fraction of the next critical load is looked at
STEEP_EXPONENT = 4.0  # … and flagged where G grows at least as λ^4 there (1 % of load, 4 % of G)


def ill_conditioned_releases(history: list[StepRecord], limit_points: list[LimitPoint],
                             fraction: float = NEAR_CRITICAL) -> str:
    """Where G was evaluated close below the path's first critical load and grows steeply there.

    Approaching a bifurcation or a load maximum λc, G may grow steeply with λ: a small error in
    either model's λc then becomes a large one in G (fig. 5 near its bifurcation: 0.1 % in λc,
    ≈ 10 % in G). The states before the step of the first critical point whose λ ≥
    ``fraction`` × λc and that carry G are named where the steepest local exponent s of
    G ∝ λ^s between two of them (1 % of load is ≈ s % of G) is at least ``STEEP_EXPONENT``;
    ``""`` otherwise (ordinary growth, G ∝ λ², is not flagged).
    """
    critical = [lp for lp in limit_points if lp.kind in ("bifurcation", "max")
                and lp.load_factor > 0]
    if not critical:
        return ""
    first = min(critical, key=lambda lp: (lp.step, lp.load_factor))
    lam_c = float(first.load_factor)
    names = sorted({k for r in history for k in r.extra if k.startswith("G_")
                    and is_release_column(k)})
    near = [r for r in history if r.step < first.step and fraction * lam_c <= r.load_factor
            < lam_c and any(r.extra.get(n) for n in names)]
    if not near:
        return ""
    near_steps = {r.step for r in near}
    steep = 0.0
    for a, b in zip(history, history[1:], strict=False):
        if b.step not in near_steps or not 0 < a.load_factor < b.load_factor:
            continue
        for n in names:
            ga, gb = a.extra.get(n), b.extra.get(n)
            if ga and gb and ga > 0 and gb > 0:
                steep = max(steep, math.log(gb / ga) / math.log(b.load_factor / a.load_factor))
    if steep < STEEP_EXPONENT:
        return ""
    return (f"G at step(s) {_steps([r.step for r in near])} is within "
            f"{100 * (1 - fraction):.0f} % below the first critical load (the {first.kind} at "
            f"λ {lam_c:.6g}): it is ill-conditioned there — a small error in the critical load "
            f"is a large one in G (G ∝ λ^{steep:.3g} there at its steepest)")


def _steps(steps: list[int]) -> str:
    if len(steps) <= 6:
        return ", ".join(map(str, steps))
    return f"{steps[0]}…{steps[-1]} ({len(steps)})"
