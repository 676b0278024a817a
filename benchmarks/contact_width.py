"""What the contact law's regularisation width costs and changes: the beam's paths at × 1 and wider.

Run from the project root: ``python -m benchmarks.contact_width [--scenes NAME ...] [--levels 1
auto] [--factors 1 10] [--out DIR]``. Writes ``benchmarks/results/beam/contact_width.{md,csv}``
(a rerun replaces them).

The penalty law of a debonded interface (``sandwich.beam.contact.pressure_law``) is regularised
over a width s (default ``sandwich.beam.build.default_contact_smoothing``,
1e-6 mm on the shipped scenes). Newton converges linearly on pairs in the law's exponential
tail (docs/speed.md, "What bounds the rest"), which sets the iteration count of every
debond scene. This benchmark solves each scene in this process with s × each factor
(``build_model(contact_smoothing=...)``) and records the solve wall time, steps, Newton
iterations, factorisations, penalty reruns (a wider law penetrates deeper at the same pressure;
past the bound the path is rerun with a stiffer penalty) and the end load, with its relative
change against factor 1. It measures a modelling choice — the answers move — and changes
nothing in the code: the shipped width stays until that choice is made against the 2D model.
"""

from __future__ import annotations

import argparse
import csv
import os
import time

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.beam import run
from sandwich.beam.build import default_contact_smoothing
from sandwich.beam.model import BeamModel
from sandwich.scene_file import load_scene

OUT = RESULTS / "beam"
DEFAULT_SCENES = tuple(p.stem for p in sorted((ROOT / "scenes").glob("*.toml")))
COLUMNS = ["scene", "core", "factor", "width_mm", "wall_s", "steps", "iterations",
           "factorisations", "penalty_reruns", "reached", "end_load", "change"]


def solve(scene: object, level: str, factor: float) -> dict[str, object]:
    """One run at ``factor`` × the default width; its cost and end state."""
    width = factor * default_contact_smoothing(scene)
    options: dict[str, object] = {"contact_smoothing": width}
    if level != "auto":
        options["core_level"] = int(level)
    count = [0]
    factorize = BeamModel.factorize

    def counted(self, *args, **kwargs):
        count[0] += 1
        return factorize(self, *args, **kwargs)

    BeamModel.factorize = counted
    try:
        t = time.perf_counter()
        result = run(scene, model_options=options)
        wall = time.perf_counter() - t
    finally:
        BeamModel.factorize = factorize
    states, sol = result.states, result.solution
    return {"width_mm": width, "wall_s": wall, "steps": len(states) - 1,
            "iterations": sum(s.iterations for s in states), "factorisations": count[0],
            "penalty_reruns": sol.extra.get("contact_penalty_reruns", 0),
            "reached": sol.converged, "end_load": states[-1].load_factor}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    parser.add_argument("--levels", nargs="*", default=["1", "auto"])
    parser.add_argument("--factors", nargs="*", type=float, default=[1.0, 10.0])
    add_out_argument(parser, OUT)
    args = parser.parse_args()
    stamp = measured_on()
    if 1.0 not in args.factors:
        parser.error("--factors must include 1 (the shipped width, the reference)")
    start = os.getloadavg()
    rows = []
    for name in args.scenes:
        scene = load_scene(ROOT / "scenes" / f"{name}.toml")
        if not any(d.end > d.start for d in scene.debonds):
            print(f"{name}: no debond, no contact law: skipped", flush=True)
            continue
        for level in args.levels:
            ref = None
            for factor in sorted(args.factors):
                row = {"scene": name, "core": level, "factor": factor, **solve(scene, level,
                                                                                 factor)}
                if factor == 1.0:
                    ref = row["end_load"]
                row["change"] = (abs(row["end_load"] - ref) / abs(ref)
                                 if ref and row["reached"] else None)
                rows.append(row)
                print(f"{name} core {level} ×{factor:g}: {row['wall_s']:.2f} s, "
                      f"{row['iterations']} its, λ {row['end_load']:.10g}", flush=True)
    end = os.getloadavg()
    args.out.mkdir(parents=True, exist_ok=True)
    with (args.out / "contact_width.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r[k] is None else r[k]) for k in COLUMNS})
    md = ["# Contact law regularisation width: cost and end load (benchmarks/contact_width.py)",
          "",
          "Every shipped scene with a debond solved in one process (kernels warm), the width s "
          "of the regularised penalty law at × 1 (shipped) and wider. `change`: relative "
          "change of the end load against × 1. A modelling choice, measured: nothing in the "
          "code changes.",
          "",
          stamp, "",
          f"Load average {start[0]:.2f} at the start, {end[0]:.2f} at the end (2 cores).", "",
          "| scene | core | width × | s (mm) | wall (s) | steps | Newton its | factorisations "
          "| penalty reruns | reached | end λ | change |",
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|"]
    for r in rows:
        change = "—" if r["change"] is None else f"{r['change']:.1e}"
        md.append(f"| {r['scene']} | {r['core']} | {r['factor']:g} | {r['width_mm']:.1e} | "
                  f"{r['wall_s']:.2f} | {r['steps']} | {r['iterations']} | "
                  f"{r['factorisations']} | {r['penalty_reruns']} | {r['reached']} | "
                  f"{r['end_load']:.8g} | {change} |")
    (args.out / "contact_width.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    main()
