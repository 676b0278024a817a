"""The speed/accuracy trade: beam at increasing element counts, 2D at increasing mesh levels.

For each scene (default: the Fig 4 and Fig 5 scenes) both models are run in this one process at
every resolution; wall times are measured here. The error of every run is taken against the finest
2D run, on the state at the end of the path:

- the path ends when the mid-span probe (``analysis.until_probe``) reaches its target, so that
  deflection is the same for every run; the error measure is the load at which each run reaches
  it, |λ_end − λ_end,ref| / |λ_end,ref| (equivalently the error in deflection at that load, to
  first order times the local stiffness ratio), and the other probes' errors are tabled too;
- headline: for each model the cheapest run with error ≤ 1 %, and the 2D / beam time ratio.

Writes ``tradeoff.csv``, ``tradeoff.md`` and ``tradeoff.png`` (error vs time, Pareto fronts)
into ``benchmarks/results/comparisons/`` (a rerun replaces them; ``--out DIR`` for another
folder); the table says the machine and date it was measured on.

Beam variants: ``paper`` (the paper's element: core level 1, ``faces = "paper"``,
``face_membrane = "paper"``, ``contact_search = "same-x"``), ``averaged`` (the same with
``face_membrane = "averaged"``, see docs/comparisons.md), ``L1``…``L6`` (every element at that
core level, docs/beam_element.md "Core levels", with the scene defaults: stretch faces, averaged
membrane, closest-point contact) and ``auto`` (``core = "auto"``, the scene default: levels from
the error indicator, the path rerun to check them).
``--until NAME=VALUE`` ends a scene's path earlier (the fig4 2D core crushes at w ≈ −13 mm, so
its path is compared to −12 mm). Wall and CPU seconds are both recorded: on a shared machine
the CPU time is the steadier of the two. Before the sweep each model solves the first scene once,
untimed (:func:`warm_up`): the process's first 2D solve pays the imports of dolfinx and PETSc.

Usage, from the project root: ``python -m benchmarks.tradeoff [--elements 15 30 60 120]
[--levels coarse medium fine] [--refine 0 1] [--scenes paper-fig4-bonded-3pb ...] [--variants
paper averaged] [--until paper-fig4-bonded-3pb=-12] [--out DIR]``
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import os
import platform
import time
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on  # noqa: E402
from sandwich.models import MODELS, with_options  # noqa: E402
from sandwich.results import Solution  # noqa: E402
from sandwich.scene import BeamModelOptions, Scene  # noqa: E402
from sandwich.scene_file import load_scene  # noqa: E402

OUT = RESULTS / "comparisons"
SCENES = ("paper-fig4-bonded-3pb", "paper-fig5-top-debond-40-load-top")
TARGET = 0.01  # the headline error level


@dataclasses.dataclass
class Run:
    """One model at one resolution on one scene: cost, end state and error."""

    scene: str
    model: str
    resolution: str
    seconds: float
    dofs: int
    converged: bool
    final_load_factor: float
    final_probes: dict[str, float]
    error: float | None = None  # load at the end of the path vs finest 2D
    probe_errors: dict[str, float] = dataclasses.field(default_factory=dict)
    cpu_seconds: float = math.nan


VARIANTS = ("paper", "averaged", "L1", "L2", "L3", "L4", "L5", "L6", "auto")


def with_beam_elements(scene: Scene, n: int, variant: str = "paper") -> Scene:
    """``scene`` with ``n`` beam elements and the beam ``variant`` (see :data:`VARIANTS`)."""
    if variant in ("paper", "averaged"):  # the paper's element (and its averaged membrane)
        options = {"core": 1, "face_membrane": variant, "faces": "paper",
                   "contact_search": "same-x"}
    else:  # core levels with the scene defaults of faces, membrane and contact
        d = BeamModelOptions()
        options = {"core": "auto" if variant == "auto" else int(variant[1:]),
                   "face_membrane": d.face_membrane, "faces": d.faces,
                   "contact_search": d.contact_search}
    return dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, elements=n, core_zones=(), **options))


def with_until(scene: Scene, value: float) -> Scene:
    """``scene`` with its until probe's target set to ``value``."""
    return dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                   until_value=value))


def timed(label: str, scene: Scene, model: str, solve: Callable[[], Solution]) -> Run:
    """Run ``solve()`` and record its wall and CPU time and end state."""
    t0, c0 = time.perf_counter(), time.process_time()
    s = solve()
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    last = s.history[-1] if s.history else None
    return Run(scene.name, model, label, seconds, s.dofs, s.converged,
               last.load_factor if last else math.nan, dict(last.probes) if last else {},
               cpu_seconds=cpu)


def measure(scene: Scene, beam_solve, ref_solve, elements, levels, refines,
            variants: tuple[str, ...] = ("paper",),
            variant_elements: dict[str, list[int]] | None = None) -> list[Run]:
    """Run every resolution of both models on ``scene``; errors against the finest 2D run."""
    runs = []
    for level in levels:
        for refine in refines:
            print(f"{scene.name}: 2d level={level} refine={refine}", flush=True)
            runs.append(timed(f"{level}+{refine}", scene, "2d",
                              lambda: ref_solve(scene, level=level, refine=refine)))  # noqa: B023
    for variant in variants:
        for n in (variant_elements or {}).get(variant, elements):
            print(f"{scene.name}: beam elements={n} {variant}", flush=True)
            sc = with_beam_elements(scene, n, variant)
            label = str(n) if variant == "paper" else f"{n} {variant}"
            runs.append(timed(label, scene, "beam", lambda: beam_solve(sc)))  # noqa: B023
    ref = [r for r in runs if r.model == "2d" and r.converged]
    if not ref:
        return runs
    finest = ref[-1]
    for r in runs:
        if not r.converged:
            continue
        r.error = abs(r.final_load_factor - finest.final_load_factor) / abs(
            finest.final_load_factor)
        r.probe_errors = {k: abs(v - finest.final_probes[k]) / abs(finest.final_probes[k])
                          for k, v in r.final_probes.items()
                          if finest.final_probes.get(k) and k != scene.analysis.until_probe}
    return runs


def cheapest(runs: list[Run], model: str, target: float = TARGET) -> Run | None:
    """The fastest run of ``model`` with error ≤ ``target`` (``None`` if none)."""
    ok = [r for r in runs if r.model == model and r.error is not None and r.error <= target]
    return min(ok, key=lambda r: r.seconds) if ok else None


def pareto(runs: list[Run]) -> list[Run]:
    """Runs not beaten on both time and error by another run of the same model."""
    pts = sorted((r for r in runs if r.error is not None), key=lambda r: (r.seconds, r.error))
    front, best = [], math.inf
    for r in pts:
        if r.error < best:
            front.append(r)
            best = r.error
    return front


def headline(runs: list[Run], scene: str) -> str:
    """The sentence of the table: cheapest runs within 1 % and their time ratio."""
    b, t = cheapest(runs, "beam"), cheapest(runs, "2d")
    if b is None or t is None:
        beams = [r.error for r in runs if r.model == "beam" and r.error is not None]
        best = f"{100 * min(beams):.2f} %" if beams else "no converged beam run"
        return (f"{scene}: 1 % not reached by {'beam' if b is None else '2d'} "
                f"(best beam error {best})")
    note = " (the finest 2D run, error 0 by definition: an upper bound)" if t.error == 0 else ""
    return (f"{scene}: at ≤ 1 % error, beam {b.resolution} elements {b.seconds:.3g} s vs 2D "
            f"{t.resolution} {t.seconds:.3g} s{note}: "
            f"2D/beam time ratio {t.seconds / b.seconds:.3g}")


def write(runs: list[Run], lines: list[str], out: Path, stamp: str = "") -> None:
    """Write ``tradeoff.csv``, ``tradeoff.md`` and ``tradeoff.png`` into ``out``.

    ``stamp`` is the table's :func:`~benchmarks.provenance.measured_on` line.
    """
    out.mkdir(parents=True, exist_ok=True)
    with (out / "tradeoff.csv").open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["scene", "model", "resolution", "seconds", "cpu_seconds", "dofs",
                    "converged", "final_load_factor", "error_load_end"])
        for r in runs:
            w.writerow([r.scene, r.model, r.resolution, f"{r.seconds:.6g}",
                        "" if math.isnan(r.cpu_seconds) else f"{r.cpu_seconds:.6g}", r.dofs,
                        r.converged,
                        "" if math.isnan(r.final_load_factor) else repr(r.final_load_factor),
                        "" if r.error is None else repr(r.error)])
    md = ["# Speed/accuracy trade (benchmarks/tradeoff.py)", "",
          "Error: load at the end of the path (the mid-span probe at its target) against the "
          "finest 2D run; time measured in the same process, after one untimed solve with "
          "each model (the process's lazy imports and cold caches are not a resolution's "
          "cost).", "", *([stamp, ""] if stamp else [])]
    md += [f"- {line}" for line in lines] + ["",
           "| scene | model | resolution | wall (s) | CPU (s) | DOFs | converged | error |",
           "|---|---|---|---|---|---|---|---|"]
    md += [f"| {r.scene} | {r.model} | {r.resolution} | {r.seconds:.3g} | "
           f"{r.cpu_seconds:.3g} | {r.dofs} | "
           f"{r.converged} | {'—' if r.error is None else f'{100 * r.error:.3f} %'} |"
           for r in runs]
    md += ["", "![error vs time](tradeoff.png)", ""]
    (out / "tradeoff.md").write_text("\n".join(md))
    scenes = sorted({r.scene for r in runs})
    fig, axes = plt.subplots(1, len(scenes), figsize=(6 * len(scenes), 4.5), squeeze=False)
    for ax, scene in zip(axes[0], scenes, strict=True):
        for model, style in (("2d", "o-"), ("beam", "s--")):
            rs = [r for r in runs if r.scene == scene and r.model == model and r.error]
            ax.loglog([r.seconds for r in rs], [r.error for r in rs], style, label=model,
                      alpha=0.4)
            front = pareto(rs)
            ax.loglog([r.seconds for r in front], [r.error for r in front], style, label=None)
            for r in rs:
                ax.annotate(r.resolution, (r.seconds, r.error), fontsize=7)
        ax.axhline(TARGET, color="k", linewidth=0.6, linestyle=":")
        ax.set(xlabel="wall time (s)", ylabel="relative error, load at end of path",
               title=scene)
        ax.legend()
    fig.tight_layout()
    fig.savefig(out / "tradeoff.png", dpi=120)
    plt.close(fig)


def warm_up(name: str, level: str, variant: str, elements: list[int], until: dict[str, float],
            beam_solve, ref_solve) -> None:
    """Solve ``name`` once with each model, untimed.

    The first run of the process pays the lazy imports (dolfinx and PETSc for 2D, ≈ 1 s of wall
    time mostly off the CPU: fig. 4's 2D coarse run measured 3.2 s wall for 2.1 s CPU without
    this) and cold caches, which are not the cost of that resolution.
    """
    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    if name in until:
        scene = with_until(scene, until[name])
    print(f"{name}: warm-up (untimed), 2d level={level}, beam elements={min(elements)} {variant}",
          flush=True)
    ref_solve(scene, level=level, refine=0)
    beam_solve(with_beam_elements(scene, min(elements), variant))


def main(argv: list[str] | None = None) -> int:
    """The benchmark's command line (``python -m benchmarks.tradeoff --help``)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--elements", nargs="+", type=int, default=[15, 30, 60, 120, 240])
    ap.add_argument("--levels", nargs="+", default=["coarse", "medium", "fine"])
    ap.add_argument("--refine", nargs="+", type=int, default=[0])
    ap.add_argument("--variants", nargs="+", default=["paper", "averaged"],
                    choices=list(VARIANTS))
    ap.add_argument("--variant-elements", nargs="+", default=[], metavar="VARIANT=N,N",
                    help="element counts of one variant (default: --elements)")
    ap.add_argument("--until", nargs="+", default=["paper-fig4-bonded-3pb=-12"],
                    metavar="SCENE=VALUE", help="end a scene's path at this probe value")
    ap.add_argument("--scene-levels", nargs="+", default=[], metavar="SCENE=LEVEL,LEVEL",
                    help="2D levels of one scene (default: --levels)")
    add_out_argument(ap, OUT)
    args = ap.parse_args(argv)
    stamp = measured_on()
    per_variant = {}
    for item in args.variant_elements:
        name, _, counts = item.partition("=")
        try:
            per_variant[name] = [int(c) for c in counts.split(",")]
        except ValueError:
            ap.error(f"--variant-elements {item!r}: expected VARIANT=N,N,...")
        if name not in VARIANTS:
            ap.error(f"--variant-elements {item!r}: unknown variant {name!r}")
    scene_levels = {}
    for item in args.scene_levels:
        name, _, levels = item.partition("=")
        scene_levels[name] = [v for v in levels.split(",") if v]
        if not scene_levels[name]:
            ap.error(f"--scene-levels {item!r}: expected SCENE=LEVEL,LEVEL")
    until = {}
    for item in args.until:
        name, _, value = item.partition("=")
        try:
            until[name] = float(value)
        except ValueError:
            ap.error(f"--until {item!r}: expected SCENE=VALUE with a number")
    def beam_solve(scene: Scene) -> Solution:
        return MODELS["beam"].solve(scene)

    def ref_solve(scene: Scene, level: str, refine: int) -> Solution:
        return MODELS["2d"].solve(with_options(scene, "2d", level=level, refine=refine,
                                              error_estimate=False))

    runs, lines = [], []
    warm_up(args.scenes[0], scene_levels.get(args.scenes[0], args.levels)[0],
            args.variants[0], per_variant.get(args.variants[0], args.elements), until,
            beam_solve, ref_solve)
    for name in args.scenes:
        scene = load_scene(ROOT / "scenes" / f"{name}.toml")
        if name in until:
            scene = with_until(scene, until[name])
        load = os.getloadavg()[0]
        rs = measure(scene, beam_solve, ref_solve, args.elements,
                     scene_levels.get(name, args.levels),
                     args.refine, tuple(args.variants), per_variant)
        runs += rs
        lines.append(headline(rs, name) + f" [path to {scene.analysis.until_probe} = "
                     f"{scene.analysis.until_value:g}; load average {load:.2f} at start, "
                     f"{os.getloadavg()[0]:.2f} at end, {platform.node()}]")
        write(runs, lines, args.out, stamp)  # after each scene: a partial table survives a crash
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
