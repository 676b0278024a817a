"""Sum factorisation of the core levels: one Newton iteration before/after, side by side.

Run from the project root: ``python -m benchmarks.beam_sum_factor [--quick] [--path SCENE ...]
[--out DIR]``. Writes ``benchmarks/results/beam/sum_factor.{md,csv}`` (a rerun replaces them):
per element count (60 … 1920) and core level (1-4, sublayers), at the nonlinear state of
``benchmarks.beam_speed`` (fig. 5 scene, linear solution scaled to 5 mm at mid-span, contact
active), the model's force + tangent with the packed kernel
(``kernels.SUM_FACTORISATION = "never"``, what main had) and with the default (``"auto"``: the
sum-factorised kernel on enriched cores), measured alternately in the same process (best of 3,
wall and thread CPU time), the factorisation and the corrector's two solves (the same for both),
and the flops as executed (:func:`sandwich.beam.kernels.layer_flops`). With ``--path``: the whole
path of each scene at its own settings (``core = "auto"`` by default), both ways, in process
(``summary`` wall seconds), into ``sum_factor_paths.md``.

The machine is shared (2 cores, other jobs): every row records ``uptime``'s load; the CPU-time
column is the less load-sensitive one.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from benchmarks.beam_speed import SCENE, deformed_state, dgemm_rate, load
from benchmarks.provenance import RESULTS, add_out_argument, measured_on
from sandwich.beam import build_model, kernels, run
from sandwich.scene_file import load_scene
from sandwich.solver.envelope import EnvelopeFactorization

OUT = RESULTS / "beam"
MODES = ("never", "auto")  # before (packed kernel everywhere), after (the default)


def _timed(fn, repeat):
    """Best wall and best thread-CPU time of ``repeat`` calls, and the last value."""
    walls, cpus, value = [], [], None
    for _ in range(repeat):
        w, c = time.perf_counter(), time.thread_time()
        value = fn()
        cpus.append(time.thread_time() - c)
        walls.append(time.perf_counter() - w)
    return min(walls), min(cpus), value


def kernel_flops(model) -> float:
    """Flops of the layer kernels per evaluation, of the kernel each layer uses now."""
    return float(sum(els.size * kernels.layer_flops(op)
                     for op, _, els, _ in model.element_families()))


def evaluate(model, u):
    model.forget_evaluations()  # a fresh evaluation: layers and contact kinematics
    return model.tangent(u)


def iteration_rows(cases, repeat):
    scene = load_scene(SCENE)
    rows = []
    for n, level in cases:
        before = load()
        model = build_model(scene, elements=n, core_level=level)
        u = deformed_state(model)
        r = {"elements": model.mesh.n_elements, "level": level, "dofs": model.size}
        times = {m: [np.inf, np.inf] for m in MODES}
        Ks = {}
        for _ in range(repeat):  # alternate: both modes see the same load
            for m in MODES:
                kernels.SUM_FACTORISATION = m
                w, c, Ks[m] = _timed(lambda: evaluate(model, u), 1)  # noqa: B023
                times[m] = [min(times[m][0], w), min(times[m][1], c)]
                r[f"{m}_mflop"] = kernel_flops(model) / 1e6
        kernels.SUM_FACTORISATION = "auto"
        diff = abs(Ks["auto"] - Ks["never"]).max() / abs(Ks["never"]).max()
        t_fac, _, fac = _timed(lambda: model.factorize(Ks["auto"]), repeat)  # noqa: B023
        res = model.internal_force(u) - model.f_ref
        t_sol, _, _ = _timed(lambda: (fac.solve(-res), fac.solve(model.f_ref)),  # noqa: B023
                             repeat)
        env = isinstance(fac, EnvelopeFactorization)
        s = fac.structure if env else None
        r.update({
            "never_wall_s": times["never"][0], "never_cpu_s": times["never"][1],
            "auto_wall_s": times["auto"][0], "auto_cpu_s": times["auto"][1],
            "factorize_s": t_fac, "two_solves_s": t_sol,
            "factor_mflop": s.flops / 1e6 if env else float("nan"),
            "solve_mflop": 2 * (4 * (s.size - s.n) + s.n) / 1e6 if env else float("nan"),
            "tangent_rel_diff": diff, "load_before": before, "load_after": load()})
        rows.append(r)
        print(f"{n:5d} el. level {level}: {model.size:7d} dofs, force+tangent "
              f"{r['never_wall_s'] * 1e3:.2f} → {r['auto_wall_s'] * 1e3:.2f} ms "
              f"(cpu {r['never_cpu_s'] * 1e3:.2f} → {r['auto_cpu_s'] * 1e3:.2f}), "
              f"{r['never_mflop']:.0f} → {r['auto_mflop']:.0f} Mflop, factor "
              f"{t_fac * 1e3:.2f} ms, |ΔK|/|K| {diff:.1e}  [{r['load_after']}]", flush=True)
    return rows


def path_rows(scenes):
    out = []
    for path in scenes:
        scene = load_scene(Path(path))
        for m in MODES:
            kernels.SUM_FACTORISATION = m
            before = load()
            t = time.perf_counter()
            result = run(scene)
            whole = time.perf_counter() - t
            s = result.solution
            out.append({"scene": Path(path).name, "mode": m, "wall_s": s.wall_seconds,
                        "in_process_s": whole, "steps": len(s.history),
                        "iterations": s.extra.get("total_newton_iterations"),
                        "final_load_factor": s.history[-1].load_factor,
                        "load_before": before,
                        "load_after": load()})
            print(out[-1], flush=True)
        kernels.SUM_FACTORISATION = "auto"
    return out


def write(rows, peak, out=OUT, stamp=""):
    out.mkdir(parents=True, exist_ok=True)
    keys = [k for k in rows[0] if not k.startswith("load")]
    (out / "sum_factor.csv").write_text(",".join(keys) + "\n" + "".join(
        ",".join(f"{r[k]:.6g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + "\n"
        for r in rows))
    md = [
        "Sum factorisation of the enriched core (`sandwich/beam/sum_factor.py`), measured by "
        "`benchmarks/beam_sum_factor.py`. One Newton iteration of the fig. 5 scene (state: "
        "linear solution scaled to 5 mm at mid-span, contact active; core levels of the "
        "`sublayers` basis everywhere): force + consistent tangent assembled into the free "
        "DOFs, *before* = the packed kernel on every layer (`kernels.SUM_FACTORISATION = "
        "\"never\"`, what main had), *after* = the default (`\"auto\"`: the sum-factorised "
        "kernel on enriched cores, level ≥ 2; level 1 and the faces keep the packed kernel), "
        "measured alternately in one process, best of 3; then the envelope LDLᵀ and the two "
        "solves (the same matrix both ways). Flops as executed: the kernels' GEMMs and "
        "contractions (strains, stresses, scatter not counted), factorisation, solves. "
        f"DGEMM rate measured in the same run: {peak / 1e9:.1f} GF/s.",
        "",
        stamp,
        "",
        f"**Shared machine, 2 cores: {rows[0]['load_before']} at the start, "
        f"{rows[-1]['load_after']} at the end.** Wall times are inflated by the other jobs; "
        "thread CPU time (`time.thread_time`) is less so. |ΔK|/|K|: largest entry of the "
        "difference of the two tangents over the largest entry (round-off).",
        "",
        "| elements | level | free DOFs | force+tangent before (ms) | after (ms) | speed-up | "
        "CPU before (ms) | CPU after (ms) | CPU speed-up | kernel Mflop before | after | "
        "factorisation (ms) | 2 solves (ms) | iteration before (ms) | after (ms) | speed-up | "
        "GF/s after | |ΔK|/|K| |",
        "|" + "---:|" * 18,
    ]
    for r in rows:
        it_b = r["never_wall_s"] + r["factorize_s"] + r["two_solves_s"]
        it_a = r["auto_wall_s"] + r["factorize_s"] + r["two_solves_s"]
        fl = r["auto_mflop"] + r["factor_mflop"] + r["solve_mflop"]
        md.append(
            f"| {r['elements']} | {r['level']} | {r['dofs']} | {r['never_wall_s'] * 1e3:.2f} | "
            f"{r['auto_wall_s'] * 1e3:.2f} | {r['never_wall_s'] / r['auto_wall_s']:.2f} | "
            f"{r['never_cpu_s'] * 1e3:.2f} | {r['auto_cpu_s'] * 1e3:.2f} | "
            f"{r['never_cpu_s'] / r['auto_cpu_s']:.2f} | {r['never_mflop']:.1f} | "
            f"{r['auto_mflop']:.1f} | {r['factorize_s'] * 1e3:.2f} | "
            f"{r['two_solves_s'] * 1e3:.2f} | {it_b * 1e3:.2f} | {it_a * 1e3:.2f} | "
            f"{it_b / it_a:.2f} | {fl / 1e3 / it_a:.1f} | {r['tangent_rel_diff']:.1e} |")
    (out / "sum_factor.md").write_text("\n".join(md) + "\n")


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="60 and 240 elements only")
    p.add_argument("--path", nargs="*", default=[], help="scenes to run whole paths of")
    p.add_argument("--no-iterations", action="store_true", help="only the paths")
    add_out_argument(p, OUT)
    args = p.parse_args()
    stamp = measured_on()
    counts = [60, 240] if args.quick else [60 * 2**k for k in range(6)]  # 60 … 1920
    cases = [(n, level) for level in (1, 2, 3, 4) for n in counts]
    peak = dgemm_rate()
    if not args.no_iterations:
        write(iteration_rows(cases, repeat=3), peak, args.out, stamp)
    if args.path:
        stamp = measured_on()
        write_paths(path_rows(args.path), args.out, stamp)


def write_paths(paths, out=OUT, stamp=""):
    """The whole-path table, ``sum_factor_paths.md``."""
    md = ["Whole paths in process (`sandwich.beam.run`, each scene's own settings: `core = "
          "\"auto\"` unless the scene says otherwise), before (packed kernel everywhere, "
          "`never`) and after (`auto`), one run each, in this order. Solve wall = "
          "`summary.json` `wall_seconds`. Shared 2-core machine: the load is given per run.", "",
          stamp, "",
          "| scene | kernel | solve wall (s) | in process (s) | steps | Newton its | final λ | "
          "load before | load after |", "|---|---|---:|---:|---:|---:|---:|---|---|"]
    for p in paths:
        md.append(f"| {p['scene']} | {p['mode']} | {p['wall_s']:.2f} | {p['in_process_s']:.2f} | "
                  f"{p['steps']} | {p['iterations']} | {p['final_load_factor']:.12g} | "
                  f"{p['load_before']} | {p['load_after']} |")
    out.mkdir(parents=True, exist_ok=True)
    (out / "sum_factor_paths.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    main()
