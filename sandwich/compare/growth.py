"""The growth figures and table of a comparison whose scene grows debonds.

A growth run's history is its envelope (:mod:`sandwich.growth`): the onset states, one per
debond length, with the tip positions; a cohesive law's run (the beam) is one path, whose states
past the first growth give the load at each length the same way. Per growing debond,
``growth_<i>.png`` draws both models' onset load and onset deflection against the debond's
length (the knock-down of the growth load), ``growth_tips_<i>.png`` the tip positions against
the load along the whole growth history; ``growth.csv`` holds each model's first growth load and
residual strength (N) and their ratio to the 2D model's.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from sandwich.compare.pair import BEAM, REFERENCE
from sandwich.compare.paths import Curve
from sandwich.compare.plots import Panel, overlay
from sandwich.growth import onset_rows, tip_column
from sandwich.results import Solution
from sandwich.scene import Scene

GROWTH_TABLE = "growth.csv"


def growth_figures(scene: Scene, solutions: dict[str, Solution], out_dir: Path,
                   scale: float) -> tuple[list[Path], list[Path]]:
    """Write the growth figures and table; (figures, tables). Nothing when nothing grows.

    ``scale`` turns load factors into loads (N): Σ|force| of the scene's loads.
    """
    figures: list[Path] = []
    tables: list[Path] = []
    growing = [i for i, d in enumerate(scene.debonds) if d.growth is not None]
    runs = {m: s for m in (REFERENCE, BEAM) if (s := solutions.get(m)) is not None
            and isinstance(s.extra.get("debond_growth"), dict)
            and "method" in s.extra["debond_growth"]}
    if not growing or not runs:
        return figures, tables
    probe = scene.analysis.until_probe or scene.probes[0].name
    for i in growing:
        start, end = tip_column(i, "start"), tip_column(i, "end")
        loads, defl, tips = [], [], []
        d = scene.debonds[i]
        for model, s in runs.items():
            onsets = onset_rows(s.history)
            if "tips" in s.extra["debond_growth"]:  # a cohesive law: its path once grown
                onsets = [r for r in s.history
                          if r.extra.get(end, d.end) - r.extra.get(start, d.start)
                          > d.length + 1e-9]
            if not onsets:
                continue
            length = np.array([r.extra.get(end, d.end) - r.extra.get(start, d.start)
                               for r in onsets])
            loads.append(Curve(model, length, scale * np.array([r.load_factor for r in onsets])))
            defl.append(Curve(model, length, np.array([r.probes[probe] for r in onsets])))
            lam = scale * np.array([r.load_factor for r in s.history])
            for col in (start, end):
                if not any(col in r.extra for r in s.history):
                    continue  # an open mouth
                tips.append(Curve(f"{model} {col.rsplit('_', 1)[1]} tip", lam,
                                  np.array([r.extra.get(col, np.nan) for r in s.history])))
        if not loads:
            continue
        panels = [Panel("onset load P (N)", loads, title="load at which the debond grows"),
                  Panel(f"{probe} at onset (mm)", defl)]
        png, table = overlay(out_dir / f"growth_{i}.png", panels, "debond length (mm)",
                             f"{scene.name}: growth envelope of debond {i}")
        figures.append(png)
        tables.append(table)
        png, table = overlay(out_dir / f"growth_tips_{i}.png",
                             [Panel("tip position x (mm)", tips)], "load P (N)",
                             f"{scene.name}: debond {i}'s tips along the growth")
        figures.append(png)
        tables.append(table)
    tables.append(_growth_table(runs, out_dir / GROWTH_TABLE, scale))
    return figures, tables


def _growth_table(runs: dict[str, Solution], path: Path, scale: float) -> Path:
    """``growth.csv``: first growth load and residual strength per model, and beam / 2D."""
    rows = []
    ref = runs.get(REFERENCE)
    for model, s in runs.items():
        g = s.extra["debond_growth"]
        row = {"model": model, "method": g["method"], "stages": g.get("stages", ""),
               "first_growth_load_N": _n(g["first_growth_load"], scale),
               "residual_strength_N": _n(g["residual_strength"], scale),
               "residual_strength_bounded": g["bounded"], "wall_seconds": s.wall_seconds}
        if ref is not None and model != REFERENCE:
            r = ref.extra["debond_growth"]
            for key in ("first_growth_load", "residual_strength"):
                if g[key] is not None and r[key]:
                    row[f"{key}_over_2d"] = g[key] / r[key]
        rows.append(row)
    names = list(dict.fromkeys(k for r in rows for k in r))
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=names)
        w.writeheader()
        w.writerows(rows)
    return path


def _n(value: float | None, scale: float) -> float | str:
    """A load factor as a load (N), or an empty cell."""
    return "" if value is None else scale * value
