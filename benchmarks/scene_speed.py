"""Beam against the 2D coarse model on every shipped scene: cost and end load, side by side.

Run from the project root: ``python -m benchmarks.scene_speed [--scenes NAME ...] [--timeout S]
[--out DIR]``. Writes ``benchmarks/results/beam/scene_speed.{md,csv}`` (a rerun replaces them).
The ``sandwich`` command is the one installed beside the interpreter that runs the script.

Per scene of ``scenes/``, each in its own process as a user runs it, one after the other:

- ``sandwich solve SCENE --model beam`` as shipped (``[beam_model] core = "auto"``);
- the same with ``[beam_model] core = 1`` added (the paper's element; into the scene's own
  ``[beam_model]`` table where it has one, the fig. 9 scenes' ``settling_allowance``);
- ``sandwich solve SCENE --model 2d --level coarse``.

Recorded: ``summary.json`` ``wall_seconds`` (the solve) and the whole process (imports, numba's
cache load, the 2D mesh and FFCx forms, result files), steps, and the load factor at the end
of each path (all three follow the scene's ``until`` target, so they end at the same probe value
when they reach it). The ratios are 2D coarse over beam, per column. Issue 12 asks for ≥ 15× on
fig. 5 and ≥ 5× on every shipped scene; the 2D coarse model is not the accuracy reference here
(see ``benchmarks/results/comparisons/tradeoff.md`` for the cost at equal accuracy).

The 1-minute load average is recorded before and after every run: on a shared 2-core machine
other jobs change the times, and only runs at low load compare.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from benchmarks.installed import write_bytecode
from benchmarks.provenance import RESULTS, ROOT, add_out_argument, console_script, measured_on

SCENES = ROOT / "scenes"
OUT = RESULTS / "beam"
SANDWICH = console_script("sandwich")


def load1() -> float:
    """The 1-minute load average."""
    return os.getloadavg()[0]


def solve(scene: Path, model: str, timeout: float, paper_core: bool = False) -> dict:
    """One ``sandwich solve`` process: its times, steps and end load (or why it stopped)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = scene
        if paper_core:
            text = scene.read_text()
            table = tomllib.loads(text).get("beam_model")
            if table is not None and "core" in table:
                raise SystemExit(f"{scene}: its [beam_model] sets core; this script sets it")
            path = Path(tmp) / scene.name
            path.write_text(text + "\n[beam_model]\ncore = 1\n" if table is None
                            else text.replace("[beam_model]\n", "[beam_model]\ncore = 1\n", 1))
        cmd = [str(SANDWICH), "solve", str(path), "--model", model, "--quiet", "--out", tmp]
        if model == "2d":
            cmd += ["--level", "coarse"]
        before = load1()
        t = time.perf_counter()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"status": f"not finished in {timeout:.0f} s", "load": before}
        whole = time.perf_counter() - t
        summary_file = Path(tmp) / "summary.json"
        if not summary_file.exists():
            return {"status": f"exit {p.returncode}: {p.stderr.strip()[-200:]}", "load": before}
        summary = json.loads(summary_file.read_text())
    return {
        "status": "ok" if summary.get("converged") else "stopped short",
        "wall": summary.get("wall_seconds"), "whole": whole,
        "steps": summary.get("steps"),  # converged states, the unloaded start included
        "load_factor": summary.get("final_load_factor"),
        "load": max(before, load1()),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="*", help="scene names (default: every file in scenes/)")
    p.add_argument("--timeout", type=float, default=900.0, help="seconds per run")
    add_out_argument(p, OUT)
    args = p.parse_args()
    names = args.scenes or sorted(f.stem for f in SCENES.glob("*.toml"))
    write_bytecode()  # the runs start from the installed state (benchmarks/installed.py)
    stamp = measured_on()
    rows = []
    for name in names:
        scene = SCENES / f"{name}.toml"
        runs = {"auto": solve(scene, "beam", args.timeout),
                "level1": solve(scene, "beam", args.timeout, paper_core=True),
                "coarse": solve(scene, "2d", args.timeout)}
        row = {"scene": name}
        for key, r in runs.items():
            for field in ("status", "wall", "whole", "steps", "load_factor", "load"):
                row[f"{key}_{field}"] = r.get(field)
        rows.append(row)
        print(name, {k: (r["status"], r.get("wall")) for k, r in runs.items()}, flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "scene_speed.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (args.out / "scene_speed.md").write_text(markdown(rows, stamp))


def _num(x, fmt: str) -> str:
    return "–" if x is None else format(x, fmt)


def _ratio(a, b) -> str:
    return "–" if a is None or b is None or b <= 0 else f"{a / b:.1f}×"


def _kernel_backend() -> str:
    """Which kernels the beam runs used (sandwich/solver/jit.py), asked of a fresh process."""
    code = ("from sandwich.solver.jit import kernel_backend as k; b = k(); "
            "print(b['backend'], '-', b['reason'])")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    out = p.stdout.strip() or p.stderr.strip()[-200:]
    return ("the ahead-of-time build (" + out.split(" - ", 1)[-1] + ")"
            if out.startswith("aot") else f"numba's JIT ({out})")


def markdown(rows: list[dict], stamp: str) -> str:
    """The table: per scene the three runs and the 2D-coarse-over-beam ratios."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=ROOT).stdout.strip()
    lines = [
        "# Beam vs 2D coarse on every shipped scene (`benchmarks/scene_speed.py`)",
        "",
        f"{stamp} Commit {commit}; each run its own `sandwich solve` process, one at a time, on "
        "a 2-core machine (the largest 1-minute load average seen around each run is in the "
        "last column). solve = `summary.json` `wall_seconds`; whole = the process. "
        "Ratios: 2D coarse over beam (> 1: the beam is faster). The scene's `until` target ends "
        "every path at the same probe value when reached; λ end is the last converged load "
        "factor of each run (status other than ok: the run did not reach it); states = converged "
        "states as `summary.json` counts them, the unloaded start included. Where the end loads "
        "differ by more than the models' known gaps, the runs followed different branches or "
        "passed a load maximum on the way (the buckling and cantilever scenes: "
        "`benchmarks/results/comparisons/gallery_agreement.md`): there the costs are of "
        "different paths. Beam kernels: " + _kernel_backend() + ".",
        "",
        "| scene | beam auto: solve / whole (s), states, λ end | beam level 1: solve / whole (s), "
        "states, λ end | 2D coarse: solve / whole (s), states, λ end | 2D/auto solve, whole | "
        "2D/level 1 solve, whole | load |",
        "|---|---|---|---|---|---|---:|",
    ]

    def cell(r, k):
        if r[f"{k}_status"] not in ("ok", "stopped short"):
            return r[f"{k}_status"]
        tag = "" if r[f"{k}_status"] == "ok" else " (stopped short)"
        return (f"{_num(r[f'{k}_wall'], '.2f')} / {_num(r[f'{k}_whole'], '.2f')}, "
                f"{r[f'{k}_steps']}, {_num(r[f'{k}_load_factor'], '.5g')}{tag}")

    for r in rows:
        load = max(x for x in (r["auto_load"], r["level1_load"], r["coarse_load"]) if x is not None)
        lines.append(
            f"| {r['scene']} | {cell(r, 'auto')} | {cell(r, 'level1')} | {cell(r, 'coarse')} | "
            f"{_ratio(r['coarse_wall'], r['auto_wall'])}, "
            f"{_ratio(r['coarse_whole'], r['auto_whole'])} | "
            f"{_ratio(r['coarse_wall'], r['level1_wall'])}, "
            f"{_ratio(r['coarse_whole'], r['level1_whole'])} | {load:.2f} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
