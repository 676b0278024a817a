"""Stability at the extremes: both models over a sweep of stiffness, thickness, slenderness,
debond length and load level, starting from the Fig 5 scene (top debond, load on top).

Per case and model: converged, steps, Newton iterations, step cuts (history column ``cuts`` or
``step_cuts`` when the model records one), wall time; per case the agreement (relative L2 of the
load curve, :mod:`comparisons.metrics`). Writes ``extremes.csv``, ``extremes.md`` (the map for
docs/) and ``extremes.png`` into ``benchmarks/results/comparisons/``.

Usage: ``python benchmarks/extremes.py [--sweeps stiffness thickness slenderness debond load]``
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from comparisons.metrics import compute_metrics  # noqa: E402
from comparisons.paths import path_parameter  # noqa: E402
from comparisons.runs import ModelRun  # noqa: E402
from sandwich.scene import Debond, Layer, Load, Probe, Scene, Support, load_scene  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "comparisons"
BASE = "paper-fig5-top-debond-40-load-top"
SWEEPS = {
    "stiffness": [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6],  # E_core / E_face
    "thickness": [10, 50, 100, 500],  # t_core / t_face
    "slenderness": [5, 20, 100, 1000],  # L / h
    "debond": [0.0, 0.1, 0.3, 0.6, 1.0],  # debond length / span
    "load": [0.25, 0.5, 1.0, 2.0],  # until value / the scene's
}


def _core_stiffness(scene: Scene, ratio: float) -> Scene:
    c, f = scene.core.material, scene.top.material
    E = ratio * f.Ex
    mat = dataclasses.replace(c, Ex=E, Ez=E, Gzx=E * c.Gzx / c.Ex)
    return dataclasses.replace(scene, core=Layer(scene.core.thickness, mat))


def _thickness(scene: Scene, ratio: float) -> Scene:
    t = scene.core.thickness / ratio
    return dataclasses.replace(scene, top=Layer(t, scene.top.material),
                               bottom=Layer(t, scene.bottom.material))


def _scale_x(scene: Scene, length: float) -> Scene:
    s = length / scene.length
    return dataclasses.replace(
        scene, length=length,
        debonds=tuple(Debond(d.interface, d.start * s, d.end * s) for d in scene.debonds),
        supports=tuple(Support(p.x * s, p.on, p.type) for p in scene.supports),
        loads=tuple(Load(ld.on, ld.x * s, ld.width * s, ld.force) for ld in scene.loads),
        probes=tuple(Probe(p.name, p.on, p.x * s) for p in scene.probes),
        analysis=dataclasses.replace(scene.analysis, until_value=scene.analysis.until_value * s))


def _debond(scene: Scene, fraction: float) -> Scene:
    L, half = scene.length, 0.5 * fraction * scene.length
    return dataclasses.replace(scene, debonds=(Debond("top", L / 2 - half, L / 2 + half),))


def _load(scene: Scene, factor: float) -> Scene:
    a = scene.analysis
    return dataclasses.replace(scene, analysis=dataclasses.replace(
        a, until_value=a.until_value * factor))


def cases(base: Scene, sweeps: list[str]) -> Iterator[tuple[str, float, Scene]]:
    make: dict[str, Callable[[Scene, float], Scene]] = {
        "stiffness": _core_stiffness, "thickness": _thickness, "debond": _debond,
        "slenderness": lambda s, r: _scale_x(s, r * s.total_height), "load": _load}
    for sweep in sweeps:
        for value in SWEEPS[sweep]:
            sc = make[sweep](base, value)
            yield sweep, value, dataclasses.replace(sc, name=f"{base.name}-{sweep}-{value:g}",
                                                    source=None)


def _cuts(run: ModelRun) -> int:
    s = run.solution
    if s is None:
        return 0
    if "step_cuts" in s.extra:
        return int(s.extra["step_cuts"])
    return int(sum(r.extra.get("cuts", r.extra.get("step_cuts", 0.0)) for r in s.history))


def run_case(scene: Scene, solvers: dict[str, Callable]) -> dict[str, ModelRun]:
    runs = {}
    for model in ("beam", "2d"):
        solve = solvers.get(model)
        if solve is None:
            runs[model] = ModelRun(model, Path("-"), "missing", None, reason="not importable")
            continue
        t0 = time.perf_counter()
        try:
            sol = solve(scene)
            runs[model] = ModelRun(model, Path("-"), "run", sol,
                                   seconds=time.perf_counter() - t0)
        except Exception as exc:  # recorded in the map, the sweep goes on
            runs[model] = ModelRun(model, Path("-"), "failed", None,
                                   reason=f"{type(exc).__name__}: {exc}",
                                   seconds=time.perf_counter() - t0)
    return runs


def row(sweep: str, value: float, scene: Scene, runs: dict[str, ModelRun]) -> dict[str, object]:
    present = [r.solution for r in runs.values() if r.solution is not None and r.solution.history]
    m = compute_metrics(scene.name, runs, path_parameter(scene.analysis.until_probe, present))
    load = m.curve("load_factor")
    out: dict[str, object] = {"sweep": sweep, "value": value}
    for model, r in runs.items():
        s = r.solution
        out[f"{model}_converged"] = bool(s and s.converged)
        out[f"{model}_steps"] = len(s.history) if s else 0
        out[f"{model}_iterations"] = sum(h.iterations for h in s.history) if s else 0
        out[f"{model}_cuts"] = _cuts(r)
        out[f"{model}_seconds"] = round(r.seconds, 4)
        out[f"{model}_note"] = (s.message if s else r.reason).replace("|", "/")[:120]
    out["load_l2"] = None if load is None else load.l2_relative
    return out


def write(rows: list[dict[str, object]], out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0]) if rows else []
    with (out / "extremes.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, keys, lineterminator="\n")
        w.writeheader()
        w.writerows({k: ("" if v is None else v) for k, v in r.items()} for r in rows)
    md = ["# Stability at the extremes (benchmarks/extremes.py)", "",
          f"Base scene: {BASE}. ✓ converged to the target, ✗ stopped early or failed; "
          "agreement = relative L2 of the beam load curve against the 2D one.", "",
          "| sweep | value | beam | 2D | iterations beam/2D | cuts beam/2D | agreement |",
          "|---|---|---|---|---|---|---|"]
    for r in rows:
        agree = "—" if r["load_l2"] is None else f"{100 * float(r['load_l2']):.2f} %"
        md.append(f"| {r['sweep']} | {r['value']:g} | {'✓' if r.get('beam_converged') else '✗'} "
                  f"| {'✓' if r.get('2d_converged') else '✗'} | {r.get('beam_iterations')}/"
                  f"{r.get('2d_iterations')} | {r.get('beam_cuts')}/{r.get('2d_cuts')} | "
                  f"{agree} |")
    md += ["", "![map](extremes.png)", ""]
    (out / "extremes.md").write_text("\n".join(md))
    sweeps = list(dict.fromkeys(r["sweep"] for r in rows))
    fig, axes = plt.subplots(1, max(len(sweeps), 1), figsize=(4 * max(len(sweeps), 1), 3.6),
                             squeeze=False)
    for ax, sweep in zip(axes[0], sweeps, strict=False):
        rs = [r for r in rows if r["sweep"] == sweep]
        for i, model in enumerate(("beam", "2d")):
            ax.scatter(range(len(rs)), [i] * len(rs), s=200, marker="s",
                       c=["tab:green" if r.get(f"{model}_converged") else "tab:red" for r in rs])
        for j, r in enumerate(rs):
            if r["load_l2"] is not None:
                ax.annotate(f"{100 * float(r['load_l2']):.1f}%", (j, 0.5), ha="center",
                            fontsize=7)
        ax.set_xticks(range(len(rs)), [f"{r['value']:g}" for r in rs], fontsize=7)
        ax.set_yticks([0, 1], ["beam", "2D"])
        ax.set_ylim(-0.6, 1.6)
        ax.set_title(sweep)
    fig.suptitle("green: converged, red: not; numbers: load-curve L2 disagreement")
    fig.tight_layout()
    fig.savefig(out / "extremes.png", dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="stability sweep of both models")
    ap.add_argument("--sweeps", nargs="+", default=list(SWEEPS), choices=list(SWEEPS))
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    solvers = {}
    for model, module in (("beam", "beam_element"), ("2d", "reference2d")):
        try:
            solvers[model] = __import__(module).solve
        except (ImportError, AttributeError) as exc:
            print(f"{model}: not available ({exc}); sweeping without it")
    base = load_scene(ROOT / "scenes" / f"{BASE}.toml")
    rows = []
    for sweep, value, scene in cases(base, args.sweeps):
        print(f"{sweep} = {value:g}", flush=True)
        rows.append(row(sweep, value, scene, run_case(scene, solvers)))
        write(rows, args.out)  # partial map survives a crash or an interrupt
    return 0 if rows and not any(isinstance(v, float) and math.isnan(v)
                                 for r in rows for v in r.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
