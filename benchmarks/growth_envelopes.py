"""Debond growth by crack-length control in both models: envelopes, residual strength, cost.

Each case (``benchmarks.cases.growth_cases.CASES``) is run by ``sandwich.compare`` with both
models at their defaults (the 2D model at ``--level``), one after the other in this process;
the comparison folder (``benchmarks/results/growth/<case>/``) holds the envelope figures and
``growth.csv``. The table has, per case, each model's first growth load and residual strength
(N), the beam's over the 2D model's, the number of lengths grown, and the seconds of each
growth run (``wall_seconds``, the same machine, one after the other: their ratio is the beam's
speed-up). For the face cantilever it also has the slope of 1/λ_c over the length against its
closed form √(6 / (G_c b² E t³)).

    python -m benchmarks.growth_envelopes                     # every case, 2D coarse
    python -m benchmarks.growth_envelopes --cases fig5 --level medium
    python -m benchmarks.growth_envelopes --objectivity --cases fig5   # beam only

``--objectivity`` instead runs the beam alone on each case at its defaults, with the growth
step halved, with twice the elements, and at the fixed core levels 1 (the paper's element) and
3 instead of ``auto``, and writes
``benchmarks/results/growth/growth_objectivity.{csv,md}``: how much the first growth load and
the residual strength move (the discretisation of the growth and of the beam).

Writes ``benchmarks/results/growth/growth_envelopes.{csv,md}``; a run of some cases replaces
their rows and keeps the others (each row says when and at which 2D level it was measured).
"""

from __future__ import annotations

import argparse
import csv
import os
import time

import numpy as np

from benchmarks.cases.growth_cases import CASES, onset_slope
from benchmarks.provenance import RESULTS, machine, write_rows

OUT = RESULTS / "growth"
FIELDS = ["measured", "case", "level_2d", "lengths_beam", "lengths_2d", "first_growth_beam_N",
          "first_growth_2d_N", "first_growth_ratio", "residual_strength_beam_N",
          "residual_strength_2d_N", "residual_strength_ratio", "onset_slope_beam_over_closed",
          "onset_slope_2d_over_closed", "seconds_beam", "seconds_2d", "speedup", "load"]


def measure(case: str, level: str) -> dict:
    from sandwich.compare import compare
    from sandwich.growth import onset_rows

    build, _ = CASES[case]
    out = OUT / case
    cmp = compare(build(level), out, reuse=False)
    rows = {r["model"]: r for r in csv.DictReader((out / "growth.csv").open())}
    sols = cmp.solutions
    row = {"measured": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "case": case,
           "level_2d": level}
    for m, name in (("beam", "beam"), ("2d", "2d")):
        r = rows.get(m, {})
        row[f"lengths_{name}"] = r.get("stages", "")
        row[f"first_growth_{name}_N"] = r.get("first_growth_load_N", "")
        row[f"residual_strength_{name}_N"] = r.get("residual_strength_N", "")
        row[f"seconds_{name}"] = f"{float(r['wall_seconds']):.1f}" if r else ""
        if case == "cantilever" and m in sols:
            onsets = onset_rows(sols[m].history)
            a = np.array([o.extra["tip_0_end"] for o in onsets])
            inv = 1.0 / np.array([o.load_factor for o in onsets])
            row[f"onset_slope_{name}_over_closed"] = (
                f"{np.polyfit(a, inv, 1)[0] / onset_slope():.4f}" if len(a) > 1 else "")
    beam = rows.get("beam", {})
    row["first_growth_ratio"] = beam.get("first_growth_load_over_2d", "")
    row["residual_strength_ratio"] = beam.get("residual_strength_over_2d", "")
    row["load"] = f"{os.getloadavg()[0]:.2f}"  # > 1.2 or so: other jobs shared the 2 cores
    if row["seconds_beam"] and row["seconds_2d"]:
        row["speedup"] = f"{float(row['seconds_2d']) / float(row['seconds_beam']):.1f}"
    return row


def write_md(rows: list[dict]) -> None:
    lines = [
        "# Debond growth by crack-length control, beam vs 2D "
        "(`benchmarks/growth_envelopes.py`)",
        "",
        f"Machine: {machine()}. Each row's `measured` column is its UTC time; the 2D level is "
        "its own column. Loads in N; ratios beam / 2D; seconds are each model's whole growth "
        "run (every length's path, and the paths stopped on an onset), one after the other in "
        "one process; speed-up = 2D seconds / beam seconds; load = the 1-minute load average "
        "at the end of the case (above ≈ 1.2 other jobs shared the 2 cores, and the times "
        "are not a clean comparison; — : not recorded). Figures and `growth.csv` per case "
        "in `benchmarks/results/growth/<case>/`.",
        "",
        "| case | what | 2D level | lengths beam / 2D | first growth beam / 2D (N) | ratio | "
        "residual strength beam / 2D (N) | ratio | 1/λ_c slope / closed form beam, 2D | "
        "seconds beam / 2D | speed-up | load | measured |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def n(v, f="{:.5g}"):
        return f.format(float(v)) if v not in ("", None) else "—"

    for r in rows:
        lines.append(
            f"| {r['case']} | {CASES[r['case']][1]} | {r['level_2d']} | {r['lengths_beam']} / "
            f"{r['lengths_2d']} | {n(r['first_growth_beam_N'])} / {n(r['first_growth_2d_N'])} | "
            f"{n(r['first_growth_ratio'], '{:.4f}')} | {n(r['residual_strength_beam_N'])} / "
            f"{n(r['residual_strength_2d_N'])} | {n(r['residual_strength_ratio'], '{:.4f}')} | "
            f"{n(r.get('onset_slope_beam_over_closed'), '{:.4f}')}, "
            f"{n(r.get('onset_slope_2d_over_closed'), '{:.4f}')} | {r['seconds_beam']} / "
            f"{r['seconds_2d']} | {r['speedup'] or '—'} | {r.get('load') or '—'} | "
            f"{r['measured']} |")
    (OUT / "growth_envelopes.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


OBJ_FIELDS = ["measured", "case", "variant", "step_mm", "elements", "lengths",
              "first_growth_N", "residual_strength_N", "first_growth_change",
              "residual_strength_change", "seconds"]


VARIANTS = ("defaults", "half step", "twice the elements", "core level 1", "core level 3")


def objectivity(case: str, variants: tuple[str, ...] = VARIANTS,
                reference: dict | None = None) -> list[dict]:
    """The beam's growth on ``case`` at its defaults, half the growth step, twice the elements."""
    import dataclasses

    from sandwich.beam import solve
    from sandwich.compare.compare import total_force
    from sandwich.growth import grow

    build, _ = CASES[case]
    base = build("coarse")
    i = next(k for k, d in enumerate(base.debonds) if d.growth is not None)
    d = base.debonds[i]

    def with_debond(sc, new):
        return dataclasses.replace(sc, debonds=tuple(new if k == i else o
                                                     for k, o in enumerate(sc.debonds)))

    half = with_debond(base, dataclasses.replace(d, growth=dataclasses.replace(
        d.growth, step=0.5 * d.growth.step)))
    finer = dataclasses.replace(base, beam_model=dataclasses.replace(
        base.beam_model, elements=2 * base.beam_model.elements))
    fixed = {f"core level {k}": dataclasses.replace(base, beam_model=dataclasses.replace(
        base.beam_model, core=k)) for k in (1, 3)}
    out, first = [], reference
    for name, sc in (("defaults", base), ("half step", half), ("twice the elements", finer),
                     *fixed.items()):
        if name not in variants:
            continue
        t = time.perf_counter()
        sol = grow(sc, solve)
        g = sol.extra["debond_growth"]
        scale = total_force(sc)
        row = {"measured": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "case": case,
               "variant": name, "step_mm": sc.debonds[i].growth.step,
               "elements": sc.beam_model.elements, "lengths": g["onsets"],
               "first_growth_N": scale * g["first_growth_load"],
               "residual_strength_N": scale * g["residual_strength"],
               "seconds": f"{time.perf_counter() - t:.1f}"}
        if first is None:
            first = row
        for k in ("first_growth", "residual_strength"):
            row[f"{k}_change"] = f"{row[f'{k}_N'] / first[f'{k}_N'] - 1:+.4f}"
        out.append(row)
        print(row, flush=True)
    return out


def write_objectivity(rows: list[dict]) -> None:
    lines = [
        "# Growth: the beam's first growth load and residual strength under a halved growth "
        "step and twice the elements (`benchmarks/growth_envelopes.py --objectivity`)",
        "",
        f"Machine: {machine()}; each row's `measured` column is its UTC time. Beam at the "
        "scene's defaults otherwise (`core = \"auto\"`); changes are relative to the defaults "
        "row of the case; seconds with the load of other jobs on the machine as it was.",
        "",
        "| case | variant | step (mm) | elements | lengths | first growth (N) | change | "
        "residual strength (N) | change | seconds | measured |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['case']} | {r['variant']} | {r['step_mm']} | {r['elements']} | "
                     f"{r['lengths']} | {float(r['first_growth_N']):.5g} | "
                     f"{r['first_growth_change']} | {float(r['residual_strength_N']):.5g} | "
                     f"{r['residual_strength_change']} | {r['seconds']} | {r['measured']} |")
    (OUT / "growth_objectivity.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    p.add_argument("--level", default="coarse", choices=("coarse", "medium", "fine"))
    p.add_argument("--objectivity", action="store_true",
                   help="the beam alone: growth step halved, elements doubled, fixed levels")
    p.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS,
                   help="with --objectivity: which runs (default: all)")
    args = p.parse_args()
    if args.objectivity:
        path = OUT / "growth_objectivity.csv"
        old = list(csv.DictReader(path.open())) if path.is_file() else []
        wanted = tuple(args.variants)
        kept = [r for r in old if r["case"] not in args.cases or r["variant"] not in wanted]
        rows = kept[:]
        for case in args.cases:
            ref = next((r for r in kept if r["case"] == case and r["variant"] == "defaults"),
                       None)
            if ref is not None:
                ref = {k: float(ref[k]) for k in ("first_growth_N", "residual_strength_N")}
            rows += objectivity(case, wanted, ref)
        rows.sort(key=lambda r: (list(CASES).index(r["case"]), VARIANTS.index(r["variant"])))
        for r in rows:  # against the defaults row as it is now (kept rows were against theirs)
            ref = next((d for d in rows if d["case"] == r["case"]
                        and d["variant"] == "defaults"), None)
            for k in ("first_growth", "residual_strength") if ref is not None else ():
                r[f"{k}_change"] = f"{float(r[f'{k}_N']) / float(ref[f'{k}_N']) - 1:+.4f}"
        write_rows(path, OBJ_FIELDS, rows)
        write_objectivity(rows)
        return
    path = OUT / "growth_envelopes.csv"
    old = list(csv.DictReader(path.open())) if path.is_file() else []
    rows = {(r["case"], r["level_2d"]): r for r in old}
    for case in args.cases:
        print(f"{case} ...", flush=True)
        rows[(case, args.level)] = measure(case, args.level)
        ordered = sorted(rows.values(), key=lambda r: (list(CASES).index(r["case"]),
                                                        r["level_2d"]))
        write_rows(path, FIELDS, ordered)
        write_md(ordered)
        print(rows[(case, args.level)], flush=True)


if __name__ == "__main__":
    main()
