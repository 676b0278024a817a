"""Will a debond grow? The mixed-mode criterion on the G columns of a solution's history.

Both models write, per converged step and debond tip, ``G_<debond>_<tip>``, ``GI_…`` and
``GII_…`` (N/mm) into the history. A debond with ``toughness = { GIc, GIIc, eta }`` is judged
by the Benzeggagh–Kenane criterion (Compos. Sci. Technol. 56, 1996):

    G ≥ G_c(ψ) = GIc + (GIIc − GIc) (G_II / G)^eta,

eta the BK exponent (scene key ``eta``, default 2). The summary reports, per tip, the first
converged step where it is reached (or none, with the largest G/G_c of the path).
"""

from __future__ import annotations

from sandwich.results import StepRecord
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
                g = float(r.extra.get(g_name, 0.0))
                gi, gii = float(r.extra[f"GI_{i}_{tip}"]), float(r.extra[f"GII_{i}_{tip}"])
                gc = bk_toughness(d.toughness, gi, gii)
                worst = max(worst, g / gc)
                if g >= gc and entry["step"] is None:
                    entry.update(step=r.step, load_factor=r.load_factor, G=g, Gc=gc,
                                 GII_over_G=gii / g if g > 0 else 0.0)
            entry["max_G_over_Gc"] = worst
            out[f"{i}_{tip}"] = entry
    return out
