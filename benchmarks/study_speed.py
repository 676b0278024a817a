"""Study engine speed: the shipped knock-down study's beam cases on 1 and 2 local workers and on a
2-worker Dask LocalCluster given by address.

Run from the project root: ``python -m benchmarks.study_speed [--study FILE] [--limit N] [--out
DIR]``. Each
configuration solves every case from scratch (a fresh study folder; no reuse) with the 2D checks
off (beam cases only: the checks' error indicator and 2D runs are not timed here), then a rerun
into the same folder times the resume (every case reused). Writes
``benchmarks/results/studies/study_speed.{csv,md}`` (a rerun replaces them).

The machine is shared (2 cores, other agents' jobs running): every row records ``uptime``'s load
before and after.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import tempfile
import time
from pathlib import Path

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.studies.study import run_study
from sandwich.studies.study_file import load_study
from sandwich.studies.study_report import crossings

OUT = RESULTS / "studies"


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main(argv: list[str] | None = None) -> int:
    """Time the configurations and write the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", type=Path,
                    default=ROOT / "studies" / "shipped" / "fig5-knockdown.toml")
    ap.add_argument("--limit", type=int, default=None, help="only the first N cases")
    add_out_argument(ap, OUT)
    args = ap.parse_args(argv)
    stamp = measured_on()
    study = load_study(args.study)
    study = dataclasses.replace(study, check=0, check_all=False,
                                cases=study.cases[: args.limit] if args.limit else study.cases)
    n = len(study.cases)
    rows = []
    answers: list[list[dict]] = []

    def timed(label: str, **engine) -> None:
        with tempfile.TemporaryDirectory(prefix="study-speed-") as tmp:
            before = _load()
            t0 = time.perf_counter()
            res = run_study(study, Path(tmp), say=lambda m: None, quiet=True, plots=False,
                            **engine)
            wall = time.perf_counter() - t0
            after = _load()
            t1 = time.perf_counter()
            again = run_study(study, Path(tmp), say=lambda m: None, quiet=True, plots=False,
                              **engine)
            resume = time.perf_counter() - t1
        solve = [float(r["solve_seconds"]) for r in res.rows if r.get("solve_seconds")]
        case_wall = [float(r["wall_seconds"]) for r in res.rows if r.get("wall_seconds")]
        row = {"configuration": label, "cases": n, "solved": res.cases.solved,
               "failed": res.cases.failed, "wall_s": round(wall, 1),
               "cases_per_min": round(60 * n / wall, 1),
               "mean_case_s": round(sum(case_wall) / max(len(case_wall), 1), 2),
               "mean_solve_s": round(sum(solve) / max(len(solve), 1), 2),
               "sum_case_s": round(sum(case_wall), 1),
               "rerun_s": round(resume, 1), "rerun_reused": again.cases.reused,
               "load_before": before, "load_after": after}
        rows.append(row)
        answers.append(crossings(study, res.rows))
        print(row, flush=True)

    timed("1 local worker (engine's LocalCluster)", workers=1)
    timed("2 local workers (engine's LocalCluster)", workers=2)
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        timed("2-worker LocalCluster by --scheduler address", scheduler=cluster.scheduler_address)
    args.out.mkdir(parents=True, exist_ok=True)
    with (args.out / "study_speed.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    md = [f"# Study engine speed: {study.name} ({n} beam cases, 2D checks off)", "",
          f"Study file `{args.study.relative_to(ROOT)}`; beam "
          f"{study.cases[0].scene.beam_model.elements} elements, core level "
          f"{study.cases[0].scene.beam_model.core}. Machine: 2 cores shared with other agents' "
          f"jobs (`uptime` load averages 1/5/15 min before and after each run in the table). "
          f"Wall time includes starting the engine's LocalCluster (not for the cluster given "
          f"by address, started before the clock). `rerun`: the same command again into the "
          f"same folder (every case reused).", "", stamp, "",
          "| configuration | cases | wall (s) | cases/min | mean case (s) | mean solve (s) | "
          "Σ case (s) | rerun (s) | reused | load before | load after |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append(f"| {r['configuration']} | {r['cases']} | {r['wall_s']} | "
                  f"{r['cases_per_min']} | {r['mean_case_s']} | {r['mean_solve_s']} | "
                  f"{r['sum_case_s']} | {r['rerun_s']} | {r['rerun_reused']} | "
                  f"{r['load_before']} | {r['load_after']} |")
    if answers and answers[0]:
        others = [a.name for a in study.axes[1:]]
        md += ["", f"The study's threshold answer from each timed run ({study.axes[0].name} where "
               f"the knock-down falls to {study.report.threshold:g}, per "
               f"{', '.join(others)}):", ""]
        for label, ans in zip((r["configuration"] for r in rows), answers, strict=True):
            md.append(f"- {label}: " + ", ".join(
                f"{'/'.join(f'{c[o]:g}' for o in others)}: "
                + ("—" if c["at"] is None else f"{c['at']:.3g}") for c in ans))
    (args.out / "study_speed.md").write_text("\n".join(md) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
