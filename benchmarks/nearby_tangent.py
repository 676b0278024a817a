"""A/B of the beam's nearby evaluation: after a converged increment the layers' tangent is kept.

Run from the project root: ``python -m benchmarks.nearby_tangent [--scenes NAME ...] [--levels
auto 1 3] [--out DIR]``. Writes ``benchmarks/results/beam/nearby_tangent.{md,csv}`` (a rerun
replaces them).

Each scene is solved in this process (kernels warm) twice per core setting, alternately: with
:meth:`sandwich.beam.model.BeamModel.internal_force_nearby` (as shipped) and with it removed
from the class (the corrector then evaluates every iterate in full, as before). Recorded: solve
wall time (``Solution.wall_seconds``), steps, Newton iterations, the end load and the largest
relative difference of the load factor over the two histories (equal step counts only).
"""

from __future__ import annotations

import argparse
import csv
import os

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.beam import run
from sandwich.beam.model import BeamModel
from sandwich.scene_file import load_scene

OUT = RESULTS / "beam"
DEFAULT_SCENES = ("default", "paper-fig5-top-debond-40-load-top",
                  "paper-fig6-top-debond-20-load-bottom", "paper-fig7-cantilever-c3",
                  "paper-fig9-clamped-d20", "paper-fig9-clamped-d40")


def solve(scene: object, level: str, nearby: bool) -> object:
    """One run; ``nearby`` False removes the method from the class for its duration."""
    options = None if level == "auto" else {"core_level": int(level)}
    method = BeamModel.internal_force_nearby
    if not nearby:
        del BeamModel.internal_force_nearby
    try:
        return run(scene, model_options=options).solution
    finally:
        if not nearby:
            BeamModel.internal_force_nearby = method


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    parser.add_argument("--levels", nargs="*", default=["auto"])
    add_out_argument(parser, OUT)
    args = parser.parse_args()
    stamp = measured_on()
    rows = []
    start_load = os.getloadavg()[0]
    for name in args.scenes:
        scene = load_scene(ROOT / "scenes" / f"{name}.toml")
        for level in args.levels:
            out = {}
            for nearby in (False, True):
                sol = solve(scene, level, nearby)
                out[nearby] = sol
            a, b = out[False], out[True]
            diff = float("nan")
            if len(a.history) == len(b.history):
                diff = max(abs(x.load_factor - y.load_factor) / max(abs(x.load_factor), 1e-300)
                           for x, y in zip(a.history, b.history, strict=True)
                           if x.load_factor != 0.0) if len(a.history) > 1 else 0.0
            row = {"scene": name, "core": level,
                   "before_s": round(a.wall_seconds, 3), "after_s": round(b.wall_seconds, 3),
                   "speed_up": round(a.wall_seconds / b.wall_seconds, 2),
                   "steps": f"{len(a.history) - 1} / {len(b.history) - 1}",
                   "iterations": f"{sum(s.iterations for s in a.history)} / "
                                 f"{sum(s.iterations for s in b.history)}",
                   "end_load": f"{a.history[-1].load_factor:.10g} / "
                               f"{b.history[-1].load_factor:.10g}",
                   "max_rel_diff": "different steps" if diff != diff else f"{diff:.1e}"}
            rows.append(row)
            print(row, flush=True)
    end_load = os.getloadavg()[0]
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "nearby_tangent.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        "# Nearby evaluation A/B (`benchmarks/nearby_tangent.py`)", "",
        "Iterations after a converged increment: every iterate evaluated in full (before) "
        "against the layers' tangent kept and the contact law re-evaluated (after, as shipped; "
        "`BeamModel.internal_force_nearby`, docs/speed.md). In process, kernels warm, "
        f"{stamp.rstrip('.')}; 1-minute load average "
        f"{start_load:.2f} at the start, {end_load:.2f} at the end (2 cores).", "",
        "| scene | core | before (s) | after (s) | speed-up | steps before / after | "
        "iterations before / after | end load before / after | max rel. diff of λ over the path |",
        "|---|---|---:|---:|---:|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['core']} | {r['before_s']} | {r['after_s']} | "
                     f"{r['speed_up']}× | {r['steps']} | {r['iterations']} | {r['end_load']} | "
                     f"{r['max_rel_diff']} |")
    (args.out / "nearby_tangent.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
