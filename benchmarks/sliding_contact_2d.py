"""The 2D model on the clamped cantilevers whose core slides ≈ 3 mm along the debonded faces.

The crack-lip contact follows the sliding (``sandwich.plane2d.contact``: each face-lip node
projected afresh on the deformed core lip). Each row is one 2D run of the scene to
w_top_tip = −40 mm at a mesh level, in this process, so that the levels show the model
converging. Columns: λ at w_top_tip = −20, −30, −40 mm (interpolated in the history), each level's
λ(−40) against the finest level run here and against the independent finite-sliding
plane-stress model issue 51 cites (kept outside the project, mesh-checked to ≈ 0.3 %; quoted as
≈ 45.0 on c4 at −40 mm, 2.7 % above the earlier small-sliding 2D fine 43.83), converged states,
steps taken under probe control, the largest sliding of a face-lip node in contact, the largest
penetration over the face thickness, the times the contact windows were widened, and the
seconds (as measured, with other jobs running on the machine: not a speed comparison, see
``docs/speed.md``).

    python -m benchmarks.sliding_contact_2d            # coarse, medium, fine on c3 and c4
    python -m benchmarks.sliding_contact_2d --scenes c4 --levels coarse medium

Writes ``benchmarks/results/reference2d/sliding_contact_2d.{csv,md}``; a run of some scenes and
levels replaces their rows and keeps the others (each row says when it was measured).
"""

from __future__ import annotations

import argparse
import csv
import re
import time

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on, write_rows
from benchmarks.sliding_contact import AT, SCENES, _at
from sandwich.scene_file import load_scene

OUT = RESULTS / "reference2d"
LEVELS = ("coarse", "medium", "fine")
#: λ(−40) of the independent finite-sliding model (module docstring), quoted
FINITE_SLIDING = {"c4": 43.83 * 1.027}
FIELDS = ["measured", "scene", "level", "cells", "lambda_20", "lambda_30", "lambda_40", "states",
          "rescues", "max_sliding", "max_penetration_over_face", "window_growths", "seconds",
          "status"]


def measure(case: str, level: str) -> dict:
    from sandwich.plane2d import system as system_module
    from sandwich.plane2d.solve import solve

    growths = []
    widen = system_module.Reference2DSystem._widen_windows

    def counted(self, states):
        growths.append(1)
        widen(self, states)

    system_module.Reference2DSystem._widen_windows = counted
    try:
        t = time.perf_counter()
        s = solve(load_scene(ROOT / "scenes" / SCENES[case]), level=level, estimate=False)
        seconds = time.perf_counter() - t
    finally:
        system_module.Reference2DSystem._widen_windows = widen
    rescued = re.search(r"\((\d+) step\(s\) taken under control", s.message)
    return {"cells": s.extra["cells"], "lambda_20": _at(s.history, AT[0]),
            "lambda_30": _at(s.history, AT[1]), "lambda_40": _at(s.history, AT[2]),
            "states": len(s.history), "rescues": int(rescued.group(1)) if rescued else 0,
            "max_sliding": s.extra["max_sliding"],
            "max_penetration_over_face": s.extra["max_penetration_over_face_thickness"],
            "window_growths": len(growths), "seconds": seconds,
            "status": "ok" if s.converged else s.message[:80]}


def _f(v, fmt: str) -> str:
    return "—" if v is None else format(v, fmt)


def _pct(a, b) -> str:
    return "—" if a is None or b is None else f"{100 * (a / b - 1):+.2f} %"


def table(rows: list[dict]) -> str:
    finest = {}
    for r in sorted(rows, key=lambda r: LEVELS.index(r["level"])):  # each scene's finest level
        finest[r["scene"]] = r
    lines = ["# The 2D model on the sliding cantilevers c3, c4 "
             "(`benchmarks/sliding_contact_2d.py`)", "",
             "Measured on " + "; ".join(sorted({r["measured"] for r in rows})) + ".", "",
             __doc__.split("\n\n")[1].replace("\n", " "), "",
             "| scene | level | cells | λ(−20) | λ(−30) | λ(−40) | vs finest here | "
             "vs finite-sliding (≈) | states | rescues | max sliding (mm) | "
             "penetration / h_face | window growths | seconds |",
             "|---|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|"]
    rows = sorted(rows, key=lambda r: (r["scene"], LEVELS.index(r["level"])))
    for r in rows:
        lam = r["lambda_40"]
        top = finest[r["scene"]]
        lines.append(
            f"| {r['scene']} | {r['level']} | {r['cells']:.0f} | {_f(r['lambda_20'], '.3f')} | "
            f"{_f(r['lambda_30'], '.3f')} | {_f(lam, '.3f')} | "
            f"{'—' if top is r else _pct(lam, top['lambda_40']) + ' (' + top['level'] + ')'} | "
            f"{_pct(lam, FINITE_SLIDING.get(r['scene']))} | {r['states']:.0f} | "
            f"{r['rescues']:.0f} | {r['max_sliding']:.2f} | "
            f"{r['max_penetration_over_face']:.2g} | {r['window_growths']:.0f} | "
            f"{r['seconds']:.1f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_out_argument(ap, OUT)
    ap.add_argument("--levels", nargs="+", choices=LEVELS, default=list(LEVELS))
    ap.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES))
    args = ap.parse_args()
    path = args.out / "sliding_contact_2d.csv"
    rows = []
    if path.is_file():  # the other scenes' rows are kept
        with open(path, newline="") as f:
            rows = [{k: v if k in ("measured", "scene", "level", "status") else
                     None if v == "" else float(v) for k, v in r.items()}
                    for r in csv.DictReader(f)
                    if r["scene"] not in args.scenes or r["level"] not in args.levels]
    for case in args.scenes:
        for level in args.levels:
            stamp = measured_on()
            row = {"measured": stamp.removeprefix("Measured on ").rstrip("."), "scene": case,
                   "level": level, **measure(case, level)}
            print(row, flush=True)
            rows.append(row)
            write_rows(path, FIELDS, rows)  # each row as soon as it is measured
    (args.out / "sliding_contact_2d.md").write_text(table(rows))


if __name__ == "__main__":
    main()
