"""Speed of the 2D reference: DOFs, Newton iterations and seconds per step, per mesh level and
number of MPI ranks.

Runs the fig4 and fig5 paper scenes (path shortened to w_top_mid = UNTIL mm unless --full) at
each level, serially and with ``mpirun -n 2``, and times where the work goes (wall times of
rank 0, accumulated over the run):

- ``mesh``: gmsh meshing (rank 0; the other ranks wait for the broadcast);
- ``setup``: dolfinx mesh, forms (FFCx JIT, cached after the first run), matrix pattern;
- ``residual``: residual assembly (internal force + contact forces);
- ``tangent``: tangent assembly (``ufl.derivative`` form + contact Hessian + supports);
- ``factorise``: MUMPS numeric LDLᵀ (the symbolic analysis is done once per run);
- ``fsolve``: MUMPS triangular solves;
- ``contact``: contact evaluation (gaps, forces, Hessians) — *already included* in residual and
  tangent; shown on its own because it is the part written in NumPy;
- ``other``: the rest of the wall time (path solver, admissibility check, probes, profiles,
  field frame).

Every (scene, level, ranks) row runs in its own process (``python -m
benchmarks.reference2d_speed --worker`` or ``mpirun -n 2 --oversubscribe python -m
benchmarks.reference2d_speed --worker``, from the project root), with a wall-clock limit
(``--timeout``): a row over the limit is reported as not finished. The 1-minute load average
(``os.getloadavg()``) is recorded before and after every row: on a shared 2-core machine the
timings are disturbed by other jobs, and 2 ranks on 2 cores compete with them.

Writes benchmarks/results/reference2d/speed.{md,json} (or into ``--out DIR``; a rerun replaces
them), with the machine and date measured on. From the project root:

    python -m benchmarks.reference2d_speed [--levels coarse medium fine] [--ranks 1 2]
        [--until -5] [--out DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on

OUT = RESULTS / "reference2d"
SCENES = ("paper-fig4-bonded-3pb", "paper-fig5-top-debond-40-load-top")
UNTIL = -5.0
PHASES = ("mesh", "setup", "residual", "tangent", "factorize", "fsolve", "contact")


class Timers:
    """Wall time accumulated by the wrapped functions."""

    def __init__(self):
        self.t = dict.fromkeys(PHASES, 0.0)

    def wrap(self, name, fn):
        def timed(*a, **k):
            t0 = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                self.t[name] += time.perf_counter() - t0
        return timed


def run(name: str, level: str, full: bool, until: float = UNTIL) -> dict:
    """Solve one scene at one level in this process (every rank) and return rank 0's timings."""
    from mpi4py import MPI

    from sandwich.plane2d import contact as ct
    from sandwich.plane2d import solve
    from sandwich.scene_file import load_scene

    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    if not full:
        scene = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                        until_value=until))
    timers = Timers()
    models = []
    solve_mod = sys.modules["sandwich.plane2d.solve"]  # (the package exports a function `solve`)
    build, mesh_fn, evaluate = solve_mod.build_model, solve_mod.build_scene_mesh, ct.evaluate

    def build_timed(*a, **k):
        t0 = time.perf_counter()
        m = build(*a, **k)
        timers.t["setup"] += time.perf_counter() - t0
        models.append(m)
        s = m.system
        s.internal_force = timers.wrap("residual", s.internal_force)
        s.tangent = timers.wrap("tangent", s.tangent)
        s.factorize = timers.wrap("factorize", s.factorize)
        s._mumps.solve = timers.wrap("fsolve", s._mumps.solve)
        return m

    ct.evaluate = timers.wrap("contact", evaluate)
    solve_mod.build_model = build_timed
    solve_mod.build_scene_mesh = timers.wrap("mesh", mesh_fn)
    try:
        MPI.COMM_WORLD.barrier()
        t0, c0 = time.perf_counter(), time.process_time()
        sol = solve(scene, level=level, estimate=False)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        solve_mod.build_model, solve_mod.build_scene_mesh, ct.evaluate = build, mesh_fn, evaluate
    steps = len(sol.history) - 1
    t = timers.t
    # factorize() of the model numerically factorises at once; its handle's solve() may
    # refactor a stale handle (counted in refactorizations), which then lands in fsolve
    other = wall - sum(t[k] for k in ("mesh", "setup", "residual", "tangent", "factorize",
                                      "fsolve"))
    counters = dict(models[0].system.counters) if models else {}
    return {
        "scene": name, "level": level, "ranks": MPI.COMM_WORLD.size, "dofs": sol.dofs,
        "cells": sol.extra["cells"], "steps": steps,
        "newton_iterations": sol.extra["newton_iterations"],
        "reached": sol.converged, "message": sol.message,
        "final_load_factor": sol.final_load_factor,
        "final_w_top_mid": sol.history[-1].probes["w_top_mid"],
        "wall_s": wall, "cpu_s": cpu, "s_per_step": wall / max(steps, 1),
        **{f"{k}_s": v for k, v in t.items()}, "other_s": other,
        "max_penetration_over_face_thickness": sol.extra["max_penetration_over_face_thickness"],
        **counters,
    }


def worker(args) -> None:
    from mpi4py import MPI

    row = run(args.scene, args.level, args.full, args.until)
    if MPI.COMM_WORLD.rank == 0:
        Path(args.json).write_text(json.dumps(row) + "\n")


def launch(name: str, level: str, ranks: int, args) -> dict:
    """One row in a fresh process (under mpirun for ranks > 1), with the load averages."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "row.json"
        cmd = [sys.executable, "-m", "benchmarks.reference2d_speed", "--worker", "--scene", name,
               "--level", level, "--until", repr(args.until), "--json", str(out)]
        if args.full:
            cmd.append("--full")
        if ranks > 1:
            mpirun = shutil.which("mpirun")
            if mpirun is None:
                raise SystemExit("mpirun not found on PATH")
            cmd = [mpirun, "-n", str(ranks), "--oversubscribe", *cmd]
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        env.setdefault("XDG_CACHE_HOME", str(ROOT / ".cache"))
        load_before = os.getloadavg()[0]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True,
                                  timeout=args.timeout)
            ok = proc.returncode == 0 and out.is_file()
            why = "" if ok else (proc.stderr[-1500:] or proc.stdout[-1500:])
        except subprocess.TimeoutExpired:
            ok, why = False, f"not finished within {args.timeout:.0f} s (killed)"
        elapsed = time.perf_counter() - t0
        row = json.loads(out.read_text()) if ok else {
            "scene": name, "level": level, "ranks": ranks, "failed": why}
        row.update(load_before=load_before, load_after=os.getloadavg()[0],
                   process_s=elapsed)
        return row


def table(rows: list[dict], args, stamp: str = "") -> str:
    target = "the scene's target" if args.full else f"w_top_mid = {args.until} mm"
    head = ("| scene | level | ranks | DOFs | steps | Newton its | s/step | total s | CPU s | "
            "mesh | setup | residual | tangent | factorise | MUMPS solve | other | (contact) | "
            "load avg before/after |")
    lines = [f"Path to {target}. Phase times in seconds (rank 0's wall time); `(contact)` is "
             "the contact evaluation, already counted inside residual and tangent. "
             "`total s` is the solve's wall time (no interpreter start-up, no MPI launch), "
             "`CPU s` rank 0's CPU time in it (less disturbed by other jobs than wall time); "
             "load average = 1-minute `os.getloadavg()` before and after the row (2-core "
             "machine shared with other jobs: timings are disturbed).", "",
             *([stamp, ""] if stamp else []), head,
             "|" + "---|" * 18]
    short = {"paper-fig4-bonded-3pb": "fig4", "paper-fig5-top-debond-40-load-top": "fig5"}
    for r in rows:
        name = short.get(r["scene"], r["scene"])
        load = f"{r['load_before']:.1f} / {r['load_after']:.1f}"
        if "failed" in r:
            why = r["failed"].strip().splitlines()[-1] if r["failed"].strip() else "failed"
            lines.append(f"| {name} | {r['level']} | {r['ranks']} | | | | | | | | | | | | | | "
                         f"| {load} |  — {why[:120]}")
            continue
        mark = "" if r["reached"] else " (stopped)"
        lines.append(
            f"| {name} | {r['level']} | {r['ranks']} | {r['dofs']} | {r['steps']}{mark} | "
            f"{r['newton_iterations']} | {r['s_per_step']:.2f} | {r['wall_s']:.1f} | "
            f"{r.get('cpu_s', float('nan')):.1f} | "
            f"{r['mesh_s']:.1f} | {r['setup_s']:.1f} | {r['residual_s']:.1f} | "
            f"{r['tangent_s']:.1f} | {r['factorize_s']:.1f} | {r['fsolve_s']:.1f} | "
            f"{r['other_s']:.1f} | ({r['contact_s']:.2f}) | {load} |")
    return "\n".join(lines) + "\n"


def main():
    """Measure every row in its own process (or be that process: ``--worker``)."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--levels", nargs="+", default=["coarse", "medium", "fine"])
    p.add_argument("--ranks", nargs="+", type=int, default=[1, 2])
    p.add_argument("--scenes", nargs="+", default=list(SCENES))
    p.add_argument("--full", action="store_true", help="the scenes' full paths")
    p.add_argument("--until", type=float, default=UNTIL, help="w_top_mid target (mm)")
    p.add_argument("--timeout", type=float, default=1800.0, help="seconds per row")
    add_out_argument(p, OUT)
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--scene", help=argparse.SUPPRESS)
    p.add_argument("--level", help=argparse.SUPPRESS)
    p.add_argument("--json", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.worker:
        worker(args)
        return
    args.out.mkdir(parents=True, exist_ok=True)
    stamp = measured_on()
    rows = []
    for level in args.levels:  # level-major: the cheap rows first
        for name in args.scenes:
            for ranks in args.ranks:
                r = launch(name, level, ranks, args)
                print({k: (round(v, 3) if isinstance(v, float) else v) for k, v in r.items()},
                      flush=True)
                rows.append(r)
                # written after every row: a long run that is stopped keeps what it measured
                (args.out / "speed.json").write_text(json.dumps(rows, indent=2) + "\n")
                (args.out / "speed.md").write_text(table(rows, args, stamp))
    print(table(rows, args, stamp))


if __name__ == "__main__":
    main()
