"""Load maxima located within their step, against fine-step paths (sandwich.solver.extrema).

``python -m benchmarks.maximum_location [--out DIR]`` (from the project root) writes
``benchmarks/results/beam/maximum_location.md`` and ``.csv`` (a rerun replaces them). Beam
paths with a load maximum before their target, each followed twice, and its first maximum read
off three ways:

- paths: as the scene has it (arc-length, the beam's settling allowance); displacement control
  of the until probe in steps of at most ``--fine`` mm to the same target (the reference);
- readings: *at state* — the converged state with the extreme load (what every model reported
  before 2026-12-05) —; *located* — the stationary point of λ's cubic Hermite interpolant in
  the probe over the step whose slopes dw/dλ turn over (no corrector; the default now);
  *narrowed* — ``[analysis] locate_critical_points = true``: shorter steps from the state
  before, aimed at that point (a run of its own: the path's states are the same, its time is
  not).

Cases: fig. 4 (bonded, the core crushing under the pad) and fig. 7 c1 (cantilever, bottom
debond) at core level 2; the knock-down study's model (fig. 5 scene, core level 1, 240 graded
elements) bonded and with a 65-mm top debond centred at x = 90 mm — the study's length-0
reference, and a case whose first critical point, read as a bifurcation on a falling step
before, is a maximum inside that step — a local snap of the debonded face at λ ≈ 90 (4 % of
the bonded panel's), where the fine displacement-controlled path stalls (listed below the
table) and the two paths sample a non-smooth event differently: no reading is better than
the path there. Errors are against the fine path's narrowed value.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

from benchmarks.location_table import reading_row, write_tables
from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.scene_file import load_scene

OUT = RESULTS / "beam"
FIG5 = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _knockdown(length: float, centre: float):
    scene = load_scene(FIG5)
    debonds = tuple(dataclasses.replace(d, start=centre - length / 2, end=centre + length / 2)
                    for d in scene.debonds)
    bm = dataclasses.replace(scene.beam_model, core=1, elements=240)
    return dataclasses.replace(scene, debonds=debonds, beam_model=bm)


def _at_level(name: str, level: int):
    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    return dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model,
                                                                     core=level))


CASES = {
    "fig. 4, level 2": lambda: _at_level("paper-fig4-bonded-3pb", 2),
    "fig. 7 c1, level 2": lambda: _at_level("paper-fig7-cantilever-c1", 2),
    "knock-down, bonded": lambda: _knockdown(0.0, 150.0),
    "knock-down, 65 mm at x = 90": lambda: _knockdown(65.0, 90.0),
}


def followed(scene, how: str, fine: float, narrowed: bool):
    """``scene`` followed ``how`` (``"as shipped"`` or ``"fine"``), narrowing or not."""
    a = dataclasses.replace(scene.analysis, locate_critical_points=narrowed)
    if how == "fine":
        a = dataclasses.replace(a, control="displacement", max_increment=fine,
                                initial_increment=fine, max_steps=5000)
    return dataclasses.replace(scene, analysis=a)


def first_maximum(scene):
    """The path's first load maximum: a dict of what the table lists (load None: none)."""
    from sandwich.beam.solve import run

    t = time.perf_counter()
    r = run(scene)
    seconds = time.perf_counter() - t
    sol = r.solution
    out = {"steps": len(sol.history) - 1, "seconds": seconds, "load": None,
           "message": sol.message, "reached": sol.converged}
    tops = [lp for lp in sol.limit_points if lp.kind == "max"]
    if tops:
        lp = tops[0]
        lam = [s.load_factor for s in r.states]
        k = lp.step if lp.located_at is None else max(
            (lp.step - 1, lp.step), key=lambda i: lam[i])  # the extreme state of the two
        out.update(load=lp.load_factor, bracket=lp.between, at_state=lam[k],
                   fraction=lp.located_at, step_bracket=(lam[lp.step - 1], lam[lp.step])
                   if lp.located_at is not None else lp.between)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    p.add_argument("--fine", type=float, default=0.05, help="fine path's step cap (mm)")
    add_out_argument(p, OUT)
    args = p.parse_args(argv)
    load0, stamp = os.getloadavg(), measured_on()
    rows = []
    for name in args.cases:
        scene = CASES[name]()
        ref = first_maximum(followed(scene, "fine", args.fine, True))
        for how in ("as shipped", "fine"):
            plain = first_maximum(followed(scene, how, args.fine, False))
            narrow = ref if how == "fine" else first_maximum(followed(scene, how, args.fine,
                                                                      True))
            rows.append({**reading_row({"case": name}, how, plain, narrow, ref),
                         "stopped": "" if plain["reached"] else " ".join(plain["message"].split())})
    stopped = [r for r in rows if r["stopped"]]
    after = (["", "Paths that stopped short of their target (their maximum is the last one "
              "they sampled):", ""] + [f"- {r['case']}, {r['path']}: {r['stopped']}"
                                       for r in stopped]) if stopped else []
    write_tables(rows, args.out, "maximum_location",
                 "First load maxima located within their step (benchmarks/maximum_location.py)",
                 __doc__.split("\n\n", 1)[1].strip(), ("case", "---", lambda r: r["case"]),
                 args.fine, load0, error_digits=3, after=after, stamp=stamp)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
