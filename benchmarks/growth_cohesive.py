"""Debond growth by the cohesive law in both models: the closed form, the mesh, each other.

Cases (both models at their defaults unless said; the 2D model at its default level, without
its mesh estimate, run right after the beam on the same scene):

- ``cantilever``: the face cantilever of ``benchmarks.cases.growth_cases`` grown by the law
  (G_c 1e-5 N/mm, σ_c 0.01 MPa, end deflection to 0.5 mm) at 240 and 480 elements: the largest
  and last |P/P_closed − 1| while its tip runs from 15 mm past its start to one process zone
  before its span's end (P_closed the beam-theory propagation load, χ eliminated), the load at
  a deflection of 0.3 mm at both meshes (mesh objectivity: the elements in the process zone
  halved), and against the beam's own crack-length envelope (10 mm steps): the cohesive load at
  each onset's deflection over the onset load; the 2D model (at level medium, the default)
  against the same closed form over the same tip range (up to 400 steps: its path takes
  smaller ones) and against its own crack-length envelope;
- ``fig5``, ``c3``: the shipped scenes with the weak mixed-mode interfaces of
  ``growth_envelopes`` (fig. 5: G_Ic 0.004, G_IIc 0.008 N/mm; c3: 0.1, 0.3 N/mm), grown by the
  law (σ_c 0.15 and 0.7 MPa: process zones of a few elements at the default meshes; 30 mm
  spans): first growth load, residual strength, how far the tips ran, against the
  crack-length rows of ``growth_envelopes.csv`` (beam and 2D, measured there);
- ``cantilever_2d_fine`` (only when asked for): the 2D cantilever at level fine, whose
  elements are half medium's (mesh objectivity of the 2D model's law).

Paired columns (on the beam's row): the 2D residual strength over the beam's and the 2D
model's seconds over the beam's.

    python -m benchmarks.growth_cohesive                 # every case but the 2D fine one
    python -m benchmarks.growth_cohesive --cases cantilever
    python -m benchmarks.growth_cohesive --cases cantilever_2d_fine

Writes ``benchmarks/results/growth/growth_cohesive.{csv,md}``; a run of some cases replaces
their rows and keeps the others.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time

import numpy as np

from benchmarks.cases.growth_cases import (
    cantilever,
    cohesive_cantilever,
    propagation_load,
    shipped,
)
from benchmarks.provenance import RESULTS, machine, write_rows

OUT = RESULTS / "growth"
FIELDS = ["measured", "case", "model", "elements", "first_growth_N", "residual_strength_N",
          "grew_mm", "longest_process_zone_mm", "closed_form_max_dev", "closed_form_last_dev",
          "load_at_0.3mm", "envelope_ratio_min", "envelope_ratio_max",
          "crack_length_beam_N", "crack_length_2d_N", "residual_over_crack_length_beam",
          "residual_2d_over_beam", "seconds_2d_over_beam", "steps", "seconds", "converged",
          "load"]
MEDIUM = "medium"  # the 2D model's default level (the cantilever's scene asks for coarse)
SHIPPED = {"fig5": ("paper-fig5-top-debond-40-load-top", (0.004, 0.008), 0.15),
           "c3": ("paper-fig7-cantilever-c3", (0.1, 0.3), 0.7)}


def _cohesive(sc, sigma_c, zone=30.0):
    from sandwich.scene import Growth

    d = dataclasses.replace(sc.debonds[0], growth=Growth(method="cohesive", sigma_c=sigma_c,
                                                         zone=zone))
    return dataclasses.replace(sc, debonds=(d, *sc.debonds[1:]))


def _row(case, sol, seconds, elements, model="beam"):
    g = sol.extra["debond_growth"]
    tips = g["tips"].values()
    return {"measured": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "case": case,
            "model": model, "elements": elements,
            "first_growth_N": "" if g["first_growth_load"] is None
            else f"{g['first_growth_load']:.4g}",
            "residual_strength_N": f"{g['residual_strength']:.4g}",
            "grew_mm": f"{max(t['grew_mm'] for t in tips):.3g}",
            "longest_process_zone_mm": f"{max(t['longest_process_zone_mm'] for t in tips):.3g}",
            "steps": len(sol.history) - 1, "seconds": f"{seconds:.1f}",
            "converged": sol.converged, "load": f"{os.getloadavg()[0]:.2f}"}


def _closed_form(row, sol):
    """The deviation from the closed form while the tip runs from 55 to 105 mm; the curve."""
    d = np.array([abs(r.probes["w0"]) for r in sol.history])
    lam = np.array([r.load_factor for r in sol.history])
    tip = np.array([r.extra["tip_0_end"] for r in sol.history])
    run = (tip >= 55.0) & (tip <= 105.0)
    if run.any():
        dev = np.abs(lam[run] / propagation_load(d[run]) - 1.0)
        row["closed_form_max_dev"] = f"{dev.max():.4f}"
        row["closed_form_last_dev"] = f"{dev[-1]:.4f}"
    return d, lam, tip


def _solve_2d(scene, level=None):
    """The 2D model's path at ``level`` (default the scene's; no mesh estimate), timed."""
    from sandwich.plane2d.solve import solve

    t0 = time.perf_counter()
    sol = solve(scene, level=level, estimate=False)
    return sol, time.perf_counter() - t0


def _pair(beam_row, row_2d, beam_sol, sol_2d):
    """The paired columns on the beam's row: 2D residual strength and seconds over the beam's."""
    rb = beam_sol.extra["debond_growth"]["residual_strength"]
    r2 = sol_2d.extra["debond_growth"]["residual_strength"]
    beam_row["residual_2d_over_beam"] = f"{r2 / rb:.4f}"
    ratio = float(row_2d["seconds"]) / float(beam_row["seconds"])
    beam_row["seconds_2d_over_beam"] = f"{ratio:.1f}"


def measure_cantilever() -> list[dict]:
    from sandwich.beam import solve
    from sandwich.growth import grow, onset_rows

    rows, curves, beam = [], {}, None
    for elements in (240, 480):
        t0 = time.perf_counter()
        sol = solve(cohesive_cantilever(elements=elements))
        row = _row("cantilever", sol, time.perf_counter() - t0, elements)
        d, lam, tip = _closed_form(row, sol)
        beam = beam or (row, sol)
        after = np.flatnonzero(tip > tip[0])[0]  # on the softening branch: deflection rises
        row["load_at_0.3mm"] = f"{np.interp(0.3, d[after:], lam[after:]):.5g}"
        curves[elements] = (d[after:], lam[after:])
        rows.append(row)
    env = onset_rows(grow(cantilever(step=10.0, max_length=110.0, until=0.5), solve).history)
    ratios = []
    for o in env[1:]:  # the onsets after the first: on the propagation branch
        d_o = abs(o.probes["w0"])
        dd, ll = curves[240]
        if dd[0] <= d_o <= dd[-1]:
            ratios.append(np.interp(d_o, dd, ll) / o.load_factor)
    for row in rows[:1]:  # the envelope against the default mesh's path
        if ratios:
            row["envelope_ratio_min"] = f"{min(ratios):.4f}"
            row["envelope_ratio_max"] = f"{max(ratios):.4f}"
    sc = cohesive_cantilever()  # the 2D path takes smaller steps: up to 400 of them
    sol_2d, seconds = _solve_2d(dataclasses.replace(
        sc, analysis=dataclasses.replace(sc.analysis, max_steps=400)), MEDIUM)
    row_2d = _row("cantilever", sol_2d, seconds, sol_2d.extra["cells"], "2d")
    d, lam, tip = _closed_form(row_2d, sol_2d)
    _pair(beam[0], row_2d, beam[1], sol_2d)
    after = np.flatnonzero(tip > tip[0])[0]
    env = onset_rows(grow(cantilever(step=10.0, max_length=110.0, until=0.5),
                          _medium_2d).history)  # the 2D model's own envelope
    ratios = [np.interp(abs(o.probes["w0"]), d[after:], lam[after:]) / o.load_factor
              for o in env[1:] if d[after] <= abs(o.probes["w0"]) <= d[-1]]
    if ratios:
        row_2d["envelope_ratio_min"] = f"{min(ratios):.4f}"
        row_2d["envelope_ratio_max"] = f"{max(ratios):.4f}"
    return rows + [row_2d]


def _medium_2d(scene, progress=None):
    """The 2D model's solve at level medium, without its mesh estimate."""
    from sandwich.plane2d.solve import solve

    return solve(scene, progress=progress, level=MEDIUM, estimate=False)


def measure_cantilever_2d_fine() -> list[dict]:
    """The 2D cantilever at level fine: its process zone's elements halved from medium's."""
    sc = cohesive_cantilever()
    sol, seconds = _solve_2d(dataclasses.replace(
        sc, analysis=dataclasses.replace(sc.analysis, max_steps=400)), "fine")
    row = _row("cantilever_2d_fine", sol, seconds, sol.extra["cells"], "2d")
    _closed_form(row, sol)
    return [row]


def measure_shipped(case: str) -> list[dict]:
    from sandwich.beam import solve

    name, toughness, sigma_c = SHIPPED[case]
    sc = _cohesive(shipped(name, toughness), sigma_c)
    t0 = time.perf_counter()
    sol = solve(sc)
    row = _row(case, sol, time.perf_counter() - t0, sol.extra["elements"])
    sol_2d, seconds = _solve_2d(sc)
    row_2d = _row(case, sol_2d, seconds, sol_2d.extra["cells"], "2d")
    _pair(row, row_2d, sol, sol_2d)
    known = {r["case"]: r for r in csv.DictReader((OUT / "growth_envelopes.csv").open())}
    if case in known:
        beam = float(known[case]["residual_strength_beam_N"])
        row["crack_length_beam_N"] = f"{beam:.4g}"
        row["crack_length_2d_N"] = f"{float(known[case]['residual_strength_2d_N']):.4g}"
        row["residual_over_crack_length_beam"] = (
            f"{sol.extra['debond_growth']['residual_strength'] / beam:.4f}")
    return [row, row_2d]


def write_md(rows: list[dict]) -> None:
    lines = [
        "# Debond growth by the cohesive law, beam and 2D (`benchmarks/growth_cohesive.py`)",
        "",
        f"Machine: {machine()}. Both models at their defaults (2D: its default level, no mesh "
        "estimate; elements = its cells), run one after the other; see the script's docstring "
        "for the cases. Paired columns on the beam's row: the 2D residual strength over the "
        "beam's, the 2D seconds over the beam's.",
        "Deviation from the closed form: |P / P_closed − 1| while the tip runs from 15 mm past "
        "its start to one process zone before its span's end. Envelope ratio: the cohesive "
        "load at each crack-length onset's deflection over that onset's load (the beam's own "
        "envelope, 10 mm steps). Crack-length columns: `growth_envelopes.csv` (residual "
        "strength; 2D at its level there).",
        "",
        "| " + " | ".join(FIELDS) + " |",
        "|" + "---|" * len(FIELDS),
    ]
    lines += ["| " + " | ".join(str(r.get(k, "")) for k in FIELDS) + " |" for r in rows]
    (OUT / "growth_cohesive.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="*", default=["cantilever", *SHIPPED])
    args = p.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / "growth_cohesive.csv"
    old = list(csv.DictReader(path.open())) if path.exists() else []
    new = []
    for case in args.cases:
        extra = {"cantilever": measure_cantilever,
                 "cantilever_2d_fine": measure_cantilever_2d_fine}
        new += extra[case]() if case in extra else measure_shipped(case)
    rows = [r for r in old if r["case"] not in args.cases] + new
    write_rows(path, FIELDS, rows)
    write_md(rows)
    for r in new:
        print(r)


if __name__ == "__main__":
    main()
