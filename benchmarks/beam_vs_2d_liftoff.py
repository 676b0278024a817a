"""Beam vs 2D: where does the compressed debonded face go unstable, and what precedes it?

Two experiments for docs/comparisons.md §3 (both models, profiles at every step):

- ``fig5``: the paper's Fig 5 scene (40 mm top debond, 10 mm patch load on top at mid-span) to
  ``w_top_mid = -5`` under displacement control in steps of at most ``STEP`` mm, so that the
  bifurcation (first state with a negative pivot) is bracketed between two states. Per step, the
  contact-free length of the top debond (stations inside the debond whose contact pressure is
  below ``OPEN_P``: the face there carries no pressure, it need not have lifted) and the
  indentation ``w_top_mid − w_bottom_mid``.
- ``bending``: the same beam in four-point bending (loads at L/3 and 2L/3, the debond in the
  constant-moment zone, no load on the debonded face) to λ = 160, 1.5 × the clamped Euler load
  of the 40 mm face (λ_E ≈ 108, estimate below). The compressed face is pressed onto the core by
  its own curvature (pressure ≈ N κ / b > 0), so a pressed state is stable against lift-off and
  neither model should open the debond.

Clamped Euler estimate of the debonded face: P_E = 4 π² E b t³ / (12 a²) with a = 40 mm;
face force N ≈ M / d (sandwich theory, d = t + h_c), M = λ · 100 N·mm between the loads.

Run from the project root: ``python -m benchmarks.beam_vs_2d_liftoff [fig5|bending] [--elements
240] [--level coarse] [--out DIR]``. Writes ``benchmarks/results/comparisons/liftoff_<case>.md``
(a rerun replaces it).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.results import Solution
from sandwich.scene import Load, Scene
from sandwich.scene_file import load_scene

OUT = RESULTS / "comparisons"
OPEN_P = 1e-5  # MPa: a station with less contact pressure than this is contact-free
STEP = 0.1  # mm: largest displacement increment of the fig5 case


def fig5_scene() -> Scene:
    s = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    s = dataclasses.replace(s, analysis=dataclasses.replace(
        s.analysis, control="displacement", until_value=-5.0, initial_increment=STEP,
        max_increment=STEP, max_steps=400))
    return _every_step(s)


def bending_scene() -> Scene:
    s = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    loads = (Load("top", s.length / 3, 10.0, -1.0), Load("top", 2 * s.length / 3, 10.0, -1.0))
    an = dataclasses.replace(s.analysis, until_probe=None, until_value=None,
                             until_load_factor=160.0)
    s = dataclasses.replace(s, name="fig5-four-point-bending", loads=loads, analysis=an)
    return _every_step(s)


def _every_step(s: Scene) -> Scene:
    return dataclasses.replace(
        s, beam_model=dataclasses.replace(s.beam_model, profile_every=1),
        reference2d=dataclasses.replace(s.reference2d, profile_every=1))


def euler_load_factor(s: Scene) -> float:
    """λ at which M/d reaches the clamped Euler load of the debonded top face."""
    d = s.top.thickness + s.core.thickness
    a = s.debonds[0].end - s.debonds[0].start
    P = 4 * math.pi**2 * s.top.material.Ex * s.width * s.top.thickness**3 / 12 / a**2
    arm = s.loads[0].x  # moment per λ between the two loads (unit forces, simply supported)
    return P * d / arm


def openness(sol: Solution, s: Scene) -> list[tuple[float, float, float, float]]:
    """(λ, open length (mm), min pressure in the debond (MPa), indentation) per profiled step."""
    db = s.debonds[0]
    by_step = {h.step: h for h in sol.history}
    rows = []
    for p in sol.profiles:
        x = p.columns["x"]
        inside = (x > db.start + 1e-9) & (x < db.end - 1e-9)
        pc = np.asarray(p.columns["p_contact_top"])[inside]
        xs = x[inside]
        open_ = pc < OPEN_P
        # open length: stations' spacing weights (trapezoid of the open indicator)
        length = float(np.trapz(open_.astype(float), xs)) if xs.size > 1 else 0.0
        h = by_step[p.step]
        ind = h.probes.get("w_top_mid", math.nan) - h.probes.get("w_bottom_mid", math.nan)
        rows.append((h.load_factor, length, float(pc.min()) if pc.size else math.nan, ind))
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", choices=["fig5", "bending"], nargs="?", default="fig5")
    ap.add_argument("--elements", type=int, default=240)
    ap.add_argument("--level", default="coarse")
    add_out_argument(ap, OUT)
    args = ap.parse_args(argv)
    stamp = measured_on()
    import sandwich.beam
    import sandwich.plane2d

    s = fig5_scene() if args.case == "fig5" else bending_scene()
    runs = {
        "beam (paper)": lambda: sandwich.beam.run(s, elements=args.elements).solution,
        "beam (averaged)": lambda: sandwich.beam.run(
            s, elements=args.elements, model_options={"face_membrane": "averaged"}).solution,
        f"2d ({args.level})": lambda: sandwich.plane2d.solve(s, level=args.level, estimate=False),
    }
    md = [f"# Lift-off of the debonded top face: {s.name}", "",
          f"benchmarks/beam_vs_2d_liftoff.py {args.case}; beam {args.elements} graded elements, "
          f"2D level {args.level}. Contact-free: contact pressure < {OPEN_P:g} MPa at a profile "
          "station inside the debond.", "", stamp, ""]
    if args.case == "bending":
        md += [f"Clamped Euler load of the 40 mm face reached at λ_E ≈ "
               f"{euler_load_factor(s):.1f} (M/d = P_E).", ""]
    for label, fn in runs.items():
        t0 = time.perf_counter()
        sol = fn()
        rows = openness(sol, s)
        lam = {h.step: h.load_factor for h in sol.history}
        lps = ", ".join(f"{lp.kind} λ ∈ ({lam.get(lp.step - 1, math.nan):.1f}, "
                        f"{lp.load_factor:.1f}] (w_top_mid {lp.probes['w_top_mid']:.2f})"
                        for lp in sol.limit_points) or "none"
        md += [f"## {label}: {time.perf_counter() - t0:.1f} s, {sol.message}", "",
               f"limit points / bifurcations (between the previous state and this one): {lps}",
               "",
               "| λ | contact-free length (mm) | min pressure in debond (MPa) | "
               "w_top − w_bottom (mm) |",
               "|---:|---:|---:|---:|"]
        md += [f"| {lam:.1f} | {ln:.2f} | {pm:.3g} | {ind:.4f} |" for lam, ln, pm, ind in rows]
        md.append("")
        print(f"{label}: {lps}", flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"liftoff_{args.case}.md").write_text("\n".join(md))
    print(f"wrote {args.out / f'liftoff_{args.case}.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
