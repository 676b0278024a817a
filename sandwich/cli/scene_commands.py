"""The commands on one scene: ``validate``, ``mesh`` and ``solve``.

A solve that stops before its target, or is interrupted (Ctrl-C, SIGTERM), keeps and writes
every converged step and exits with code 1 after saying where and why.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from types import SimpleNamespace

from sandwich.cli.common import (
    EXIT_OK,
    EXIT_STOPPED,
    RESULTS,
    accuracy_line,
    default_out,
    guard_memory,
    load_scenes,
    overridden,
    say,
)
from sandwich.models import mpi_rank, run_model
from sandwich.results import InterruptedSolve, check_output_folder
from sandwich.scene import Scene

__all__ = ["LARGE_BEAM", "cmd_mesh", "cmd_solve", "cmd_validate", "warnings_before_solve"]

LARGE_BEAM = 20_000  # beam elements above which a solve takes minutes and gigabytes


def cmd_validate(args: argparse.Namespace) -> int:
    """Check scene files and say which are usable."""
    for s in load_scenes(args.scenes):
        say(args, f"ok: {s.source} ({s.name}: {len(s.debonds)} debond(s), "
             f"{len(s.supports)} support(s), {len(s.loads)} load(s))")
    return EXIT_OK


def cmd_mesh(args: argparse.Namespace) -> int:
    """Mesh a scene for the 2D reference and print a quality report."""
    (scene,) = load_scenes([args.scene])
    scene = overridden(scene, "2d", args)
    guard_memory([scene], ("mesh",), args)
    out = Path(args.out) if args.out else RESULTS / scene.name / "mesh"
    check_output_folder(out)
    from sandwich.meshes import build_mesh, quality_report, write_mesh

    mesh = build_mesh(scene)
    files = write_mesh(mesh, out, scene.name)
    say(args, str(quality_report(mesh)))
    for kind, path in files.items():
        say(args, f"wrote {kind}: {path}")
    return EXIT_OK


class _StepBar:
    """Feeds the runner's step events to a progress bar; counts the steps past the start."""

    def __init__(self, bar):
        self.bar = bar
        self.steps = 0  # converged steps after the unloaded state 0, as the runner streamed them

    def __call__(self, event) -> None:
        if event.phase == "step":
            self.steps = int(event.step or 0)
            self.bar(event)
        elif event.phase == "note":  # the bar restarts with the path
            self.steps = 0
            self.bar(SimpleNamespace(step=0, load_factor=0.0, probes={}, message=event.message))


def growth_line(growth: dict) -> str:
    """What a growth run found, in one line (summary ``debond_growth`` of a growth run)."""
    if "tips" in growth:  # a cohesive law's path
        moved = "; ".join(f"tip {k} {t['from']:g} -> {t['to']:.4g} mm (process zone up to "
                          f"{t['longest_process_zone_mm']:.3g} mm)"
                          for k, t in growth["tips"].items())
        if growth.get("first_growth_load") is None:
            return f"  growth (cohesive law): no tip moved; {moved}"
        at_least = "" if growth["bounded"] else "at least "
        return (f"  growth (cohesive law): first at load factor "
                f"{growth['first_growth_load']:.6g}, residual strength {at_least}"
                f"{growth['residual_strength']:.6g}; {moved}")
    if growth.get("first_growth_load") is None:
        return f"  growth: none ({growth['stopped']})"
    at_least = "" if growth["bounded"] else "at least "
    moved = "; ".join(f"debond {i} [{d['from'][0]:g}, {d['from'][1]:g}] -> "
                      f"[{d['to'][0]:g}, {d['to'][1]:g}]" for i, d in growth["debonds"].items())
    return (f"  growth: first at load factor {growth['first_growth_load']:.6g}, residual "
            f"strength {at_least}{growth['residual_strength']:.6g}; {growth['stable_steps']} "
            f"stable, {growth['unstable_steps']} unstable step(s); {moved}")


def written_files(folder: Path) -> str:
    """The result files in ``folder``, the field frames counted: what a solve wrote there."""
    from sandwich.results.writing import is_result_file

    if not folder.is_dir():  # an MPI rank other than 0 writes nothing
        return ""
    names = sorted(p.name for p in folder.iterdir() if is_result_file(p.name))
    frames = [n for n in names if n.startswith("fields_") and n.endswith(".vtu")]
    shown = [n for n in names if n not in frames]
    if frames:
        shown.append(f"{len(frames)} fields_*.vtu frame(s)")
    return ", ".join(shown)


def warnings_before_solve(scene: Scene, model: str) -> list[str]:
    """What a user should know before a solve starts (the solve still runs)."""
    out = []
    for i, ld in enumerate(scene.loads):
        lo, hi = ld.span
        for j, sup in enumerate(scene.supports):
            if ld.on in sup.faces and lo - 1e-9 <= sup.x <= hi + 1e-9:
                out.append(f"loads[{i}] acts over supports[{j}] (x = {sup.x:g} mm on the "
                           f"{ld.on} face): the support takes the load through the core, which "
                           "may crush there")
    a = scene.analysis
    if a.until_load_factor is not None and a.until_load_factor < 0:
        out.append(f"analysis.until.load_factor = {a.until_load_factor:g} < 0 reverses every "
                   "load's force")
    if model == "beam" and scene.beam_model.elements > LARGE_BEAM:
        out.append(f"beam_model.elements = {scene.beam_model.elements} is above {LARGE_BEAM}: "
                   "expect minutes and gigabytes")
    return out


def cmd_solve(args: argparse.Namespace) -> int:
    """Solve one scene with one model."""
    from sandwich.progress import PathProgress

    (scene,) = load_scenes([args.scene])
    scene = overridden(scene, args.model, args)
    guard_memory([scene], (args.model,), args)
    out = Path(args.out) if args.out else default_out(scene, args.model)
    check_output_folder(out)
    for line in warnings_before_solve(scene, args.model):
        print(f"warning: {scene.source}: {line}", file=sys.stderr)
    t0 = time.perf_counter()
    quiet = args.quiet or mpi_rank() != 0
    feed = None
    try:
        with PathProgress(scene, f"{scene.name} [{args.model}]", quiet=quiet) as bar:
            feed = _StepBar(bar)
            sol = run_model(scene, args.model, out, progress=feed)
    except InterruptedSolve:
        what = ("checking the core levels" if args.model == "beam"
                else "estimating the mesh's error")
        print(f"interrupted while {what}: the path that reached the target is written to "
              f"{out}/ (its warnings say what was not finished)", file=sys.stderr)
        return EXIT_STOPPED
    except KeyboardInterrupt:
        steps = feed.steps if feed is not None else 0
        print("interrupted before any step converged: an empty history is written to "
              f"{out}/" if not steps else
              f"interrupted: the {steps} converged step(s) are written to {out}/",
              file=sys.stderr)
        return EXIT_STOPPED
    say(args, f"{args.model}: {len(sol.history)} converged step(s), final load factor "
         f"{sol.final_load_factor:.6g}, {sol.dofs} DOFs, {time.perf_counter() - t0:.1f} s")
    for lp in sol.limit_points:
        where = (f"in step {lp.step} (between load factors {lp.between[0]:.6g} and "
                 f"{lp.between[1]:.6g})" if lp.located_at is not None and lp.between
                 else f"at step {lp.step}")
        say(args, f"  {lp.kind} {where}: load factor {lp.load_factor:.6g}")
    growth = sol.extra.get("debond_growth")
    grown = isinstance(growth, dict) and "method" in growth
    if grown:
        say(args, growth_line(growth))
    lengths = grown and "tips" not in growth  # crack-length control: a path per length
    say(args, accuracy_line(f"{args.model} (the last length's path)" if lengths else args.model,
                            sol))
    say(args, f"results in {out}/ ({written_files(out)})")
    for w in sol.warnings if mpi_rank() == 0 else ():
        print(f"WARNING: {w}", file=sys.stderr)
    if not sol.converged:
        print(f"stopped before the target: {sol.message}", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK
