"""A whole study: its cases, the 2D spot checks, the table, the plots and the summary.

``sandwich study STUDY.toml`` calls :func:`run_study`; the pieces are
:mod:`sandwich.studies.study_file`
(format and checks), :mod:`sandwich.studies.study_run` (the Dask engine, reuse, progress),
:mod:`sandwich.studies.study_check` (which cases the 2D model checks) and
:mod:`sandwich.studies.study_report`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sandwich.models import PROJECT_ROOT
from sandwich.studies.study_check import check_errors, select_checks
from sandwich.studies.study_file import Study
from sandwich.studies.study_report import plot, rows, summary, write_table
from sandwich.studies.study_run import Progress, StudyRun, run_cases


@dataclass
class StudyResult:
    """What a study run wrote and how it went."""

    table: Path
    summary: Path
    plots: list[Path]
    cases: StudyRun
    checks: StudyRun | None = None
    checked: list[int] = field(default_factory=list)
    rows: list[dict[str, Any]] = field(default_factory=list)

    @property
    def interrupted(self) -> bool:
        """Whether Ctrl-C stopped it (finished cases are kept)."""
        return self.cases.interrupted or bool(self.checks and self.checks.interrupted)


def _run_lines(label: str, run: StudyRun, total: int) -> list[str]:
    lines = [f"{label}: {total} case(s): {run.reused} reused, {run.solved} solved now, "
             f"{run.failed} failed now" + (f" on {run.engine}" if run.engine else "")
             + f", {run.seconds:.1f} s" + (" (interrupted)" if run.interrupted else "") + "."]
    for why, n in run.stale.items():
        lines.append(f"{label}: not reusing {n} case(s): {why}")
    return lines


def run_study(study: Study, out: Path, *, workers: int = 2, scheduler: str | None = None,
              client: Any = None, say: Callable[[str], None] = print, quiet: bool = False,
              stream: Any = None, root: Path = PROJECT_ROOT, plots: bool = True) -> StudyResult:
    """Run (or resume) ``study`` into ``out``; see the module docstring.

    ``workers``/``scheduler``/``client``: the engine (:func:`sandwich.studies.study_run.run_cases`);
    ``say`` gets the messages, ``stream`` the progress lines (``quiet``: none).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    total = len(study.cases)
    prog: dict[str, Progress] = {}

    def progress(done: int, running: int, failed: int) -> None:
        if "p" not in prog:  # the reused count is known at the first call
            prog["p"] = Progress(total, done, stream=stream, quiet=quiet, label=study.name)
        prog["p"](done, running, failed)

    cases = run_cases(study, out, workers=workers, scheduler=scheduler, client=client,
                      indicator=study.check > 0, progress=progress, say=say, root=root)
    lines = _run_lines("beam cases" if study.model == "beam" else "cases", cases, total)
    for line in lines:
        say(line)
    checks_run = None
    chosen: list[int] = []
    check_rows: dict[int, dict[str, Any]] = {}
    if study.check and not cases.interrupted:
        chosen = select_checks(study, cases.records, study.check)
        picked = [c for c in study.cases if c.index in chosen]
        say(f"2D spot checks: {len(picked)} case(s): {', '.join(str(i) for i in chosen)}")
        p2 = {}

        def progress2(done: int, running: int, failed: int) -> None:
            if "p" not in p2:
                p2["p"] = Progress(len(picked), done, stream=stream, quiet=quiet,
                                   label=f"{study.name} 2D")
            p2["p"](done, running, failed)

        checks_run = run_cases(study, out, picked, model="2d", workers=workers,
                               scheduler=scheduler, client=client, progress=progress2, say=say,
                               root=root)
        for line in _run_lines("2D checks", checks_run, len(picked)):
            say(line)
            lines.append(line)
        for i in chosen:
            if i in checks_run.records:
                check_rows[i] = check_errors(cases.records[i], checks_run.records[i])
    table = rows(study, cases.records, check_rows)
    csv_path = out / f"{study.name}.csv"
    write_table(table, csv_path)
    written = plot(study, table, out) if plots and table else []
    checked = [r for r in table if r.get("checked_2d")]
    md = summary(study, table, lines, checked, written)
    md_path = out / "summary.md"
    md_path.write_text(md + "\n", encoding="utf-8")
    return StudyResult(csv_path, md_path, written, cases, checks_run, chosen, table)
