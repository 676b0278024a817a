"""Beam model speed: one Newton iteration (60 … 7680 elements, core levels 1-4) and the fig. 5 path.

Run from the project root: ``python -m benchmarks.beam_speed [--quick] [--no-2d]
[--convergence] [--out DIR]``. Writes under ``benchmarks/results/beam/`` (a rerun replaces the
tables; each says the machine and date it was measured on) or ``DIR``:

- ``newton_iteration.{csv,md,png}``: one Newton iteration = internal force and tangent (eqs. 19,
  24-25 + contact, assembled into the eliminated DOFs, one pass) + factorisation + the two
  solves the corrector makes (δu_r, δu_f), at a nonlinear state of the paper's fig. 5 scene
  (the level-1 path's converged state at 5 mm mid-span deflection, past the limit point,
  contact active; carried into levels 2-4), per element count and core level, with the flop
  count and the fraction of this machine's measured DGEMM rate;
- ``fig5_speed.md``: the fig. 5 full path at the default settings, compiled path against the
  NumPy/SuperLU reference path in the same process (warm, best of 3), the whole CLI process,
  and the 2D coarse and medium runs on the same path (CLI, ``summary.json`` ``wall_seconds``);
- with ``--convergence``: ``fig5_path.md``, λ(−15 mm) against the element count.

The machine is shared (2 cores, other jobs running): every table records ``uptime``'s load.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import os
import statistics
import subprocess
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np

from benchmarks.installed import write_bytecode
from benchmarks.provenance import RESULTS, ROOT, add_out_argument, console_script, measured_on
from sandwich.beam import build_model, kernels, run
from sandwich.beam.core_levels import transfer
from sandwich.beam.model import BeamModel
from sandwich.beam.solve import scene_model_options
from sandwich.scene_file import load_scene
from sandwich.solver.envelope import EnvelopeFactorization
from sandwich.solver.jit import kernel_backend
from sandwich.solver.newton import _solve_both
from sandwich.solver.sparse import SparseFactorization

OUT = RESULTS / "beam"
SCENE = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def load() -> str:
    """``uptime``'s load averages (1, 5, 15 min) on this 2-core machine."""
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + \
        f" ({os.cpu_count()} cores)"


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - t)
    return min(times), value


def dgemm_rate() -> float:
    """Measured single-thread DGEMM rate (flop/s), this machine's attainable peak."""
    a, b = np.random.rand(1500, 1500), np.random.rand(1500, 1500)
    a @ b
    t, _ = best_of(lambda: a @ b, 3)
    return 2 * 1500**3 / t


def evaluate(model, u):
    model.forget_evaluations()  # a fresh evaluation: layers and contact kinematics
    return model.tangent(u)


def kernel_flops(model) -> float:
    """Flops of the layer kernels per evaluation (force + tangent), as executed.

    The packed kernel's GEMMs (``kernels.point_flops``) or, for the layers the sum-factorised
    kernel evaluates (core levels 2-4), its two stages (``kernels.layer_flops``).
    """
    return float(sum(els.size * kernels.layer_flops(op)
                     for op, _, els, _ in model.element_families()))


def deformed_state(model):
    """Linear solution scaled to w_top_mid = −5 mm (contact active on the debond).

    Not an equilibrium: on fine meshes its compressed debonded face has thousands of negative
    eigenvalues (3840 elements: 2439) and the pivot-free LDLᵀ is refused there. The iteration
    table uses :func:`path_state` instead; the kernel-only benchmarks keep this one.
    """
    fac0 = model.factorize(model.tangent(np.zeros(model.size)))
    u = fac0.solve(model.f_ref)
    return u * (-5.0 / (model.probe_vector("w_top_mid") @ u))


SMALL_DOFS = 20000  # below: best of 5 × repeat (an iteration of a few ms is noisier)
PATH_TARGET = -5.0  # mm at mid-span: past fig. 5's limit point, contact active on the debond


@functools.cache
def _path_end(n: int):
    """The fig. 5 path at level 1, ``n`` elements, followed to w_top_mid = PATH_TARGET."""
    scene = paper_scene(n)
    scene = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                    until_value=PATH_TARGET))
    r = run(scene)
    if not r.solution.converged:
        raise RuntimeError(f"{n} elements: the path stopped short: {r.solution.message}")
    return r.model, r.states[-1].u


def path_state(model):
    """The converged level-1 state at w_top_mid = PATH_TARGET on ``model``'s mesh, carried
    into ``model``'s core levels (enrichment amplitudes the level-1 model lacks: zero)."""
    src, u = _path_end(model.mesh.n_elements)
    return transfer(u, src, model)


def newton_iteration_times(cases, repeat):
    scene = load_scene(SCENE)
    rows = []
    for n, level in cases:
        model = build_model(scene, elements=n, core_level=level, **scene_model_options(scene))
        u = path_state(model)
        repeat_here = repeat * (5 if model.size < SMALL_DOFS else 1)  # ms-scale: more tries
        t_eval, K = best_of(partial(evaluate, model, u), repeat_here)
        model.factorisations.structures.clear()  # the symbolic part as a path builds it
        model.factorize(K)
        t_fac, fac = best_of(partial(model.factorize, K), repeat_here)
        r = model.internal_force(u) - model.f_ref
        # as the corrector asks for them: one call where the factorisation takes both
        t_sol, _ = best_of(lambda: _solve_both(fac, -r, model.f_ref),  # noqa: B023
                           repeat_here)
        env = isinstance(fac, EnvelopeFactorization)
        s = fac.structure if env else None
        f_kernel = kernel_flops(model)
        f_fac = s.flops if env else float("nan")
        f_sol = 2 * (4 * (s.size - s.n) + s.n) if env else float("nan")
        it = t_eval + t_fac + t_sol
        rows.append({"elements": model.mesh.n_elements, "level": level, "dofs": model.size,
                     "half_bandwidth": s.half_bandwidth if env else -1,
                     "force_tangent_s": t_eval, "factorize_s": t_fac, "two_solves_s": t_sol,
                     "iteration_s": it, "kernel_mflop": f_kernel / 1e6,
                     "factor_mflop": f_fac / 1e6, "solve_mflop": f_sol / 1e6,
                     "gflops": (f_kernel + f_fac + f_sol) / it / 1e9,
                     "backend": "envelope" if env else "superlu"})
        print(f"{n:5d} el. level {level}: {model.size:7d} dofs, eval {t_eval * 1e3:.2f} ms, "
              f"factor {t_fac * 1e3:.2f} ms, solves {t_sol * 1e3:.2f} ms, "
              f"{rows[-1]['gflops']:.1f} GF/s  [{load()}]", flush=True)
    return rows


def reference_iteration(n, repeat):
    """The NumPy element path + SuperLU at ``n`` elements (what main had)."""
    scene = load_scene(SCENE)
    model = build_model(scene, elements=n, **scene_model_options(scene))
    model.use_kernels = False
    u = path_state(model)
    t_eval, K = best_of(partial(evaluate, model, u), repeat)
    t_fac, fac = best_of(partial(SparseFactorization, K), repeat)
    r = model.internal_force(u) - model.f_ref
    t_sol, _ = best_of(lambda: (fac.solve(-r), fac.solve(model.f_ref)), repeat)
    return t_eval, t_fac, t_sol


def paper_scene(elements: int | None = None):
    """The fig. 5 scene with the paper's core (level 1; the scene default is now "auto")."""
    scene = load_scene(SCENE)
    options = dataclasses.replace(scene.beam_model, core=1)
    if elements is not None:
        options = dataclasses.replace(options, elements=elements)
    return dataclasses.replace(scene, beam_model=options)


def in_process_path(reference: bool, repeat: int, elements: int | None = None,
                    auto: bool = False):
    """fig. 5 full path in this process (warm), compiled or NumPy/SuperLU: best wall, result.

    ``auto``: the scene as shipped (``core = "auto"``), else the paper's core (level 1).
    """
    scene = load_scene(SCENE) if auto else paper_scene(elements)
    saved = BeamModel.use_kernels, BeamModel.factorize
    if reference:
        BeamModel.use_kernels = False
        BeamModel.factorize = lambda self, K: SparseFactorization(K)
    try:
        run(scene)  # warm-up (compilation / cache load, imports)
        best, result = None, None
        for _ in range(repeat):
            r = run(scene)
            if best is None or r.solution.wall_seconds < best:
                best, result = r.solution.wall_seconds, r.solution
    finally:
        BeamModel.use_kernels, BeamModel.factorize = saved
    return best, result


def cli_run(model: str, repeat: int, auto: bool = False, level: str | None = None,
            kernels: str | None = None):
    """``sandwich solve`` as a user runs it: whole-process time and summary.json wall_seconds.

    The beam runs a copy of the scene with ``[beam_model] core = 1`` (the paper's core), or
    the scene as shipped with ``auto``; the 2D model at mesh ``level`` (``--level``; None: the
    scene's, which for fig. 5 is the default ``"medium"``). ``kernels="jit"``: numba's JIT
    instead of the ahead-of-time build (``SANDWICH_KERNELS``, sandwich/solver/jit.py).
    """
    env = {k: v for k, v in os.environ.items() if k != "SANDWICH_KERNELS"}
    if kernels is not None:
        env["SANDWICH_KERNELS"] = kernels
    out = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as tmp:
            scene = Path(tmp) / SCENE.name
            extra = "" if auto or model != "beam" else "\n[beam_model]\ncore = 1\n"
            scene.write_text(SCENE.read_text() + extra)
            t = time.perf_counter()
            level_args = [] if level is None else ["--level", level]
            p = subprocess.run([str(console_script("sandwich")), "solve", str(scene),
                                "--model", model, "--quiet", "--out", tmp, *level_args],
                               capture_output=True, text=True, cwd=ROOT, env=env)
            whole = time.perf_counter() - t
            if p.returncode != 0:
                raise RuntimeError(p.stderr)
            summary = json.loads((Path(tmp) / "summary.json").read_text())
        out.append((whole, summary))
    return min(out, key=lambda x: x[0])


PAIRS = 7  # paired beam/2D coarse runs of fig5_speed


def paired_ratios(n: int) -> list[dict[str, float]]:
    """``n`` pairs of CLI runs, the beam (paper's core) then 2D coarse, one after the other.

    Each pair's ratio is of two runs a few seconds apart, so a load change between the two
    models' best-of runs above does not enter it.
    """
    out = []
    for _ in range(n):
        wb, sb = cli_run("beam", 1)
        w2, s2 = cli_run("2d", 1, level="coarse")
        out.append({"beam_solve": sb["wall_seconds"], "beam_whole": wb,
                    "2d_solve": s2["wall_seconds"], "2d_whole": w2})
        print(f"pair: beam {sb['wall_seconds']:.3f} s, 2D coarse {s2['wall_seconds']:.2f} s, "
              f"{s2['wall_seconds'] / sb['wall_seconds']:.1f}×", flush=True)
    return out


def fig5_speed(repeat, with_2d):
    write_bytecode()  # the CLI runs start from the installed state (benchmarks/installed.py)
    stamp = measured_on()
    before = load()
    t_new, s_new = in_process_path(False, repeat)
    t_ref, s_ref = in_process_path(True, repeat)
    t_480, s_480 = in_process_path(False, repeat, elements=480)
    t_auto, s_auto = in_process_path(False, 1, auto=True)
    whole, summary = cli_run("beam", repeat)
    whole_jit, summary_jit = cli_run("beam", repeat, kernels="jit")
    whole_auto, summary_auto = cli_run("beam", 1, auto=True)
    # 2D coarse and the scene's own level (medium): until 2026-12-02 this table's "2D coarse"
    # row ran the scene's level without --level, i.e. 2D medium, under the coarse label
    two_d = {lvl: cli_run("2d", 1, level=lvl) for lvl in ("coarse", "medium")} if with_2d else {}
    pairs = paired_ratios(PAIRS) if with_2d else []
    after = load()
    lam_new, lam_ref = s_new.history[-1].load_factor, s_ref.history[-1].load_factor
    kb = kernel_backend()
    backend = ("ahead-of-time build" if kb["backend"] == "aot"
               else f"numba JIT — {kb['reason']}")
    lines = [
        "fig. 5 full path (paper-fig5-top-debond-40-load-top to w_top_mid = -15 mm, arc-length, "
        "240 elements, the scene's element choices — stretch faces, averaged face membrane, "
        "closest-point contact): with the paper's core (`[beam_model] core = 1`) and as "
        "shipped (`core = \"auto\"`: core levels chosen and checked by passes of the path and "
        "end-state checks; fig. 5: two passes, two checks).",
        "",
        stamp,
        "",
        f"2 cores: {before} before, {after} after (this benchmark's own runs included; "
        "other jobs, if any, inflate the times). Times are best of the runs.",
        "",
        "| run | solve wall (s) | whole process (s) | steps | Newton its | λ(−15 mm) | "
        "negative pivots seen |",
        "|---|---:|---:|---:|---:|---:|---|",
        f"| compiled kernels + envelope LDLᵀ (in process, warm) | {t_new:.3f} | – | "
        f"{len(s_new.history)} | {s_new.extra['total_newton_iterations']} | {lam_new:.10g} | "
        f"{len(s_new.limit_points)} limit/bifurcation point(s) |",
        f"| NumPy reference + SuperLU (in process, warm) | {t_ref:.3f} | – | "
        f"{len(s_ref.history)} | {s_ref.extra['total_newton_iterations']} | {lam_ref:.10g} | "
        f"{len(s_ref.limit_points)} |",
        f"| compiled, 480 elements (within 0.5 % of the mesh limit, `fig5_path.md`) | "
        f"{t_480:.3f} | – | {len(s_480.history)} | "
        f"{s_480.extra['total_newton_iterations']} | {s_480.history[-1].load_factor:.10g} | "
        f"{len(s_480.limit_points)} |",
        f"| `sandwich solve --model beam` (CLI, kernels: {backend}) | "
        f"{summary['wall_seconds']:.3f} | {whole:.2f} | {summary['steps']} | "
        f"{summary['total_newton_iterations']} | {summary['final_load_factor']:.10g} | – |",
        f"| the same with numba's JIT (`SANDWICH_KERNELS=jit`, warm numba cache) | "
        f"{summary_jit['wall_seconds']:.3f} | {whole_jit:.2f} | {summary_jit['steps']} | "
        f"{summary_jit['total_newton_iterations']} | "
        f"{summary_jit['final_load_factor']:.10g} | – |",
        f"| as shipped, `core = \"auto\"` (in process, warm) | {t_auto:.3f} | – | "
        f"{len(s_auto.history)} | {s_auto.extra['total_newton_iterations']} | "
        f"{s_auto.history[-1].load_factor:.10g} | {len(s_auto.limit_points)} |",
        f"| as shipped, `core = \"auto\"` (CLI) | {summary_auto['wall_seconds']:.3f} | "
        f"{whole_auto:.2f} | {summary_auto['steps']} | "
        f"{summary_auto['total_newton_iterations']} | "
        f"{summary_auto['final_load_factor']:.10g} | – |",
    ]
    for lvl, (w2, s2) in two_d.items():
        lines.append(f"| `sandwich solve --model 2d --level {lvl}` (CLI) | "
                     f"{s2['wall_seconds']:.3f} | {w2:.2f} | {s2['steps']} | – | "
                     f"{s2['final_load_factor']:.10g} | – |")
    lines += ["", f"Speed-up of the solve, compiled vs reference: {t_ref / t_new:.1f}×; "
              f"λ(−15 mm) differs by {abs(lam_new / lam_ref - 1):.1e} (relative)."]
    for lvl, (w2, s2) in two_d.items():
        lines.append(f"Beam (CLI solve) vs 2D {lvl} (CLI solve): "
                     f"{s2['wall_seconds'] / summary['wall_seconds']:.1f}× on solve wall, "
                     f"{w2 / whole:.1f}× on whole process (paper's core); "
                     f"{s2['wall_seconds'] / summary_auto['wall_seconds']:.2f}× and "
                     f"{w2 / whole_auto:.2f}× as shipped (auto).")
    if pairs:
        solve = sorted(p["2d_solve"] / p["beam_solve"] for p in pairs)
        whole_r = sorted(p["2d_whole"] / p["beam_whole"] for p in pairs)
        lines += [
            "",
            f"**Paired runs** (the 15× target decided on the run-to-run spread, not on one "
            f"pair): {len(pairs)} pairs, each a `sandwich solve` of the beam (paper's core) "
            "right before one of 2D coarse, so that both see the same machine state. 2D coarse "
            f"/ beam on solve wall: median **{statistics.median(solve):.1f}×**, range "
            f"{solve[0]:.1f}-{solve[-1]:.1f}×, ≥ 15× in {sum(r >= 15 for r in solve)} of "
            f"{len(solve)} pairs; on whole process: median {statistics.median(whole_r):.1f}×, "
            f"range {whole_r[0]:.1f}-{whole_r[-1]:.1f}×. Beam solve wall "
            f"{min(p['beam_solve'] for p in pairs):.3f}-{max(p['beam_solve'] for p in pairs):.3f}"
            f" s, 2D coarse {min(p['2d_solve'] for p in pairs):.2f}-"
            f"{max(p['2d_solve'] for p in pairs):.2f} s.",
        ]
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "fig5_speed.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def write_iterations(rows, reference, peak, before, after, stamp):
    OUT.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    (OUT / "newton_iteration.csv").write_text(
        ",".join(keys) + "\n" + "".join(
            ",".join(f"{r[k]:.6g}" if isinstance(r[k], float) else str(r[k]) for k in keys)
            + "\n" for r in rows))
    md = [
        "One Newton iteration of the beam model on the fig. 5 scene (state: the converged "
        f"state of the level-1 path at w_top_mid = {PATH_TARGET:g} mm on the same mesh, past "
        "the limit point, contact active, carried into levels 2-4 with zero enrichment "
        "amplitudes): internal force + consistent tangent "
        "assembled into the free DOFs in one pass (numba kernels, `sandwich/beam/kernels.py`), "
        "the contact pairs' closest-point projections included (computed afresh at every "
        "evaluation, as at a new iterate; until 2026-12-05 the repeated evaluations of one "
        "state reused them, ≈ 0.12 ms at 240 elements that the table left out), "
        "envelope LDLᵀ with inertia (`sandwich/solver/envelope/`), and the corrector's two "
        f"solves. Best of 15 below {SMALL_DOFS} free DOFs, else of 3. Flops: the kernels' "
        "GEMMs (strains/stresses and scatter not counted), the factorisation and the solves, "
        "exactly as executed. Peak: this machine's "
        f"measured single-thread DGEMM rate, {peak / 1e9:.1f} GF/s.",
        "",
        stamp,
        "",
        f"2 cores: {before} at the start, {after} at the end (this benchmark's own work "
        "included; other jobs, if any, inflate the times).",
        "",
        "The factorisation's backend: `envelope` (the pivot-free LDLᵀ, half-band of its "
        "structure) or `superlu` — the stated fallback, taken when the LDLᵀ is untrustworthy "
        "(a pivot below `singular_rtol · n · max|K|` or growth above the limit; its flops are "
        "not counted: `nan`). Until 2026-12-04 the state was the linear solution scaled to "
        "5 mm, which is not an equilibrium: on fine meshes its compressed debonded face had "
        "thousands of negative eigenvalues (3840 elements: 2439), the LDLᵀ was refused from "
        "3840 elements on and SuperLU took over (7680 elements, level 1: 0.77 s per "
        "iteration); no state of the path does that.",
        "",
        "| elements | core level | free DOFs | backend | half-band | force+tangent (ms) | "
        "factorisation (ms) | 2 solves (ms) | iteration (ms) | Mflop | GF/s | % of peak | "
        "per element (µs) |",
        "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        fl = r["kernel_mflop"] + r["factor_mflop"] + r["solve_mflop"]
        md.append(
            f"| {r['elements']} | {r['level']} | {r['dofs']} | {r['backend']} | "
            f"{r['half_bandwidth'] if r['backend'] == 'envelope' else '–'} | "
            f"{r['force_tangent_s'] * 1e3:.2f} | {r['factorize_s'] * 1e3:.2f} | "
            f"{r['two_solves_s'] * 1e3:.3f} | {r['iteration_s'] * 1e3:.2f} | {fl:.1f} | "
            f"{r['gflops']:.1f} | {100 * r['gflops'] * 1e9 / peak:.0f} | "
            f"{r['iteration_s'] / r['elements'] * 1e6:.1f} |")
    if reference is not None:
        n, (te, tf, ts) = reference
        mine = next(r for r in rows if r["elements"] == n and r["level"] == 1)
        md += ["", f"Reference (NumPy element path + SuperLU, as on main before this work) at "
               f"{n} elements, level 1, same state and load: force+tangent {te * 1e3:.2f} ms, "
               f"factorisation {tf * 1e3:.2f} ms, 2 solves {ts * 1e3:.3f} ms, iteration "
               f"{(te + tf + ts) * 1e3:.2f} ms: {(te + tf + ts) / mine['iteration_s']:.1f}× "
               "slower."]
    (OUT / "newton_iteration.md").write_text("\n".join(md) + "\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    for level in sorted({r["level"] for r in rows}):
        sel = [r for r in rows if r["level"] == level]
        ax.loglog([r["elements"] for r in sel], [r["iteration_s"] for r in sel], "o-",
                  label=f"core level {level}")
    sel = [r for r in rows if r["level"] == 1]
    n = np.array([r["elements"] for r in sel])
    ax.loglog(n, sel[0]["iteration_s"] * n / n[0], "k:", label="linear growth")
    ax.set_xlabel("elements")
    ax.set_ylabel("time per Newton iteration (s)")
    ax.set_title(f"beam model, fig. 5 scene ({before.split(' (')[0]})")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "newton_iteration.png", dpi=120)


def fig5_path(counts):
    """Full fig. 5 path at each element count (default graded mesh): one row per count."""
    out = []
    for n in counts:
        scene = paper_scene()
        t = time.perf_counter()
        r = run(scene, elements=n)
        wall = time.perf_counter() - t
        s = r.solution
        lam = s.history[-1].load_factor
        out.append((s.extra["elements"], wall, len(s.history), s.extra["total_newton_iterations"],
                    lam, s.converged, s.extra["max_penetration"]))
        print(f"fig5 {n}: {wall:.2f} s, {len(s.history)} steps, λ = {lam:.6g}", flush=True)
    return out


def richardson_limit(path_rows):
    """Mesh limit of λ(−15 mm) by Aitken's Δ² on the last three counts (each twice the last).

    Also returns the observed order p = log2 of the ratio of successive differences.
    """
    (n1, *_, l1), (n2, *_, l2), (n3, *_, l3) = [(r[0], r[4]) for r in path_rows[-3:]]
    if not (n2 == 2 * n1 and n3 == 2 * n2):
        raise ValueError("the last three element counts must double")
    d1, d2 = l1 - l2, l2 - l3
    if d1 == d2 or d1 * d2 <= 0:
        return l3, float("nan")  # not in the asymptotic range: no extrapolation
    return l3 - d2 * d2 / (d1 - d2), float(np.log2(d1 / d2))


def write_convergence(path_rows, stamp):
    ref, order = richardson_limit(path_rows)
    md = ["| elements | wall (s) | steps | Newton iterations | final λ | λ vs limit | "
          "converged | max penetration (mm) |", "|---:|---:|---:|---:|---:|---:|---|---:|"]
    md += [f"| {e} | {w:.2f} | {s} | {it} | {lam:.6g} | {lam / ref - 1:+.2%} | {c} | {p:.2e} |"
           for e, w, s, it, lam, c, p in path_rows]
    within = [r for r in path_rows if abs(r[4] / ref - 1) <= 0.005 and r[5]]
    verdict = (f"Smallest count within 0.5 % of the limit: **{within[0][0]} elements, "
               f"{within[0][1]:.1f} s** (target: under 10 s)." if within
               else "No count within 0.5 % of the limit.")
    (OUT / "fig5_path.md").write_text(
        "Full path of paper-fig5-top-debond-40-load-top to w_top_mid = -15 mm "
        "(arc-length), the paper's element on the default graded mesh (small elements at "
        "supports, load edges, debond tips and all along the debond). The final λ is the "
        "load (N) at the target deflection; fixing the deflection and converging λ is the "
        "same statement as converging the deflection at that load. Limit: Aitken "
        f"extrapolation of the last three counts, λ∞ = {ref:.6g} N (observed order "
        f"{order:.2f}). {load()} at the end (shared machine).\n\n{stamp}\n\n" + "\n".join(md)
        + "\n\n"
        + verdict + "\n")


def main():
    global OUT
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="60..480 elements, levels 1-2")
    p.add_argument("--no-2d", action="store_true", help="skip the 2D runs of fig. 5")
    only = p.add_mutually_exclusive_group()
    only.add_argument("--iterations-only", action="store_true",
                      help="only the Newton iteration table (newton_iteration.md), not fig. 5's "
                      "runs")
    only.add_argument("--fig5-only", action="store_true",
                      help="only fig. 5's runs (fig5_speed.md), not the Newton iteration table")
    p.add_argument("--convergence", action="store_true",
                   help="also the fig. 5 λ(−15) convergence table (120 … 1920 elements)")
    add_out_argument(p, OUT)
    args = p.parse_args()
    OUT = args.out.resolve()
    counts = [60 * 2**k for k in range(4 if args.quick else 8)]  # 60 … 7680
    cases = [(n, 1) for n in counts]
    for level in ((2,) if args.quick else (2, 3, 4)):
        top = 7680 if level == 2 else 1920  # memory: level 4 at 7680 el. is ~0.5 M DOFs
        cases += [(n, level) for n in counts if n <= top]
    if not args.fig5_only:
        stamp, before = measured_on(), load()
        peak = dgemm_rate()
        rows = newton_iteration_times(cases, repeat=3)
        reference = (240, reference_iteration(240, 3))
        write_iterations(rows, reference, peak, before, load(), stamp)
    if args.iterations_only:
        return
    fig5_speed(1 if args.quick else 3, with_2d=not args.no_2d)
    if args.convergence:
        stamp = measured_on()
        write_convergence(fig5_path([120, 240, 360, 480, 960, 1920]), stamp)


if __name__ == "__main__":
    main()
