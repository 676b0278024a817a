"""The commands that run both models and compare them: ``compare``, ``gallery``, ``demo``."""

from __future__ import annotations

import argparse
import glob
import sys
from pathlib import Path

from sandwich.cli.common import (
    EXIT_BAD_INPUT,
    EXIT_OK,
    EXIT_STOPPED,
    RESULTS,
    accuracy_line,
    guard_memory,
    load_scenes,
    overridden_both,
    say,
)
from sandwich.models import MODELS, PROJECT_ROOT, ModelRun
from sandwich.results import check_output_folder
from sandwich.scene import Scene

__all__ = ["DEMO_SCENE", "cmd_compare", "cmd_demo", "cmd_gallery"]

DEMO_SCENE = "scenes/default.toml"


def _report_runs(args: argparse.Namespace, runs: dict[str, ModelRun]) -> None:
    for model, run in runs.items():
        if run.stale:
            say(args, f"{model}: {run.stale}; solved again")
        elif run.origin == "reused":
            say(args, f"{model}: reused {run.folder}/ (same scene, resolution and code)")


def _compare_and_report(args: argparse.Namespace, scene: Scene, out: Path,
                        results_root: Path | None) -> int:
    """Run (or reuse) both models on ``scene``, write the comparison and summarise it."""
    from sandwich.compare import compare
    from sandwich.compare.compare import total_force
    from sandwich.compare.metrics import critical_lines
    from sandwich.models import text_progress

    scene = overridden_both(scene, args)

    guard_memory([scene], tuple(MODELS), args)
    check_output_folder(out)
    progress = None if args.quiet else text_progress()
    try:
        cmp = compare(scene, out, reuse=not getattr(args, "no_reuse", False), progress=progress,
                      results_root=results_root)
    except KeyboardInterrupt:
        print("interrupted: the converged steps of the model being solved are written to its "
              "result folder", file=sys.stderr)
        return EXIT_STOPPED
    _report_runs(args, cmp.runs)
    for model, reason in cmp.missing.items():
        print(f"{model}: no result ({reason})", file=sys.stderr)
    for model, sol in cmp.solutions.items():
        say(args, accuracy_line(model, sol))
        for w in sol.warnings:
            print(f"WARNING ({model}): {w}", file=sys.stderr)
    for line in critical_lines(cmp.metrics, total_force(scene)):
        say(args, line)
    curve = cmp.metrics.curve("load_factor")
    if curve is not None and curve.l2_relative is not None:
        say(args, f"load-deflection curve, beam vs 2D: L2 error {100 * curve.l2_relative:.2f} %, "
             f"max {100 * curve.max_relative:.2f} % over the common range")
    for g in cmp.metrics.releases:  # energy release rate per debond tip (G_<tip>.png)
        if g.ratio_at_end is not None and g.l2_relative is not None:
            hi = g.common_range[1] if g.common_range else 0.0
            say(args, f"G at debond tip {g.tip}, beam vs 2D: L2 error "
                 f"{100 * g.l2_relative:.1f} %, beam/2D {g.ratio_at_end:.3f} at {g.abscissa} = "
                 f"{hi:.4g}")
    if cmp.metrics.wall_ratio is not None:
        say(args, f"cost: 2D took {cmp.metrics.wall_ratio:.1f}x the beam's wall time, "
             f"{cmp.metrics.dofs_ratio:.1f}x its DOFs")
    say(args, f"pictures, CSVs and metrics.json: {out.resolve()}/")
    return EXIT_OK if not cmp.missing else EXIT_STOPPED


def cmd_compare(args: argparse.Namespace) -> int:
    """Run both models on a scene and overlay them."""
    (scene,) = load_scenes([args.scene])
    if args.out:  # everything under --out: the comparison and the models' folders in it
        return _compare_and_report(args, scene, Path(args.out), None)
    return _compare_and_report(args, scene, RESULTS / scene.name / "compare", RESULTS)


def cmd_gallery(args: argparse.Namespace) -> int:
    """Run every shipped paper-like scene and write the report."""
    from sandwich.compare import gallery
    from sandwich.models import text_progress

    paths = sorted(glob.glob(args.scenes))
    if not paths:
        print(f"gallery: no scene matches {args.scenes}", file=sys.stderr)
        return EXIT_BAD_INPUT
    scenes = load_scenes(paths)
    guard_memory(scenes, tuple(MODELS), args)
    out = Path(args.out) if args.out else RESULTS / "gallery"
    check_output_folder(out)
    try:
        g = gallery(scenes, out, progress=None if args.quiet else text_progress(),
                    results_root=None if args.out else RESULTS)
    except KeyboardInterrupt:
        print("interrupted: the scenes done so far are written", file=sys.stderr)
        return EXIT_STOPPED
    for cmp in g.comparisons.values():
        _report_runs(args, cmp.runs)
    say(args, f"gallery report: {g.report.resolve()}")
    return EXIT_OK


def cmd_demo(args: argparse.Namespace) -> int:
    """The README's first command: both models on the default scene, and where the pictures are."""
    path = Path(args.scene)
    if args.scene == DEMO_SCENE and not path.is_file():  # run from outside the repository
        path = PROJECT_ROOT / DEMO_SCENE
    (scene,) = load_scenes([str(path)])
    if args.out:
        return _compare_and_report(args, scene, Path(args.out), None)
    return _compare_and_report(args, scene, RESULTS / scene.name / "compare", RESULTS)
