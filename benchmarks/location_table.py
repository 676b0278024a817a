"""The table both critical-point benchmarks write: a point read at the state, located, narrowed.

Used by ``benchmarks.critical_location`` (bifurcations) and ``benchmarks.maximum_location`` (load
maxima): each
row is one path of one case, its point read three ways against the fine path's narrowed value.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Callable
from pathlib import Path


def reading_row(case: dict[str, object], how: str, plain: dict, narrow: dict,
                ref: dict) -> dict[str, object]:
    """One row: the ``case`` columns, the path ``how``, its three readings and their errors.

    ``plain``, ``narrow`` and ``ref`` are a benchmark's readings of the path as followed, of the
    same path narrowed, and of the fine path narrowed (keys ``steps``, ``seconds``, ``load``,
    and where a point was found ``at_state``, ``step_bracket``, ``bracket``).
    """
    row = {**case, "path": how, "steps": plain["steps"],
           "seconds": round(plain["seconds"], 3),
           "seconds_narrowed": round(narrow["seconds"], 3),
           "step_low": plain.get("step_bracket", (None, None))[0],
           "step_high": plain.get("step_bracket", (None, None))[1],
           "at_state": plain.get("at_state"), "located": plain["load"],
           "narrowed": narrow["load"],
           "narrowed_low": narrow.get("bracket", (None, None))[0],
           "narrowed_high": narrow.get("bracket", (None, None))[1],
           "reference": ref["load"]}
    for k in ("at_state", "located", "narrowed"):
        row[f"{k}_error_pct"] = (None if row[k] is None or ref["load"] is None
                                 else 100 * (row[k] - ref["load"]) / ref["load"])
    print(*case.values(), how, {k: row[k] for k in ("steps", "at_state", "located", "narrowed",
                                                    "reference")}, flush=True)
    return row


def write_tables(rows: list[dict], out: Path, stem: str, title: str, doc: str,
                 first: tuple[str, str, Callable[[dict], str]], fine: float,
                 load0: tuple[float, ...], error_digits: int = 2,
                 after: list[str] | None = None, stamp: str = "") -> None:
    """Write ``<stem>.csv`` and ``<stem>.md`` under ``out``.

    ``first``: the first column's header, alignment and cell; ``doc`` the script's description;
    ``after``: lines below the table; ``stamp``: the ``Measured on …`` line.
    """
    out.mkdir(parents=True, exist_ok=True)
    with open(out / f"{stem}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    def num(v, fmt="{:.2f}"):
        return "—" if v is None else fmt.format(v)

    err = "{:+." + str(error_digits) + "f} %"
    head, align, cell = first
    lines = [
        f"# {title}", "", doc, "", *([stamp, ""] if stamp else []),
        f"Load average at start {load0[0]:.2f}, at end {os.getloadavg()[0]:.2f} (2 cores). "
        f"Fine paths: displacement steps ≤ {fine} mm. Seconds: the beam run in process, "
        "without / with narrowing.",
        "",
        f"| {head} | path | steps | step (λ) | at state | error | located | error "
        "| narrowed | error | its bracket | seconds |",
        f"|{align}|---|---:|---|---:|---:|---:|---:|---:|---:|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {cell(r)} | {r['path']} | {r['steps']} | "
            f"{num(r['step_low'])} – {num(r['step_high'])} "
            f"| {num(r['at_state'])} | {num(r['at_state_error_pct'], err)} "
            f"| {num(r['located'])} | {num(r['located_error_pct'], err)} "
            f"| {num(r['narrowed'])} | {num(r['narrowed_error_pct'], err)} "
            f"| {num(r['narrowed_low'])} – {num(r['narrowed_high'])} "
            f"| {r['seconds']:.2f} / {r['seconds_narrowed']:.2f} |")
    lines += after or []
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {out / f'{stem}.md'}")
