"""Beam G against closed form for uniform core levels and for level patches at the tip.

Why does the beam's G move with the core level (docs/fracture.md "Beam core levels")? For the
closed-form cases of ``benchmarks/cases/fracture_cases.py`` (peel couple, sliding couples,
cantilever face slope), geometrically linear (λ = 1, one linear solve), this measures

- the history columns' estimate (:func:`sandwich.beam.fracture.tip_releases`: closure over
  Δ ≈ the face thickness, round(t/h) tip elements), and the closure of
  :func:`sandwich.beam.fracture.closure_release` over Δ = 1 (the one-element VCCT used until
  2026-12-01), 2, 4, 8 tip elements;
- the energy released by untying the tip node (Clapeyron, two linear solves at fixed load: the
  discrete model's own G over one element, independent of any closure formula),

for uniform core levels 1…6 (``--levels``) and meshes, and for a level-k patch of p elements on
each side of the tip on a level-1 beam (what "auto" does). Writes
``benchmarks/results/fracture/core_levels.md`` (+ ``.csv``; a rerun replaces them). Run from the
project root: ``python -m benchmarks.fracture_core_levels [--out DIR]``.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time

import numpy as np

from benchmarks.cases.fracture_cases import (
    cantilever_slope,
    peel_g,
    peel_loads,
    scene,
    shear_g,
    shear_loads,
)
from benchmarks.provenance import RESULTS, add_out_argument, measured_on
from sandwich.beam import build_model
from sandwich.beam.constraints import NodeSupport, build_dof_map
from sandwich.beam.fracture import beam_tips, closure_release, tip_releases
from sandwich.beam.solve import linear_solution

OUT = RESULTS / "fracture"
CLOSURES = (1, 2, 4, 8)


def _untied(model, sc, node):
    """``model`` with the top tie at ``node`` removed (the debond one node longer)."""
    x = model.mesh.x
    tol = 1e-9 * sc.length
    bonded = {i: np.array([sc.is_bonded(i, float(xx), tol) for xx in x]) for i in ("top", "bottom")}
    bonded["top"][node] = False
    supports = [NodeSupport(model.mesh.node_at(s.x, 1e-6 * sc.length), f, s.type)
                for s in sc.supports for f in s.faces]
    n_paper = 20 * model.mesh.n_nodes
    extra = model.dof_map.free.size - n_paper
    mode_active = (model.dof_map.free[n_paper:] >= 0).reshape(model.mesh.n_nodes,
                                                              extra // model.mesh.n_nodes)
    return dataclasses.replace(model, dof_map=build_dof_map(model.mesh.n_nodes, bonded, supports,
                                                            mode_active))


def measure(sc, levels, elements):
    """(history G, closure G over CLOSURES, extension G) at λ = 1 for ``levels``."""
    model = build_model(sc, elements=elements, core_level=levels)
    tip = beam_tips(sc, model)[0]
    u, _ = linear_solution(model, 1.0)
    closure = [closure_release(model, u, tip, n) for n in CLOSURES]
    g = tip_releases(model, u, [tip])[0]  # the history columns' estimate (Δ ≈ t_face)
    longer = _untied(model, sc, tip.node)
    u2, _ = linear_solution(longer, 1.0)
    work = longer.f_ref @ u2 - model.f_ref @ u  # twice the energy released at fixed load
    return g, closure, work / (2 * sc.width * tip.ahead_length), model, tip


def cases():
    """(name, scene builder(a), closed form(scene) or None for the slope case)."""
    base = scene(peel_loads())
    return [
        ("peel", lambda a, core: scene(peel_loads(), a=a), lambda s: peel_g(s, 1.0)),
        ("sliding", lambda a, core: scene(shear_loads(base), a=a, probe_on="bottom"),
         lambda s: shear_g(s, 1.0)),
        ("cantilever", lambda a, core: scene([("top", 0.0, 1.0)], a=a), None),
    ]


def patch_levels(model_levels_size, tip_node, p, k):
    """Level k on the p elements each side of the tip node, 1 elsewhere."""
    lv = np.ones(model_levels_size, dtype=int)
    lv[max(tip_node - p, 0):tip_node + p] = k
    return lv


def run(args):
    rows = []
    for name, make, exact in cases():
        for config in args.configs:
            kind, *spec = config.split(":")
            for elements in args.elements:
                def levels_for(sc, kind=kind, spec=spec, elements=elements):
                    m = build_model(sc, elements=elements)
                    if kind == "uniform":
                        return int(spec[0])
                    node = beam_tips(sc, m)[0].node
                    return patch_levels(m.mesh.n_elements, node, int(spec[1]), int(spec[0]))

                t0 = time.perf_counter()
                if exact is not None:
                    sc = make(60.0, None)
                    g, cl, ext, model, tip = measure(sc, levels_for(sc), elements)
                    ref = exact(sc)
                    vals = (g.G / ref, *(c.G / ref for c in cl), ext / ref, g.GII / g.G)
                else:  # slope d√G/da between a = 40 and 60 (the root rotation drops out)
                    out = []
                    for a in (40.0, 60.0):
                        sc = make(a, None)
                        g, cl, ext, model, tip = measure(sc, levels_for(sc), elements)
                        out.append((g.G, *(c.G for c in cl), ext, g.GII / g.G))
                    ref = cantilever_slope(sc, 1.0)
                    vals = tuple((np.sqrt(b) - np.sqrt(a)) / 20.0 / ref
                                 for a, b in zip(out[0][:-1], out[1][:-1], strict=True)
                                 ) + (out[1][-1],)
                rows.append({"case": name, "config": config, "elements": elements,
                             "history": vals[0], **{f"closure_{n}": v for n, v in
                                                 zip(CLOSURES, vals[1:-2], strict=True)},
                             "extension": vals[-2], "GII_over_G": vals[-1],
                             "seconds": time.perf_counter() - t0})
                print(rows[-1], flush=True)
    return rows


def write(rows, out=OUT, stamp=""):
    stem = "core_levels"
    out.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    with open(out / f"{stem}.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)
    lines = [f"# Beam G / closed form vs core level ({time.strftime('%Y-%m-%d')}, load "
             f"{os.getloadavg()[0]:.1f})", "",
             "λ = 1, one linear solve. `uniform:k` = level k everywhere; `patch:k:p` = level k "
             "on p elements each side of the tip, 1 elsewhere. "
             "history = the G columns' estimate (closure over Δ ≈ the face thickness, "
             "round(t/h) tip elements); Δ=n = closure over n tip elements (Δ=1: the "
             "one-element VCCT of the G columns until 2026-12-01); "
             "extension = energy of untying the tip node at fixed load (the discrete model's "
             "own G over one element). Cantilever: slope d√G/da / closed form. G_II/G of the "
             "history estimate (at a = 60 for the cantilever).", "", stamp, "",
             "| case | config | el. | history (Δ≈t) | " + " | ".join(f"Δ={n}" for n in CLOSURES)
             + " | extension | G_II/G |",
             "|---" * (6 + len(CLOSURES)) + "|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['config']} | {r['elements']} | {r['history']:.4f} | "
                     + " | ".join(f"{r[f'closure_{n}']:.4f}" for n in CLOSURES)
                     + f" | {r['extension']:.4f} | {r['GII_over_G']:.3f} |")
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--configs", nargs="+", default=[
        "uniform:1", "uniform:2", "uniform:3", "uniform:4", "uniform:6",
        "patch:2:2", "patch:2:5", "patch:2:16", "patch:2:64", "patch:4:5", "patch:4:64"])
    ap.add_argument("--elements", nargs="+", type=int, default=[480])
    add_out_argument(ap, OUT)
    args = ap.parse_args()
    stamp = measured_on()
    write(run(args), args.out, stamp)


if __name__ == "__main__":
    main()
