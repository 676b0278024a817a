"""Averaged face membrane compiled (sandwich/beam/averaged_kernel.py) vs its NumPy path.

Run from the project root: ``python -m benchmarks.beam_face_kernel [--repeat 3] [--out DIR]``.
Writes ``benchmarks/results/beam/face_kernel.md``:

- per Newton iteration, at the fig. 5 scene's defaults (stretch faces, ``face_membrane =
  "averaged"``, closest-point contact), 240 elements, core levels 1 and 2, at a nonlinear state
  (linear solution scaled to 5 mm at mid-span): CPU seconds of the two face layers' force +
  tangent (assembled into the reduced CSR values) and of the whole force + tangent evaluation,
  with the faces' kernel time at ``face_membrane = "paper"`` (same faces otherwise) for scale;
- whole paths (``sandwich.beam.run``, CPU seconds, warm): fig. 5 at core levels 1 and 2 and at
  the scene's default ``core = "auto"``, fig. 4 at its defaults; end λ and Newton iterations.

"before" is the code path main had for these layers: :func:`sandwich.beam.kernels.supports`
returning False for ``membrane_average`` layers, so the model evaluates them by
:mod:`sandwich.beam.element` (NumPy) and scatters the blocks; "after" is the compiled kernel.
Both run in this process, alternately; times are best of ``--repeat``. Every table records
``uptime``'s load (2-core machine shared with other jobs).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from contextlib import contextmanager
from functools import partial

import numpy as np

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.beam import build_model, kernels, run
from sandwich.beam.element import layer_state, layer_tangent
from sandwich.scene_file import load_scene

OUT = RESULTS / "beam"
FIG5 = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"
FIG4 = ROOT / "scenes" / "paper-fig4-bonded-3pb.toml"
_SUPPORTS = kernels.supports


def load() -> str:
    """``uptime``'s load averages (1, 5, 15 min)."""
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + \
        f" ({os.cpu_count()} cores)"


@contextmanager
def numpy_faces(before: bool):
    """With ``before``: averaged layers by the NumPy path, as on main."""
    if before:
        kernels.supports = lambda op: not op.membrane_average
    try:
        yield
    finally:
        kernels.supports = _SUPPORTS


def cpu_best(fn, repeat):
    """Best CPU time (process_time: all threads) of ``repeat`` calls, and the last value."""
    best, value = float("inf"), None
    for _ in range(repeat):
        t = time.process_time()
        value = fn()
        best = min(best, time.process_time() - t)
    return best, value


def deformed_state(model):
    """Linear solution scaled to w_top_mid = −5 mm (contact active on the debond)."""
    u = model.factorize(model.tangent(np.zeros(model.size))).solve(model.f_ref)
    return u * (-5.0 / (model.probe_vector("w_top_mid") @ u))


def face_evaluation(model, u_full, before):
    """Force + tangent of the two face families as :meth:`BeamModel._compiled_forces` does."""
    slots = model.pattern.family_slots
    data = np.zeros(model.pattern.indices.size)
    lengths = model.mesh.lengths
    for i, (op, products, els, dofs) in enumerate(model.element_families()):
        if op.name not in ("top", "bottom"):
            continue
        if not before:
            kernels.layer_assemble(op, u_full[dofs], lengths[els], model.width, *slots[i], data)
            continue
        u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
        u_e[:, op.dofs] = u_full[dofs]
        st = layer_state(op, u_e, lengths[els], model.width)
        kernels.scatter_blocks(layer_tangent(op, st, products), *slots[i], data)
    return data


def full_evaluation(model, u):
    model.forget_evaluations()  # a fresh evaluation: layers and contact kinematics
    return model.tangent(u)


def iteration_rows(levels, elements, repeat):
    scene = load_scene(FIG5)
    rows = []
    for level in levels:
        model = build_model(scene, elements=elements, core_level=level)
        assert model.layers["top"].membrane_average and model.layers["top"].stretch
        u = deformed_state(model)
        u_full = model.expand(u)
        row = {"level": level, "elements": model.mesh.n_elements, "dofs": model.size}
        K = {}
        for before in (True, False, True, False):  # alternate: load drifts
            tag = "before" if before else "after"
            with numpy_faces(before):
                face_evaluation(model, u_full, before)  # warm
                t_face, _ = cpu_best(partial(face_evaluation, model, u_full, before), repeat)
                t_all, K[tag] = cpu_best(partial(full_evaluation, model, u), repeat)
            row[f"face_{tag}"] = min(row.get(f"face_{tag}", np.inf), t_face)
            row[f"all_{tag}"] = min(row.get(f"all_{tag}", np.inf), t_all)
        row["K_rel"] = abs(K["after"] - K["before"]).max() / abs(K["before"]).max()
        paper = build_model(scene, elements=elements, core_level=level, face_membrane="paper")
        u_paper = paper.expand(deformed_state(paper))
        face_evaluation(paper, u_paper, False)
        row["face_paper"] = cpu_best(partial(face_evaluation, paper, u_paper, False), repeat)[0]
        row["load"] = load()
        rows.append(row)
        print(row, flush=True)
    return rows


def path_rows(cases, repeat):
    rows = []
    for label, path, core in cases:
        scene = load_scene(path)
        if core is not None:
            scene = dataclasses.replace(
                scene, beam_model=dataclasses.replace(scene.beam_model, core=core))
        row = {"path": label}
        for before in (True, False):
            tag = "before" if before else "after"
            with numpy_faces(before):
                t, r = cpu_best(lambda s=scene: run(s), repeat)
            row[f"cpu_{tag}"] = t
            row[f"lam_{tag}"] = r.states[-1].load_factor
            row[f"its_{tag}"] = sum(s.iterations for s in r.states)
            row[f"steps_{tag}"] = len(r.states) - 1
        row["load"] = load()
        rows.append(row)
        print(row, flush=True)
    return rows


def write(it_rows, p_rows, elements, repeat, out=OUT, stamp=""):
    out.mkdir(parents=True, exist_ok=True)
    md = [stamp, "",
        "Averaged face membrane (`face_membrane = \"averaged\"`, the default, with the stretch "
        "faces) evaluated by the compiled kernel (`sandwich/beam/averaged_kernel.py`, after) "
        "against the NumPy path main used for it (`sandwich/beam/element.py`, before), in one "
        f"process, alternately. CPU seconds (`time.process_time`), best of {repeat}. "
        "Written by `benchmarks/beam_face_kernel.py`.",
        "",
        f"## One Newton iteration, fig. 5 scene, {elements} elements (state: 5 mm at mid-span)",
        "",
        "| core level | DOFs | faces force+tangent before (ms) | after (ms) | speed-up | "
        "paper membrane, kernel (ms) | whole force+tangent before (ms) | after (ms) | speed-up | "
        "max |ΔK|/max |K| | load |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in it_rows:
        md.append(
            f"| {r['level']} | {r['dofs']} | {r['face_before'] * 1e3:.2f} | "
            f"{r['face_after'] * 1e3:.3f} | {r['face_before'] / r['face_after']:.1f}× | "
            f"{r['face_paper'] * 1e3:.3f} | "
            f"{r['all_before'] * 1e3:.2f} | {r['all_after'] * 1e3:.2f} | "
            f"{r['all_before'] / r['all_after']:.1f}× | {r['K_rel']:.1e} | {r['load']} |")
    md += ["", "## Whole paths (`sandwich.beam.run`, warm, CPU s)", "",
           "| path | CPU before (s) | CPU after (s) | speed-up | steps | "
           "Newton its (before/after) | λ end before | λ end after | relative Δλ | load |",
           "|---|---:|---:|---:|---:|---|---:|---:|---:|---|"]
    for r in p_rows:
        d = abs(r["lam_after"] - r["lam_before"]) / abs(r["lam_before"])
        md.append(
            f"| {r['path']} | {r['cpu_before']:.3f} | {r['cpu_after']:.3f} | "
            f"{r['cpu_before'] / r['cpu_after']:.2f}× | {r['steps_after']} | "
            f"{r['its_before']}/{r['its_after']} | {r['lam_before']:.10f} | "
            f"{r['lam_after']:.10f} | {d:.1e} | {r['load']} |")
    (out / "face_kernel.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--elements", type=int, default=240)
    add_out_argument(p, OUT)
    args = p.parse_args()
    stamp = measured_on()
    it_rows = iteration_rows((1, 2), args.elements, args.repeat)
    cases = [("fig. 5, core level 1", FIG5, 1), ("fig. 5, core level 2", FIG5, 2),
             ("fig. 5, defaults (core auto)", FIG5, None), ("fig. 4, defaults", FIG4, None)]
    run(load_scene(FIG4))  # warm-up: numba cache load, imports
    p_rows = path_rows(cases, args.repeat)
    write(it_rows, p_rows, args.elements, args.repeat, args.out, stamp)


if __name__ == "__main__":
    main()
