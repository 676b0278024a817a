"""Core levels of the beam against the 2D reference: end-of-path load, error, wall time.

Run from the project root: ``python -m benchmarks.core_levels --case fig5 --variants L1 L2 L3
auto`` (appends rows to ``benchmarks/results/beam/core_levels.csv``, each with the machine and
date it was measured on) and ``--report`` (writes ``core_levels.md`` and ``core_levels.png`` from
every row); ``--out DIR`` for another folder (the 2D references stay cached in
``benchmarks/results/beam/core_levels_2d.json``).

Cases (scene, target, 2D reference):

- ``bend``: the bonded three-point bend of fig. 4 made linear (w_top_mid = −1 mm); reference the
  2D model at level ``fine``, solved here (``--reference2d``) and kept in
  ``core_levels_2d.json``;
- ``fig4``: fig. 4 to w_top_mid = −12 mm; reference the 2D ``medium`` run of
  ``benchmarks/results/comparisons/tradeoff.csv`` (its ``fine`` run stopped before −12 mm);
- ``fig5``: fig. 5 to w_top_mid = −15 mm; reference the 2D ``fine`` run of tradeoff.csv;
- ``c3``: the c3 cantilever to −40 mm; reference the 2D ``medium`` run, solved here;
- ``demo``: ``scenes/default.toml`` (fig. 5 to −8 mm, the ``make demo`` scene); reference the 2D
  ``fine`` run, solved here.

Variants: ``L<k>`` every element at level k (``P<k>``: the polynomial family), ``auto`` the
scene default (error indicator against ``[beam_model] tolerance``). Without a suffix a variant
runs the scene defaults (stretch faces, averaged face membrane, closest-point contact); suffix
letters switch one of them back to the paper's choice: ``f`` the paper's faces (``faces =
"paper"``: w constant through a face), ``m`` the paper's membrane strain (``face_membrane =
"paper"``), ``s`` same-x contact pairing (``contact_search = "same-x"``), ``p`` all three — so
``L1p`` is the paper's element. Rows written before 2026-12-02 (no ``faces`` column) were run
with all three of the paper's choices and are named with ``p``. Elements: the scene's
(240) unless ``--elements``. The machine's load average is recorded with every row.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import os
import time
from pathlib import Path

from benchmarks.provenance import (
    RESULTS,
    ROOT,
    add_out_argument,
    append_row,
    machine_and_date,
    measured_line,
    measured_on,
)
from sandwich.beam import run
from sandwich.scene_file import load_scene

OUT = RESULTS / "beam"
TRADEOFF = RESULTS / "comparisons" / "tradeoff.csv"
CASES = {
    "bend": ("paper-fig4-bonded-3pb.toml", -1.0, "linear"),
    "fig4": ("paper-fig4-bonded-3pb.toml", -12.0, "nonlinear"),
    "fig5": ("paper-fig5-top-debond-40-load-top.toml", -15.0, "nonlinear"),
    "c3": ("paper-fig7-cantilever-c3.toml", -40.0, "nonlinear"),
    "demo": ("default.toml", -8.0, "nonlinear"),
}
REFERENCE_LEVEL = {"bend": "fine", "c3": "medium", "demo": "fine"}
FIELDS = ["case", "variant", "elements", "dofs", "levels", "estimate", "lambda_end", "reached",
          "steps", "iterations", "seconds", "load", "w_end", "max_steps", "faces", "membrane",
          "contact", "measured"]
PAPER_CHOICES = {"f": ("faces", "paper"), "m": ("membrane", "paper"), "s": ("contact", "same-x")}


def parse_variant(variant: str) -> tuple[str, dict[str, str]]:
    """(core part ``L3``/``P2``/``auto``, {faces, membrane, contact}) of a variant name."""
    core = variant
    choice = {"faces": "stretch", "membrane": "averaged", "contact": "closest-point"}
    while core and core[-1] in "pfms" and core != "auto":
        for letter in ("fms" if core[-1] == "p" else core[-1]):
            key, value = PAPER_CHOICES[letter]
            choice[key] = value
        core = core[:-1]
    if core != "auto" and not (core[:1] in ("L", "P") and core[1:].isdigit()):
        raise SystemExit(f"unknown variant {variant!r}: expected L<k>, P<k> or auto, optionally "
                         "followed by f, m, s or p (the paper's faces, membrane, contact, all)")
    return core, choice


def case_scene(case: str, max_steps: int | None = None):
    """The case's scene with its target (and linear analysis for ``bend``)."""
    name, until, kind = CASES[case]
    scene = load_scene(ROOT / "scenes" / name)
    a = dataclasses.replace(scene.analysis, kind=kind, until_value=until)
    if max_steps is not None:
        a = dataclasses.replace(a, max_steps=max_steps)
    return dataclasses.replace(scene, analysis=a)


def reference(case: str) -> tuple[float, str]:
    """2D reference load factor at the case's target and where it comes from."""
    if case in ("fig4", "fig5"):
        level = "medium+0" if case == "fig4" else "fine+0"
        scene = CASES[case][0].removesuffix(".toml")
        for row in csv.DictReader(open(TRADEOFF)):
            if row["scene"] == scene and row["model"] == "2d" and row["resolution"] == level:
                return float(row["final_load_factor"]), f"2D {level.split('+')[0]}, tradeoff.csv"
        raise SystemExit(f"no 2D {level} row for {scene} in {TRADEOFF}")
    cached = json.loads((OUT / "core_levels_2d.json").read_text()) if (
        OUT / "core_levels_2d.json").exists() else {}
    if case not in cached:
        raise SystemExit(f"no 2D reference for {case}: run with --reference2d {case}")
    return cached[case]["lambda_end"], f"2D {cached[case]['level']}, solved here"


def solve_reference(case: str) -> None:
    """Solve the 2D model on the case and cache its end load (level: REFERENCE_LEVEL)."""
    from sandwich.plane2d import solve as solve2d

    level = REFERENCE_LEVEL[case]
    t = time.perf_counter()
    sol = solve2d(case_scene(case), level=level, estimate=False)
    path = OUT / "core_levels_2d.json"
    cached = json.loads(path.read_text()) if path.exists() else {}
    cached[case] = {"level": level, "lambda_end": sol.history[-1].load_factor,
                    "converged": sol.converged, "seconds": time.perf_counter() - t,
                    "dofs": sol.dofs, "measured": measured_on()}
    path.write_text(json.dumps(cached, indent=2) + "\n")
    print(case, cached[case], flush=True)


def one(case: str, variant: str, elements: int | None, max_steps: int | None = None) -> dict:
    scene = case_scene(case, max_steps)
    core_part, choice = parse_variant(variant)
    opts: dict = {"face_stretch": choice["faces"] == "stretch",
                  "face_membrane": choice["membrane"], "contact_search": choice["contact"]}
    if core_part != "auto":
        opts.update(core_level=int(core_part[1:]),
                    core_basis="polynomial" if core_part[0] == "P" else "sublayers")
    load = os.getloadavg()[0]
    stamp = measured_on()
    t = time.perf_counter()
    r = run(scene, elements=elements, model_options=opts)
    seconds = time.perf_counter() - t
    s = r.solution
    core = s.extra["core"]
    counts: dict[int, int] = {}
    for e in r.model.element_levels:
        counts[int(e)] = counts.get(int(e), 0) + 1
    return dict(case=case, variant=variant, elements=r.model.mesh.n_elements, dofs=s.dofs,
                levels=" ".join(f"L{k}:{v}" for k, v in sorted(counts.items())),
                estimate=("" if core["estimated_error"] is None
                          else f"{core['estimated_error']:.4g}"),
                lambda_end=f"{s.history[-1].load_factor:.6g}", reached=s.converged,
                steps=len(s.history), iterations=s.extra["total_newton_iterations"],
                seconds=f"{seconds:.2f}", load=f"{load:.2f}",
                w_end=f"{s.history[-1].probes[scene.analysis.until_probe]:.4g}",
                max_steps=scene.analysis.max_steps, **choice,
                measured=machine_and_date(stamp))


def report(out: Path = OUT) -> None:
    """Write ``core_levels.md`` and ``core_levels.png`` in ``out`` from its every row."""
    rows = list(csv.DictReader(open(out / "core_levels.csv")))
    lines = ["# Beam core levels against the 2D reference (benchmarks/core_levels.py)", "",
             "err = λ_beam/λ_2D − 1 at the case's target deflection; `estimate` = the beam's own",
             "indicator (auto); seconds = whole beam solve in one process; load = 1-min load",
             "average when the run started (the machine has 2 cores: > 2 means shared).", "",
             measured_line(rows), ""]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = [c for c in CASES if any(r["case"] == c for r in rows)]
    fig, axes = plt.subplots(1, len(cases), figsize=(4.5 * len(cases), 4), squeeze=False)
    for ax, case in zip(axes[0], cases, strict=True):
        try:
            ref, src = reference(case)
        except SystemExit as e:
            lines += [f"## {case}: {e}", ""]
            continue
        _, until, kind = CASES[case]
        lines += [f"## {case} ({kind}, to {until:g} mm): 2D λ = {ref:.6g} ({src})", "",
                  "| variant | faces | membrane | contact | elements | DOFs | levels | estimate "
                  "| λ | err | reached | steps | s | load |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            if r["case"] != case:
                continue
            err = float(r["lambda_end"]) / ref - 1
            reached = r["reached"] == "True"
            said = (f"{100 * err:+.2f} %" if reached else
                    f"— (stopped at w = {r.get('w_end') or '?'} mm, max_steps "
                    f"{r.get('max_steps') or '?'})")
            lines.append(f"| {r['variant']} | {r.get('faces') or 'paper'} | "
                         f"{r.get('membrane') or 'paper'} | {r.get('contact') or 'same-x'} | "
                         f"{r['elements']} | {r['dofs']} | "
                         f"{r['levels']} | "
                         f"{r['estimate']} | {r['lambda_end']} | {said} | "
                         f"{r['reached']} | {r['steps']} | {r['seconds']} | {r['load']} |")
            if not reached:
                continue
            auto = r["variant"].startswith("auto")
            ax.loglog(float(r["seconds"]), abs(err) + 1e-5, "*" if auto else "o",
                      ms=10 if auto else 6)
            ax.annotate(r["variant"], (float(r["seconds"]), abs(err) + 1e-5), fontsize=7)
        lines.append("")
        ax.set(title=case, xlabel="beam wall time (s)", ylabel="|λ/λ_2D − 1|")
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "core_levels.png", dpi=110)
    (out / "core_levels.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--case", choices=sorted(CASES), default="fig5")
    p.add_argument("--variants", nargs="*", default=["L1", "L2", "L3", "L4", "auto"])
    p.add_argument("--elements", type=int, default=None)
    p.add_argument("--max-steps", type=int, default=None, help="cap the path's steps")
    p.add_argument("--reference2d", nargs="*", choices=sorted(CASES))
    p.add_argument("--report", action="store_true")
    add_out_argument(p, OUT)
    a = p.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    if a.reference2d:
        for case in a.reference2d:
            solve_reference(case)
        return
    if a.report:
        report(a.out)
        return
    for v in a.variants:
        row = one(a.case, v, a.elements, a.max_steps)
        append_row(a.out / "core_levels.csv", FIELDS, row)
        print(row, flush=True)


if __name__ == "__main__":
    main()
