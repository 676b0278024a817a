"""Interface tractions ahead of every debond tip in both models: ``tip_tractions.csv`` + plots.

The rows come from each model's profile at the common path level the other profile figures use
(:func:`sandwich.compare.profiles.choose_common`), cut around each tip by
:func:`sandwich.results.tractions.tip_rows` (distance ``s`` ahead of the tip, σzz and τ of the
core at that interface, MPa). One figure per tip, ``tip_tractions_<debond>_<tip>.png``.
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from sandwich.compare.pair import BEAM, REFERENCE
from sandwich.compare.paths import Curve
from sandwich.compare.plots import Panel, overlay
from sandwich.compare.profiles import ChosenProfile
from sandwich.results.tractions import HEADER, scene_tips, tip_rows


def write_tip_tractions(scene: object, chosen: Mapping[str, ChosenProfile], out_dir: Path
                        ) -> list[Path]:
    """Write the combined table and one figure per tip; return the files written."""
    tips = scene_tips(scene)
    if not tips or not chosen:
        return []
    rows = [r for m in (REFERENCE, BEAM) if m in chosen
            for r in tip_rows(scene, chosen[m].profile, model=m)]
    out = Path(out_dir) / "tip_tractions.csv"
    with out.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(("model", *HEADER))
        w.writerows(rows)
    written = [out]
    levels = "; ".join(f"{m}: step {c.profile.step}, λ={c.load_factor:.4g}"
                       for m, c in chosen.items())
    for t in tips:
        key = (t.debond, t.tip)
        sz, tau = [], []
        for m in (REFERENCE, BEAM):
            mine = [r for r in rows if r[0] == m and (r[2], r[3]) == key]
            if not mine:
                continue
            s = np.array([float(r[5]) for r in mine])
            sz.append(Curve(m, s, np.array([float(r[7]) if r[7] != "" else np.nan
                                            for r in mine])))
            tau.append(Curve(m, s, np.array([float(r[8]) if r[8] != "" else np.nan
                                             for r in mine])))
        panels = [Panel("σzz (MPa)", sz, title=f"{t.interface} interface, s > 0 bonded",
                        spans=[(min(c.x.min() for c in sz), 0.0)] if sz else ()),
                  Panel("τ (MPa)", tau, spans=[(min(c.x.min() for c in tau), 0.0)] if tau else ())]
        png, table = overlay(Path(out_dir) / f"tip_tractions_{t.debond}_{t.tip}.png", panels,
                             "s: distance ahead of the tip (mm)",
                             f"{scene.name}: interface tractions at debond {t.debond} "
                             f"{t.tip} tip\n{levels}")
        written += [png, table]
    return written
