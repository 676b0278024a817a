"""The ``sandwich`` command: validate | mesh | solve | compare | gallery | demo.

Every command refuses a bad scene before any work (exit code 2, one line per problem naming the
file, the key and the reason). A solve that stops before its target keeps and writes every
converged step and exits with code 1 after saying where and why.
"""

from __future__ import annotations

import argparse
import glob
import os
import sys
import time
import traceback
from pathlib import Path

from sandwich.scene import Scene, SceneError, load_scene

EXIT_OK, EXIT_STOPPED, EXIT_BAD_INPUT, EXIT_INTERNAL = 0, 1, 2, 3
MODELS = ("beam", "2d")


def _say(args: argparse.Namespace, msg: str) -> None:
    if not getattr(args, "quiet", False) and mpi_rank() == 0:
        print(msg, flush=True)


def _load(paths: list[str]) -> list[Scene]:
    """Load every scene or raise one SceneError carrying all their problems."""
    scenes, problems = [], []
    for p in paths:
        try:
            scenes.append(load_scene(p))
        except SceneError as exc:
            problems.extend(exc.problems)
    if problems:
        raise SceneError(problems)
    return scenes


def default_out(scene: Scene, model: str) -> Path:
    """The default result folder ``results/<scene>/<model>/``."""
    return Path("results") / scene.name / model


def cmd_validate(args: argparse.Namespace) -> int:
    """Check scene files and say which are usable."""
    for s in _load(args.scenes):
        _say(args, f"ok: {s.source} ({s.name}: {len(s.debonds)} debond(s), "
             f"{len(s.supports)} support(s), {len(s.loads)} load(s))")
    return EXIT_OK


def cmd_mesh(args: argparse.Namespace) -> int:
    """Mesh a scene for the 2D reference and print a quality report."""
    from meshes import build_mesh, quality_report, write_mesh

    (scene,) = _load([args.scene])
    out = Path(args.out) if args.out else Path("results") / scene.name / "mesh"
    mesh = build_mesh(scene, level=args.level, refine=args.refine)
    files = write_mesh(mesh, out, scene.name)
    _say(args, str(quality_report(mesh)))
    for kind, path in files.items():
        _say(args, f"wrote {kind}: {path}")
    return EXIT_OK


def mpi_rank() -> int:
    """Rank of this process under mpirun (0 when run alone), from the launcher's environment."""
    for var in ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"):
        if var in os.environ:
            return int(os.environ[var])
    return 0


def run_model(scene: Scene, model: str, out: Path, *, quiet: bool = False,
              level: str | None = None, refine: int | None = None):
    """Solve ``scene`` with ``model`` and write its result files into ``out`` (rank 0 only)."""
    from sandwich.progress import PathProgress
    from sandwich.results import write_solution

    quiet = quiet or mpi_rank() != 0
    with PathProgress(scene, f"{scene.name} [{model}]", quiet=quiet) as progress:
        if model == "beam":
            from beam_element import solve
            solution = solve(scene, progress=progress)
        else:
            from reference2d import solve
            solution = solve(scene, progress=progress, level=level, refine=refine)
    if mpi_rank() == 0:
        write_solution(solution, out)
    return solution


def cmd_solve(args: argparse.Namespace) -> int:
    """Solve one scene with one model."""
    (scene,) = _load([args.scene])
    out = Path(args.out) if args.out else default_out(scene, args.model)
    t0 = time.perf_counter()
    sol = run_model(scene, args.model, out, quiet=args.quiet, level=args.level,
                    refine=args.refine)
    _say(args, f"{args.model}: {len(sol.history)} converged step(s), final load factor "
         f"{sol.final_load_factor:.6g}, {sol.dofs} DOFs, {time.perf_counter() - t0:.1f} s")
    for lp in sol.limit_points:
        _say(args, f"  {lp.kind} at step {lp.step}: load factor {lp.load_factor:.6g}")
    _say(args, f"results in {out}/ (history.csv, profiles.csv, summary.json)")
    if not sol.converged:
        print(f"stopped before the target: {sol.message}", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK


def _compare_and_report(args: argparse.Namespace, scene: Scene, out: Path, reuse: bool) -> int:
    """Run (or reuse) both models on ``scene``, write the comparison and summarise it."""
    from comparisons import compare, text_progress

    progress = None if args.quiet else text_progress()
    cmp = compare(scene, out, reuse=reuse, progress=progress)
    for model, reason in cmp.missing.items():
        print(f"{model}: no result ({reason})", file=sys.stderr)
    curve = cmp.metrics.curve("load_factor")
    if curve is not None and curve.l2_relative is not None:
        _say(args, f"load-deflection curve, beam vs 2D: L2 error {100 * curve.l2_relative:.2f} %, "
             f"max {100 * curve.max_relative:.2f} % over the common range")
    if cmp.metrics.wall_ratio is not None:
        _say(args, f"cost: 2D took {cmp.metrics.wall_ratio:.1f}x the beam's wall time, "
             f"{cmp.metrics.dofs_ratio:.1f}x its DOFs")
    _say(args, f"pictures, CSVs and metrics.json: {out.resolve()}/")
    return EXIT_OK if not cmp.missing else EXIT_STOPPED


def cmd_compare(args: argparse.Namespace) -> int:
    """Run both models on a scene and overlay them."""
    (scene,) = _load([args.scene])
    out = Path(args.out) if args.out else Path("results") / scene.name / "compare"
    return _compare_and_report(args, scene, out, reuse=not args.no_reuse)


def cmd_gallery(args: argparse.Namespace) -> int:
    """Run every shipped paper-like scene and write the report."""
    from comparisons import gallery, text_progress

    paths = sorted(glob.glob(args.scenes))
    if not paths:
        print(f"gallery: no scene matches {args.scenes}", file=sys.stderr)
        return EXIT_BAD_INPUT
    scenes = _load(paths)
    out = Path(args.out) if args.out else Path("results") / "gallery"
    gallery(scenes, out, progress=None if args.quiet else text_progress())
    _say(args, f"gallery report: {(out / 'report.md').resolve()}")
    return EXIT_OK


def cmd_demo(args: argparse.Namespace) -> int:
    """The README's first command: both models on the default scene, and where the pictures are."""
    (scene,) = _load([args.scene])
    out = Path("results") / scene.name / "compare"
    return _compare_and_report(args, scene, out, reuse=True)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``sandwich`` command."""
    p = argparse.ArgumentParser(prog="sandwich", description=__doc__.splitlines()[0])
    p.add_argument("--quiet", action="store_true", help="print only errors, no progress bar")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS,
                        help="print only errors, no progress bar")
    sub = p.add_subparsers(dest="command", required=True)

    v = sub.add_parser("validate", parents=[common], help="check scene files")
    v.add_argument("scenes", nargs="+")
    v.set_defaults(func=cmd_validate)

    m = sub.add_parser("mesh", parents=[common],
                       help="mesh a scene for the 2D reference (.msh, .xdmf)")
    m.add_argument("scene")
    m.add_argument("--level", choices=("coarse", "medium", "fine", "explicit"))
    m.add_argument("--refine", type=int)
    m.add_argument("--out")
    m.set_defaults(func=cmd_mesh)

    s = sub.add_parser("solve", parents=[common], help="solve a scene with one model")
    s.add_argument("scene")
    s.add_argument("--model", choices=MODELS, required=True)
    s.add_argument("--out", help="result folder (default results/<scene>/<model>/)")
    s.add_argument("--level", choices=("coarse", "medium", "fine", "explicit"),
                   help="2D mesh level (overrides the scene)")
    s.add_argument("--refine", type=int, help="2D uniform refinements (overrides the scene)")
    s.set_defaults(func=cmd_solve)

    c = sub.add_parser("compare", parents=[common],
                       help="run both models on a scene and overlay them")
    c.add_argument("scene")
    c.add_argument("--out")
    c.add_argument("--no-reuse", action="store_true", help="re-run models even if fresh")
    c.set_defaults(func=cmd_compare)

    g = sub.add_parser("gallery", parents=[common],
                       help="run every paper-like scene and write a report")
    g.add_argument("--scenes", default="scenes/paper-*.toml")
    g.add_argument("--out")
    g.set_defaults(func=cmd_gallery)

    d = sub.add_parser("demo", parents=[common], help="run the default scene end to end")
    d.add_argument("scene", nargs="?", default="scenes/default.toml")
    d.set_defaults(func=cmd_demo)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except SceneError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_STOPPED
    except Exception as exc:  # a bug, not bad input: say so plainly, keep the trace in a file
        log = Path(".sandwich-crash.log")
        log.write_text(traceback.format_exc())
        print(f"sandwich: internal error ({type(exc).__name__}: {exc}); details in {log}",
              file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
