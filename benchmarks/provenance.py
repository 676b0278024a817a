"""Where a benchmark writes and what its tables say about the run: machine and date.

Every script writes its tables into one canonical folder under ``benchmarks/results/`` (a rerun
replaces them) or into ``--out DIR``; every table carries a line made by :func:`measured_on`.
The machine is named by ``$SANDWICH_BENCH_MACHINE`` when set (e.g. ``machine B (2-core AVX-512
Xeon)``), else by its CPU model and count as the kernel reports them.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]  # the project: scenes/, benchmarks/results/
RESULTS = ROOT / "benchmarks" / "results"


def machine(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """This machine's name: ``$SANDWICH_BENCH_MACHINE``, else its CPU model and CPU count."""
    name = os.environ.get("SANDWICH_BENCH_MACHINE", "").strip()
    if name:
        return name
    model = ""
    if cpuinfo.is_file():
        for line in cpuinfo.read_text(errors="replace").splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{model or platform.machine() or 'unknown CPU'}, {os.cpu_count()} CPUs"


def measured_on(when: float | None = None, verb: str = "Measured") -> str:
    """The sentence ``Measured on <machine>, <YYYY-MM-DD HH:MM> UTC.`` (``when``: epoch s; now).

    ``verb`` names what was done there and then (``Computed`` for a table derived from another).
    """
    stamp = time.strftime("%Y-%m-%d %H:%M", time.gmtime(when))
    return f"{verb} on {machine()}, {stamp} UTC."


def console_script(name: str) -> Path:
    """The ``name`` command installed beside the interpreter that runs this benchmark."""
    return Path(sys.executable).with_name(name)


def add_out_argument(parser: argparse.ArgumentParser, default: Path) -> None:
    """``--out DIR``: the folder the tables go to, ``default`` (the canonical one) unless given."""
    shown = default.relative_to(ROOT) if default.is_relative_to(ROOT) else default
    parser.add_argument("--out", type=Path, default=default, metavar="DIR",
                        help=f"folder to write the tables in (default: {shown}; a rerun "
                             "replaces the tables there)")


def machine_and_date(sentence: str) -> str:
    """``<machine>, <date> UTC`` out of a :func:`measured_on` sentence (a table's column)."""
    return sentence.removeprefix("Measured on ").removesuffix(".")


def write_rows(path: Path, fields: list[str], rows: list[dict]) -> None:
    """Write ``rows`` as the csv at ``path`` (its folder made), header ``fields``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fields)
        w.writeheader()
        w.writerows(rows)


def append_row(path: Path, fields: list[str], row: dict) -> None:
    """Append ``row`` to the csv at ``path``, rewriting its header to ``fields`` if it differs."""
    if path.exists():
        with open(path, newline="") as f:
            header = next(csv.reader(f), [])
        if header != fields:
            with open(path, newline="") as f:
                rows = list(csv.DictReader(f))
            with open(path, "w", newline="") as f:
                w = csv.DictWriter(f, fields, restval="", extrasaction="ignore")
                w.writeheader()
                w.writerows(rows)
    new = not path.exists()
    with open(path, "a", newline="") as f:
        w = csv.DictWriter(f, fields)
        if new:
            w.writeheader()
        w.writerow(row)


def measured_line(rows: list[dict], column: str = "measured") -> str:
    """A table's provenance from its rows' ``column``: the machines and dates, in row order."""
    seen = list(dict.fromkeys(r[column] for r in rows if r.get(column)))
    older = sum(1 for r in rows if not r.get(column))
    said = f"Measured on {'; '.join(seen)}." if seen else ""
    if older:
        said += (f" {older} row(s) measured before the rows said where and when (their date: "
                 "the csv's git history).")
    return said.strip()
