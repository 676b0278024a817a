"""The ``study`` command: a design study's cases in parallel, its 2D checks, table and plots."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from sandwich.cli.common import EXIT_OK, EXIT_STOPPED, RESULTS, UsageError, guard_memory, say
from sandwich.results import check_output_folder

__all__ = ["STUDY_2D_SAMPLE", "WORKERS_MAX", "cmd_study"]

WORKERS_MAX = 512
STUDY_2D_SAMPLE = 400  # at most this many cases' 2D meshes are laid out by the memory guard


def cmd_study(args: argparse.Namespace) -> int:
    """Run (or resume) a design study: every case, the 2D spot checks, table, plots."""
    from sandwich.studies.study import run_study
    from sandwich.studies.study_file import load_study

    study = load_study(args.study)
    if args.workers is not None and not 1 <= args.workers <= WORKERS_MAX:
        raise UsageError(f"option --workers: must be between 1 and {WORKERS_MAX}, "
                         f"got {args.workers}")
    if args.scheduler is None:  # a cluster's memory is not this machine's to judge
        _guard_study(study, args.workers or 2, args)
    out = Path(args.out) if args.out else RESULTS / "studies" / study.name
    check_output_folder(out)
    say(args, f"{study.name}: {len(study.cases)} case(s), model {study.model}"
         + (f", {study.check} 2D spot check(s)" if study.check else "") + f"; results in {out}/")
    result = run_study(study, out, workers=args.workers or 2, scheduler=args.scheduler,
                       say=lambda m: say(args, m), quiet=args.quiet)
    say(args, f"table: {result.table}; summary: {result.summary}"
         + "".join(f"; plot: {p}" for p in result.plots))
    if result.interrupted:
        print("interrupted: the finished cases are kept; run the same command to resume",
              file=sys.stderr)
        return EXIT_STOPPED
    failed = sum(r.get("status") == "failed" for r in result.rows)
    if failed:
        print(f"{failed} case(s) failed (reasons in {result.table})", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK


def _guard_study(study, workers: int, args: argparse.Namespace) -> None:
    """The memory guard on a study's largest case, ``workers`` of them at once (and its checks)."""
    from sandwich.models import memory

    whats = (study.model,) + (("2d",) if study.check and study.model != "2d" else ())
    for what in whats:
        # every case's beam estimate is arithmetic; a 2D one lays the mesh out (~5 ms): at most
        # STUDY_2D_SAMPLE cases evenly spread are laid out
        cases = study.cases if what == "beam" else \
            study.cases[::max(1, len(study.cases) // STUDY_2D_SAMPLE)]
        try:
            if what == "2d" and study.max_cells is not None:  # larger meshes are not run
                cases = [c for c in cases if memory.mesh_size(c.scene)[0] <= study.max_cells]
            sizes = [(memory.estimate(c.scene, what).peak_bytes, c) for c in cases]
        except (ValueError, KeyError):  # a layout the mesher refuses says why when it runs
            continue
        if not sizes:
            continue
        _, worst = max(sizes, key=lambda t: t[0])
        copies = min(workers, len(study.cases) if what == study.model else study.check)
        guard_memory([worst.scene], (what,), args, copies=copies, where=str(study.source),
               label=f"case {worst.index}" + (" (its 2D check)" if what != study.model else ""))
