"""Does the 2D model's mesh estimate cover its true error? The default level, per scene.

Run from the project root: ``python -m benchmarks.mesh_error_2d`` (``--cases …``, ``--out
DIR``); writes ``benchmarks/results/reference2d/mesh_error.{csv,md}``.

Each case is solved by the 2D model at its default level (medium) with its estimate
(``summary.json`` → ``mesh_error``: the path again at level coarse, ``estimate_factor`` × the
change; :mod:`sandwich.plane2d.mesh_error`) and at level fine (the peel couple: on explicit
meshes at refine 0 / 1 / 2, estimated at 1). ``true`` is the medium level's
error against the Richardson extrapolation of coarse (the estimate's own run), medium and fine
with the rate the three levels show (where they converge monotonically; else against fine,
and the table says so). The issue's test: where the true error exceeds a tenth of the
tolerance, estimated / true within [1, 5]. c3 and c4 take fine from
``reference2d/sliding_contact_2d.csv`` (their fine runs take 15-20 minutes).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import math
import time
from pathlib import Path

from benchmarks.provenance import RESULTS, add_out_argument, measured_on, write_rows
from benchmarks.verdicts import verdict
from sandwich.plane2d import solve
from sandwich.plane2d.mesh_error import TOLERANCES, estimate_factor
from sandwich.results.changes import STRESS_QUANTITIES, averaged_peaks
from sandwich.scene_file import load_scene

OUT = RESULTS / "reference2d"
ROOT = Path(__file__).resolve().parents[1]
SLIDING_CSV = RESULTS / "reference2d" / "sliding_contact_2d.csv"
FIG4 = "paper-fig4-bonded-3pb.toml"
FIG5 = "paper-fig5-top-debond-40-load-top.toml"
#: case -> (scene file, what it changes: None or a load target under load control)
CASES = {"fig5": (FIG5, None), "demo": ("default.toml", None), "fig4-load": (FIG4, 1500.0),
         "fig5-G-450": (FIG5, 450.0), "fig5-G-600": (FIG5, 600.0),
         "c3": ("paper-fig7-cantilever-c3.toml", None),
         "c4": ("paper-fig7-cantilever-c4.toml", None), "peel": (None, None)}
SLIDING = ("c3", "c4")
LEVELS = (("coarse", 0), ("medium", 0), ("fine", 0))
#: the peel couple of tests/fracture on explicit meshes (core 4 mm, faces 8 mm, 1 mm at the
#: tip): its load converges at p ≈ 1, the slowest rate the estimate allows for
PEEL_SIZES = {"core_size": 4.0, "face_size": 8.0, "tip_size": 1.0}
PEEL_LEVELS = (("explicit", 0), ("explicit", 1), ("explicit", 2))
FIELDS = ["case", "levels", "quantity", "coarse", "medium", "fine", "rate", "reference", "true",
          "estimated", "ratio", "verdict", "seconds_medium", "seconds_coarse", "measured"]


def case_scene(case: str):
    """The case's scene: as shipped, or under load control to its load target."""
    if case == "peel":
        from benchmarks.cases.fracture_cases import peel_loads, scene

        sc = scene(peel_loads())
        return dataclasses.replace(sc, reference2d=dataclasses.replace(
            sc.reference2d, level="explicit", **PEEL_SIZES))
    name, load = CASES[case]
    scene = load_scene(ROOT / "scenes" / name)
    if load is None:
        return scene
    a = dataclasses.replace(scene.analysis, control="load", until_probe=None, until_value=None,
                            until_load_factor=load)
    return dataclasses.replace(scene, analysis=a)


def answers(row: dict) -> dict[str, float]:
    """A state's answer: the load, each probe, the averaged stress peaks, G and G_II/G at the
    tip of the largest G."""
    out = {"load": row["load_factor"]}
    out.update({f"probe {k}": v for k, v in row["probes"].items()})
    out.update({f"peak {k}": v for k, v in row.get("stress", {}).items()})
    tips = [k for k, v in row["extra"].items() if k.startswith("G_") and v is not None]
    if tips:
        top = max(tips, key=lambda k: abs(row["extra"][k]))
        out["G"] = row["extra"][top]
        out["G_II/G"] = row["extra"]["GII" + top[1:]] / row["extra"][top]
    return out


#: below this rate three levels are not taken as asymptotic: the reference is the finest level
MIN_RATE = 0.5


def richardson(c: float, m: float, f: float) -> tuple[float, float | None]:
    """The extrapolated value and the rate of three levels halving h; (fine, None) if not.

    Not where the changes alternate in sign, do not shrink, or shrink at a rate below
    ``MIN_RATE`` (an extrapolation at rate p multiplies the last change by 1 / (2^p − 1): 11
    at p = 0.12, where the levels are not in their asymptotic range).
    """
    d1, d2 = c - m, m - f
    if d1 == 0.0 or d2 == 0.0 or d1 * d2 < 0.0 or abs(d2) >= abs(d1):
        return f, None
    p = math.log2(d1 / d2)
    if p < MIN_RATE:
        return f, None
    return f - d2 / (2.0**p - 1.0), p


def _row_of(sol) -> dict:
    last = sol.history[-1]
    stress = averaged_peaks(sol.profiles[-1].columns) \
        if sol.profiles and sol.profiles[-1].step == last.step else {}
    return {"load_factor": last.load_factor, "probes": dict(last.probes),
            "extra": dict(last.extra), "stress": stress}


def fine_of(case: str, scene, level: tuple[str, int]) -> tuple[dict, str]:
    """The fine level's state at the target (c3/c4: the end load from the sliding table)."""
    if case in SLIDING:
        for row in csv.DictReader(open(SLIDING_CSV)):
            if row["scene"] == case and row["level"] == "fine" and row["status"] == "ok":
                return ({"load_factor": float(row["lambda_40"]), "probes": {}, "extra": {}},
                        "sliding_contact_2d.csv")
        raise SystemExit(f"no fine row of {case} in {SLIDING_CSV}")
    sol = solve(scene, level=level[0], refine=level[1], estimate=False)
    if not sol.converged:
        raise SystemExit(f"{case}: 2D {level} stopped: {sol.message}")
    return _row_of(sol), "solved here"


REFERENCES = OUT / "mesh_error_references.json"


def _keep_references(case: str, refs: dict[str, float], measured: str) -> None:
    """The case's converged 2D answer (Richardson, or fine) per quantity, for the beam's table
    (benchmarks.honest_estimates): ``mesh_error_references.json``."""
    kept = json.loads(REFERENCES.read_text()) if REFERENCES.exists() else {}
    kept[case] = {"values": refs, "measured": measured}
    REFERENCES.write_text(json.dumps(kept, indent=1, sort_keys=True) + "\n")


def run_case(case: str, measured: str) -> list[dict]:
    scene = case_scene(case)
    levels = PEEL_LEVELS if case == "peel" else LEVELS
    t = time.perf_counter()
    medium = solve(scene, level=levels[1][0], refine=levels[1][1], estimate=True)
    seconds = time.perf_counter() - t
    entry = medium.extra["mesh_error"]
    if entry.get("not_measured"):
        raise SystemExit(f"{case}: no estimate: {entry['not_measured']}")
    m_row = _row_of(medium)
    c_row = {**entry["coarser_answer"], "stress": entry["coarser_answer"]["stress_peaks"]}
    f_row, source = fine_of(case, scene, levels[2])
    values = [answers(r) for r in (c_row, m_row, f_row)]
    refs = {k: richardson(*(lv[k] for lv in values)) for k in values[2] if k in values[0]}
    _keep_references(case, {k: ref for k, (ref, _) in refs.items()}, measured)
    kinds = {"load and probes": [k for k in refs if k == "load" or k.startswith("probe")],
             "G": [k for k in refs if k == "G"], "G_II/G": [k for k in refs if k == "G_II/G"],
             **{name: [f"peak {c}" for c in columns if f"peak {c}" in refs]
                for name, columns in STRESS_QUANTITIES.items()}}
    # a probe relative to the largest probe, a stress peak to the largest of its group
    scales = {k: max(abs(refs[j][0]) for j in keys if j != "load")
              for keys in kinds.values() for k in keys if k != "load"}

    def true_error(k: str) -> float:
        m, ref = values[1][k], refs[k][0]
        if k == "G_II/G":
            return abs(m - ref)
        return abs(m - ref) / (abs(ref) if k in ("load", "G") else scales[k])
    rows = []
    for name, keys in kinds.items():
        if not keys or name not in entry["quantities"]:
            continue
        worst = max(keys, key=true_error)
        true, tol = true_error(worst), TOLERANCES[name]
        estimated = entry["quantities"][name]["estimated_error"]
        ratio, said = verdict(true, estimated, tol)
        ref, p = refs[worst]
        rows.append({"case": case, "levels": " / ".join(f"{lv}+{r}" for lv, r in levels),
                     "quantity": f"{name} ({worst})",
                     "coarse": f"{values[0][worst]:.6g}", "medium": f"{values[1][worst]:.6g}",
                     "fine": f"{values[2][worst]:.6g}", "rate": "" if p is None else f"{p:.2f}",
                     "reference": (f"Richardson {ref:.6g}" if p is not None
                                   else f"fine ({source}): not asymptotic"),
                     "true": f"{100 * true:.3f} %", "estimated": f"{100 * estimated:.3f} %",
                     "ratio": "" if ratio is None else f"{ratio:.2f}", "verdict": said,
                     "seconds_medium": f"{seconds - entry['coarser_seconds']:.1f}",
                     "seconds_coarse": f"{entry['coarser_seconds']:.1f}",
                     "measured": measured})
    return rows


def write_tables(out: Path, rows: list[dict], measured: str) -> None:
    """``mesh_error.csv`` and ``mesh_error.md`` in ``out`` (rewritten after every case)."""
    write_rows(out / "mesh_error.csv", FIELDS, rows)
    lines = ["# Does the 2D mesh estimate cover its true error? (benchmarks/mesh_error_2d.py)",
             "", measured, "",
             "The 2D model at its default level (medium) with its estimate (the path again one",
             "level coarser, the change (interface σzz, singular at tips and supports: "
             f"{estimate_factor('interface sigma_zz'):.2f} × it): `summary.json` → "
             "`mesh_error`),",
             "against the Richardson extrapolation of the three levels at the rate they show",
             "(`rate`; where the changes alternate, grow or shrink at a rate below "
             f"{MIN_RATE:g}, the",
             "finest level, which then only bounds the true error from below); `ratio` =",
             "estimated / true; the test: where the true error exceeds a",
             "tenth of the tolerance (1 % loads and probes, 2 % G and G_II/G), ratio in",
             "[1, 5]. `peel`: the peel couple of tests/fracture on explicit meshes (core 4 mm,",
             "faces 8 mm, 1 mm at the tip) at refine 0 / 1 / 2, estimated at refine 1.",
             "Seconds: the estimated level's path, and the coarser path the estimate adds.", "",
             "| " + " | ".join(FIELDS[:-1]) + " |",
             "|" + "---|" * (len(FIELDS) - 1)]
    lines += ["| " + " | ".join(str(r[k]) for k in FIELDS[:-1]) + " |" for r in rows]
    (out / "mesh_error.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    add_out_argument(parser, OUT)
    args = parser.parse_args()
    measured = measured_on()
    path = args.out / "mesh_error.csv"
    kept = [r for r in csv.DictReader(open(path)) if r["case"] not in args.cases] \
        if path.exists() else []  # the other cases' rows stay
    rows: list[dict] = []
    for case in args.cases:
        rows += run_case(case, measured)
        print(rows[-1] if rows else case, flush=True)
        order = list(CASES)
        merged = sorted(kept + rows, key=lambda r: order.index(r["case"]))
        write_tables(args.out, merged, " ".join(dict.fromkeys(r["measured"] for r in merged)))


if __name__ == "__main__":
    main()
