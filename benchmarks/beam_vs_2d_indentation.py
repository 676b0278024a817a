"""Beam vs 2D: local indentation of a bonded face under patch loads of decreasing width (linear).

Experiment for docs/comparisons.md §3. The Fig 4 beam (bonded, three-point bending) is loaded
linearly (λ = 100 N) by a patch on the top face at mid-span whose width goes from the whole span
down to 2.5 mm. Printed per width, for both models: w_top_mid, w_bottom_mid and the indentation
w_top_mid − w_bottom_mid (the squeeze of the core under the load), and their beam/2D ratios.
The bottom face measures the global response (bending, shear, supports); the indentation is the
core's local response, which the paper's core (cubic in z over its whole height) can only
approximate once the load is narrow compared with the core thickness (25 mm).

Run from the project root: ``python -m benchmarks.beam_vs_2d_indentation [--elements 480]
[--levels coarse medium] [--out DIR]``. Writes ``benchmarks/results/comparisons/indentation.md``
(a rerun replaces it).
"""

from __future__ import annotations

import argparse
import dataclasses

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.scene import Scene
from sandwich.scene_file import load_scene

OUT = RESULTS / "comparisons"
WIDTHS = (300.0, 40.0, 20.0, 10.0, 5.0, 2.5)
LOAD = 100.0


def scene_with_patch(width: float) -> Scene:
    s = load_scene(ROOT / "scenes" / "paper-fig4-bonded-3pb.toml")
    loads = tuple(dataclasses.replace(ld, x=s.length / 2, width=width) for ld in s.loads)
    an = dataclasses.replace(s.analysis, kind="linear", until_probe=None, until_value=None,
                             until_load_factor=LOAD)
    return dataclasses.replace(s, name=f"fig4-linear-patch-{width:g}", loads=loads, analysis=an)


def probes(sol) -> tuple[float, float]:
    last = sol.history[-1]
    return last.probes["w_top_mid"], last.probes["w_bottom_mid"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=480)
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium"])
    add_out_argument(ap, OUT)
    args = ap.parse_args(argv)
    stamp = measured_on()
    import sandwich.beam
    import sandwich.plane2d

    md = ["# Indentation under a patch load, bonded fig4 beam, linear (λ = 100 N)", "",
          f"benchmarks/beam_vs_2d_indentation.py; beam {args.elements} graded elements "
          "(averaged face membrane: the converged element, linear answers equal the paper's); "
          f"2D levels {', '.join(args.levels)} (ratios against the last). Indentation = "
          "w_top_mid − w_bottom_mid.", "", stamp, "",
          "| patch width (mm) | beam w_top | beam w_bot | beam indent. | "
          + " | ".join(f"2D {lv} indent." for lv in args.levels)
          + " | 2D w_bot | ratio w_bot | ratio indent. |",
          "|---:|---:|---:|---:|" + "---:|" * len(args.levels) + "---:|---:|---:|"]
    for width in WIDTHS:
        s = scene_with_patch(width)
        bt, bb = probes(sandwich.beam.run(s, elements=args.elements,
                                         model_options={"face_membrane": "averaged"}).solution)
        ref = [probes(sandwich.plane2d.solve(s, level=lv, estimate=False)) for lv in args.levels]
        rt, rb = ref[-1]
        md.append(f"| {width:g} | {bt:.5f} | {bb:.5f} | {bt - bb:.5f} | "
                  + " | ".join(f"{t - b:.5f}" for t, b in ref)
                  + f" | {rb:.5f} | {bb / rb:.4f} | {(bt - bb) / (rt - rb):.4f} |")
        print(md[-1], flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "indentation.md").write_text("\n".join(md) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
