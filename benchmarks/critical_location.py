"""Bifurcation loads located within their step, against fine-step paths (sandwich.solver.critical).

``python -m benchmarks.critical_location [--out DIR]`` (from the project root) writes
``benchmarks/results/beam/critical_location.md`` and ``.csv`` (a rerun replaces them). The
knock-down study's model (fig. 5 scene, core level 1, 240 graded elements, the scene's other
defaults) with a top debond centred under the load (x = 150 mm), lengths ``--lengths``: each
path followed three ways, and its first bifurcation read off three ways.

- paths: as shipped (arc-length, settling allowance 2); the same with the settling allowance
  off (shorter steps); displacement control of ``w_top_mid`` in steps of at most
  ``--fine`` mm to −12 mm (the reference);
- readings: *at state* — the first state with the new negative-pivot count (what every model
  reported before 2026-12-05) —; *located* — where the tangent's crossed eigenvalue,
  interpolated linearly along the step between the two states' factorisations, is zero (the
  default now, no corrector); *narrowed* — ``[analysis] locate_critical_points = true``: shorter
  steps from the state before aimed at that point, regula falsi on the eigenvalue (a run of
  its own: the path's states are the same, its time is not).

Errors are against the fine path's narrowed value (its bracket is listed: equilibria either
side of the crossing, which bound the reference's own error).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

from benchmarks.location_table import reading_row, write_tables
from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.scene_file import load_scene

SCENE = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"
OUT = RESULTS / "beam"


def case(length: float, how: str, fine: float, narrowed: bool):
    """The knock-down study's scene for a centred debond of ``length`` mm, followed ``how``."""
    scene = load_scene(SCENE)
    debonds = tuple(dataclasses.replace(d, start=150.0 - length / 2, end=150.0 + length / 2)
                    for d in scene.debonds)
    bm = dataclasses.replace(scene.beam_model, core=1, elements=240)
    a = dataclasses.replace(scene.analysis, locate_critical_points=narrowed)
    if how == "allowance off":
        bm = dataclasses.replace(bm, settling_allowance=int(a.max_iterations))
    elif how == "fine":
        a = dataclasses.replace(a, control="displacement", until_value=-12.0, max_increment=fine,
                                initial_increment=fine, max_steps=2000)
    return dataclasses.replace(scene, debonds=debonds, beam_model=bm, analysis=a)


def first_bifurcation(scene):
    """The path's first bifurcation: a dict of what the table lists (None: no bifurcation)."""
    from sandwich.beam.solve import run

    t = time.perf_counter()
    r = run(scene)
    seconds = time.perf_counter() - t
    sol = r.solution
    bif = [lp for lp in sol.limit_points if lp.kind == "bifurcation"]
    out = {"steps": len(sol.history) - 1, "seconds": seconds, "load": None}
    if bif:
        lp = bif[0]
        state = next(s for s in r.states if s.step == lp.step)
        before = next(s for s in r.states if s.step == lp.step - 1)
        out.update(load=lp.load_factor, bracket=lp.between, step_bracket=(
            before.load_factor, state.load_factor), at_state=state.load_factor)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--lengths", type=float, nargs="+",
                   default=[20, 35, 40, 50, 55, 60, 70, 75])
    p.add_argument("--fine", type=float, default=0.05, help="fine path's step cap (mm)")
    add_out_argument(p, OUT)
    args = p.parse_args(argv)
    load0, stamp = os.getloadavg(), measured_on()
    rows = []
    for length in args.lengths:
        ref = first_bifurcation(case(length, "fine", args.fine, True))
        for how in ("as shipped", "allowance off", "fine"):
            plain = first_bifurcation(case(length, how, args.fine, False))
            narrow = ref if how == "fine" else first_bifurcation(case(length, how, args.fine,
                                                                      True))
            rows.append(reading_row({"length_mm": length}, how, plain, narrow, ref))
    write_tables(rows, args.out, "critical_location",
                 "First bifurcation loads located within their step "
                 "(benchmarks/critical_location.py)", __doc__.split("\n\n", 1)[1].strip(),
                 ("debond (mm)", "---:", lambda r: f"{r['length_mm']:g}"), args.fine, load0,
                 stamp=stamp)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
