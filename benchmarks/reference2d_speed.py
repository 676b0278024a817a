"""Speed of the 2D reference: DOFs, Newton iterations and seconds per step, per mesh level.

Runs the fig4 and fig5 paper scenes (path shortened to w_top_mid = UNTIL mm unless --full) and
times where the work goes: residual assembly, tangent assembly (incl. contact), MUMPS
factorisation (numeric only after the first: the symbolic analysis is reused), contact
evaluation (wall times of rank 0). Runs under mpirun too (`mpirun -n 2 ... --out speed_2ranks`):
timings are then rank 0's, files written by rank 0.
Writes benchmarks/results/reference2d/<out>.{md,json}.

    XDG_CACHE_HOME=.cache .venv/bin/python benchmarks/reference2d_speed.py [--levels coarse medium]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

from mpi4py import MPI

from reference2d import contact as ct
from reference2d import model as model_mod
from reference2d import solve
from sandwich.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "reference2d"
SCENES = ("paper-fig4-bonded-3pb", "paper-fig5-top-debond-40-load-top")
UNTIL = -3.0


class Timers:
    """Wall time accumulated by the wrapped model methods."""

    def __init__(self):
        self.t = {"residual": 0.0, "tangent": 0.0, "factorize": 0.0, "contact": 0.0}

    def wrap(self, name, fn):
        def timed(*a, **k):
            t0 = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                self.t[name] += time.perf_counter() - t0
        return timed


def run(name, level, full, until=UNTIL):
    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    if not full:
        scene = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                        until_value=until))
    timers = Timers()
    build = model_mod.build_model

    def build_timed(*a, **k):
        m = build(*a, **k)
        s = m.system
        s.internal_force = timers.wrap("residual", s.internal_force)
        s.tangent = timers.wrap("tangent", s.tangent)
        s.factorize = timers.wrap("factorize", s.factorize)
        return m

    evaluate = ct.evaluate
    ct.evaluate = timers.wrap("contact", evaluate)
    solve_mod = sys.modules["reference2d.solve"]  # (the package exports a function `solve`)
    solve_mod.build_model = build_timed
    try:
        t0 = time.perf_counter()
        sol = solve(scene, level=level)
        wall = time.perf_counter() - t0
    finally:
        solve_mod.build_model = build
        ct.evaluate = evaluate
    steps = len(sol.history) - 1
    return {
        "scene": name, "level": level, "ranks": MPI.COMM_WORLD.size, "dofs": sol.dofs,
        "cells": sol.extra["cells"], "steps": steps,
        "newton_iterations": sol.extra["newton_iterations"],
        "reached": sol.converged, "final_load_factor": sol.final_load_factor,
        "wall_s": wall, "s_per_step": wall / max(steps, 1),
        **{f"{k}_s": v for k, v in timers.t.items()},
        "max_penetration_over_face_thickness": sol.extra["max_penetration_over_face_thickness"],
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    p.add_argument("--full", action="store_true", help="the scenes' full paths")
    p.add_argument("--until", type=float, default=UNTIL, help="w_top_mid target (mm)")
    p.add_argument("--out", default="speed", help="file stem under benchmarks/results/reference2d")
    args = p.parse_args()
    rows = []
    for name in SCENES:
        for level in args.levels:
            r = run(name, level, args.full, args.until)
            if MPI.COMM_WORLD.rank == 0:
                print(r, flush=True)
            rows.append(r)
    if MPI.COMM_WORLD.rank != 0:
        return
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / f"{args.out}.json").write_text(json.dumps(rows, indent=2) + "\n")
    head = ("| scene | level | ranks | DOFs | steps | Newton its | s/step | residual s | "
            "tangent s | factorise s | contact s | total s |")
    ranks = rows[0]["ranks"] if rows else 1
    lines = [f"Path to w_top_mid = {'target' if args.full else args.until} mm, {ranks} rank(s).",
             "", head,
             "|" + "---|" * 12]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['level']} | {r['ranks']} | {r['dofs']} | {r['steps']} "
                     f"| {r['newton_iterations']} | {r['s_per_step']:.3f} | {r['residual_s']:.1f} "
                     f"| {r['tangent_s']:.1f} | {r['factorize_s']:.1f} | {r['contact_s']:.2f} "
                     f"| {r['wall_s']:.1f} |")
    (OUT / f"{args.out}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
