"""Run a study's cases: reuse the finished ones, send the rest to Dask workers, show progress.

One engine, :mod:`distributed`: without a scheduler address a ``LocalCluster`` of ``workers``
single-threaded worker processes is started on this machine (and closed at the end); with one,
the cases go to that cluster (its workers need this project installed). Every case is solved by
:func:`sandwich.studies.study_case.solve_case` on a worker, which writes the case's result set and
record
into ``<out>/cases/<key>/`` (the key: a hash of the case's scene content, model and options); a
finished case is never sent again while its identity holds. A case that fails, or whose worker
dies more often than the scheduler allows, is a failed record with its reason; the other cases go
on. Ctrl-C cancels what is left: every case finished so far stays on disk and the next run says
how many it reuses.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sandwich.models import PROJECT_ROOT
from sandwich.scene import Problem
from sandwich.studies.study_case import reusable, solve_case
from sandwich.studies.study_file import Case, Study, StudyError

SCHEDULER_TIMEOUT = "10s"  # how long --scheduler's address may take to answer
LINE_SECONDS = 30.0  # a non-terminal stream gets a progress line at least this often


@dataclass
class StudyRun:
    """The records of every case (by index) and how the run went."""

    records: dict[int, dict[str, Any]]
    reused: int = 0
    solved: int = 0
    failed: int = 0
    stale: dict[str, int] = field(default_factory=dict)  # reason -> cases not reused for it
    seconds: float = 0.0
    interrupted: bool = False
    engine: str = ""


def case_folder(out: Path, case: Case, model: str = "beam") -> Path:
    """Where a case's result set and record live."""
    return Path(out) / ("cases" if model != "2d-check" else "checks") / case.key


class Progress:
    """``done / running / failed`` and an ETA, on one redrawn line (terminal) or as lines.

    When ``stream`` is not a terminal: one line per tenth of the cases or per
    :data:`LINE_SECONDS`, whichever comes first, as the path progress of a single solve does.
    """

    def __init__(self, total: int, reused: int, stream: Any = None, quiet: bool = False,
                 label: str = "study"):
        self.total, self.reused = total, reused
        self.stream = sys.stderr if stream is None else stream
        self.quiet = quiet
        self.label = label
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.t0 = time.perf_counter()
        self._last = (-1, self.t0)

    def line(self, done: int, running: int, failed: int) -> str:
        """The progress text (``done`` counts reused and failed cases too)."""
        new = done - self.reused
        left = self.total - done
        elapsed = time.perf_counter() - self.t0
        if new > 0 and left > 0:
            eta = f", ETA {_duration(elapsed / new * left)}"
        elif left == 0:
            eta = f", took {_duration(elapsed)}"
        else:
            eta = ""
        return (f"{self.label}: {done}/{self.total} done ({self.reused} reused), {running} "
                f"running, {failed} failed{eta}")

    def __call__(self, done: int, running: int, failed: int) -> None:
        """Show the state if it is time to."""
        if self.quiet:
            return
        text = self.line(done, running, failed)
        if self.tty:
            print("\r" + text + "\x1b[K", end="" if done < self.total else "\n",
                  file=self.stream, flush=True)
            return
        tenth = (10 * done) // max(self.total, 1)
        now = time.perf_counter()
        if tenth != self._last[0] or now - self._last[1] >= LINE_SECONDS or done == self.total:
            print(text, file=self.stream, flush=True)
            self._last = (tenth, now)


def _duration(s: float) -> str:
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.1f} min"


def open_client(workers: int, scheduler: str | None):
    """A Dask client: to ``scheduler``, or to a new LocalCluster of ``workers`` processes.

    Returns ``(client, cluster_or_None, description)``.
    """
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            raise StudyError([Problem(
                "command line", "--scheduler",
                f"no Dask scheduler answered at {scheduler!r} within {SCHEDULER_TIMEOUT} "
                f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}); start one there "
                "(`dask scheduler`, then `dask worker <address>` on each machine) or leave "
                "--scheduler out to run on this machine's cores")]) from None
        return client, None, f"Dask cluster {scheduler} ({_threads(client)} worker threads)"
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=40)
    client = Client(cluster)
    return client, cluster, f"{workers} local worker process{'es' if workers > 1 else ''}"


def _threads(client) -> int:
    try:
        return max(sum(client.nthreads().values()), 1)
    except Exception:  # noqa: BLE001 - only for the progress line
        return 1


def run_cases(study: Study, out: Path, cases: list[Case] | None = None, *, model: str | None = None,
              workers: int = 2, scheduler: str | None = None, client: Any = None,
              indicator: bool = False, progress: Callable[[int, int, int], None] | None = None,
              say: Callable[[str], None] = print, root: Path = PROJECT_ROOT,
              on_record: Callable[[dict[str, Any]], None] | None = None) -> StudyRun:
    """Solve (or reuse) ``cases`` of ``study`` (default all) with ``model`` (default the study's).

    Parameters
    ----------
    study, out
        The study and its output folder (cases go to ``out/cases/<key>/``, 2D checks to
        ``out/checks/<key>/``).
    cases, model
        What to run; ``model="2d"`` runs 2D spot checks (folders under ``checks/``).
    workers, scheduler, client
        A LocalCluster of ``workers`` processes, or the cluster at ``scheduler``, or an open
        ``client`` (kept open).
    indicator
        Also compute the beam's error indicator of every case (asked by ``check``).
    progress
        ``progress(done, running, failed)`` after every finished case.
    on_record
        Called with every finished case's record as it arrives.
    """
    model = model or study.model
    cases = list(study.cases if cases is None else cases)
    kind = "2d-check" if model == "2d" and study.model == "beam" else model
    t0 = time.perf_counter()
    run = StudyRun(records={})
    todo: list[tuple[Case, Path]] = []
    for case in cases:
        folder = case_folder(out, case, kind)
        rec, why = reusable(case.scene, model, folder, root, need_indicator=indicator)
        if rec is not None:
            run.records[case.index] = rec
            run.reused += 1
        else:
            todo.append((case, folder))
            if why:
                run.stale[why] = run.stale.get(why, 0) + 1
    failed = sum(r.get("status") == "failed" for r in run.records.values())
    show = progress or (lambda d, r, f: None)
    done = len(run.records)
    if not todo:
        show(done, 0, failed)
        run.seconds = time.perf_counter() - t0
        return run
    own = client is None
    cluster = None
    if own:
        client, cluster, run.engine = open_client(workers, scheduler)
    else:
        run.engine = f"Dask client ({_threads(client)} worker threads)"
    from distributed import as_completed

    futures = {}
    try:
        nthreads = _threads(client)
        for case, folder in todo:
            task = {"index": case.index, "key": case.key, "values": case.values,
                    "scene": case.scene, "model": model, "folder": str(folder.resolve()),
                    "indicator": indicator, "root": str(root), "timeout": study.timeout,
                    "max_cells": study.max_cells, "fields": study.fields}
            fut = client.submit(solve_case, task, key=f"{study.name}-{kind}-{case.key}",
                                pure=False, retries=0)
            futures[fut] = case
        show(done, min(len(futures), nthreads), failed)
        for fut in as_completed(futures):
            case = futures[fut]
            try:
                rec = fut.result()
            except Exception as exc:  # noqa: BLE001 - a killed worker, a lost node: recorded
                rec = {"index": case.index, "key": case.key, "values": case.values,
                       "model": model, "status": "failed",
                       "reason": f"the worker running it was lost ({type(exc).__name__}: "
                                 f"{exc})"}
            run.records[case.index] = rec
            done += 1
            if rec.get("status") == "failed":
                failed += 1
                run.failed += 1
            else:
                run.solved += 1
            if on_record is not None:
                on_record(rec)
            show(done, min(len(cases) - done, nthreads), failed)
    except KeyboardInterrupt:
        run.interrupted = True
        for fut in futures:
            fut.cancel()
        say(f"interrupted: {done - run.reused - run.failed} case(s) finished in this run are "
            f"stored under {out}/; run the study again to resume")
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    run.seconds = time.perf_counter() - t0
    return run
