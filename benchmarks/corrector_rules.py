"""A/B of the corrector's rising-residual test on every shipped scene (beam model).

Run from the project root: ``python -m benchmarks.corrector_rules [--scenes NAME ...] [--levels
auto 1] [--out DIR]``. Writes ``benchmarks/results/beam/corrector_rules.{md,csv}`` (a rerun
replaces them).

Each scene is solved in this process (kernels warm) with the path follower as shipped
(``sandwich.solver.path.follower.DIVERGENCE_RISES = 2``: a step's corrector whose residual rose
twice in a row above its first one is abandoned and the step cut; its retries run without the
test, and the rest of the path too once a corrector converged after rising so) and with the test off
(``DIVERGENCE_RISES = 0``, the path follower before it), one after the other. Every corrector
run of the path follower is counted through a wrapper of ``newton_correct``: attempts, failed
attempts and the iterations they spent. Recorded: solve wall (``Solution.wall_seconds``),
converged states, all corrector iterations, failed attempts / their iterations, the end load.
"""

from __future__ import annotations

import argparse
import csv
import os

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.beam import run
from sandwich.scene_file import load_scene
from sandwich.solver.path import attempts as attempts_module
from sandwich.solver.path import follower as follower_module

OUT = RESULTS / "beam"


def solve(scene: object, level: str, rises: int) -> tuple[object, dict[str, int]]:
    """One run with ``divergence_rises = rises``; the corrector's counts."""
    options = None if level == "auto" else {"core_level": int(level)}
    original = attempts_module.newton_correct
    counts = {"attempts": 0, "iterations": 0, "failed": 0, "failed_iterations": 0}

    def counted(system, u, lam, constraint, settings, *args, **kwargs):
        res = original(system, u, lam, constraint, settings, *args, **kwargs)
        counts["attempts"] += 1
        counts["iterations"] += res.iterations
        if not res.converged:
            counts["failed"] += 1
            counts["failed_iterations"] += res.iterations
        return res

    shipped = follower_module.DIVERGENCE_RISES
    attempts_module.newton_correct, follower_module.DIVERGENCE_RISES = counted, rises
    try:
        return run(scene, model_options=options).solution, counts
    finally:
        attempts_module.newton_correct, follower_module.DIVERGENCE_RISES = original, shipped


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*",
                        default=sorted(p.stem for p in (ROOT / "scenes").glob("*.toml")))
    parser.add_argument("--levels", nargs="*", default=["auto", "1"])
    add_out_argument(parser, OUT)
    args = parser.parse_args()
    stamp = measured_on()
    rows = []
    loads = [os.getloadavg()[0]]
    for name in args.scenes:
        scene = load_scene(ROOT / "scenes" / f"{name}.toml")
        for level in args.levels:
            for rises in (0, 2):
                sol, c = solve(scene, level, rises)
                rows.append({"scene": name, "core": level, "divergence_rises": rises,
                             "solve_s": round(sol.wall_seconds, 3), "states": len(sol.history),
                             "end_load": float(sol.final_load_factor),
                             "converged": bool(sol.converged), **c})
                loads.append(os.getloadavg()[0])
                print(" ".join(f"{k}={v}" for k, v in rows[-1].items()), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "corrector_rules.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [
        "# The corrector's rising-residual test, on and off (`benchmarks/corrector_rules.py`)",
        "",
        f"{stamp} {os.cpu_count()} cores, 1-minute load {min(loads):.2f}-{max(loads):.2f} "
        "over the runs (this benchmark's own process included). Beam model, each scene in one "
        "process, off then on. `off`: "
        "`DIVERGENCE_RISES = 0` (the path follower before the test); `on`: 2 (as shipped). "
        "Corrector iterations: every corrector the path follower ran (steps, retries, target "
        "hits; the end-state checks of `auto` are not counted); failed: those that did not "
        "converge and their iterations.",
        "",
        "| scene | core | solve off / on (s) | on/off | states off / on | iterations off / on "
        "| failed attempts (iterations) off / on | end load off / on |",
        "|---|---|---:|---:|---|---|---|---|",
    ]
    tot = {0: 0.0, 2: 0.0}
    for i in range(0, len(rows), 2):
        a, b = rows[i], rows[i + 1]
        tot[0] += a["solve_s"]
        tot[2] += b["solve_s"]
        end = (f"{a['end_load']:.10g} (same to 1e-6)"
               if abs(a["end_load"] - b["end_load"]) <= 1e-6 * abs(a["end_load"])
               else f"**{a['end_load']:.10g} / {b['end_load']:.10g}**")
        lines.append(
            f"| {a['scene']} | {a['core']} | {a['solve_s']:.2f} / {b['solve_s']:.2f} | "
            f"{b['solve_s'] / a['solve_s']:.2f} | {a['states']} / {b['states']} | "
            f"{a['iterations']} / {b['iterations']} | {a['failed']} ({a['failed_iterations']}) / "
            f"{b['failed']} ({b['failed_iterations']}) | "
            f"{end} |")
    lines += ["", f"Total solve time: off {tot[0]:.1f} s, on {tot[2]:.1f} s "
              f"({tot[2] / tot[0]:.2f}). An end load in bold: the two runs ended on different "
              "equilibria at the scene's until target (the branch-sensitive scenes, "
              "`benchmarks/results/comparisons/gallery_agreement.md`)."]
    (args.out / "corrector_rules.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
