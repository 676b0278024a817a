"""The ``sandwich`` command: validate | mesh | solve | compare | gallery | demo | study.

Every command refuses a bad scene, bad option or unusable output folder before any work (exit
code 2, one line per problem naming the file or option, the key and the reason), and so does
every command that solves or meshes for a run estimated not to fit in the memory available
(:mod:`sandwich.cli.memory_guard`). A solve that
stops before its target, or is interrupted (Ctrl-C, SIGTERM), keeps and writes every converged
step and exits with code 1 after saying where and why.

Exit codes: 0 done, 1 stopped before the target (converged steps written), 2 bad input,
3 internal error (details in a crash log whose path is printed).
"""

from __future__ import annotations

import argparse
import glob
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path
from types import SimpleNamespace

from sandwich.cli.memory_guard import check_memory
from sandwich.models import MODELS, PROJECT_ROOT, ModelRun, mpi_rank, run_model, with_options
from sandwich.quiet_logs import hush_libraries, unhush_libraries
from sandwich.results import OutputError, check_output_folder
from sandwich.scene import MESH_LEVELS, Scene, SceneError
from sandwich.scene_file import load_scene

EXIT_OK, EXIT_STOPPED, EXIT_BAD_INPUT, EXIT_INTERNAL = 0, 1, 2, 3
EXAMPLES = """units: N, mm, MPa (scene files); load factor λ multiplies every load's force

examples:
  sandwich validate scenes/*.toml
  sandwich solve scenes/paper-fig5-top-debond-40-load-top.toml --model beam --elements 480
  sandwich solve scenes/paper-fig5-top-debond-40-load-top.toml --model 2d --level coarse
  sandwich compare scenes/default.toml --out /tmp/cmp
  sandwich gallery --out /tmp/gallery
  sandwich study studies/shipped/fig5-knockdown.toml --workers 2

exit codes: 0 done, 1 stopped before the target or interrupted (converged steps written),
2 bad input (scene, option, output folder, or a run estimated not to fit in the memory
available; nothing solved), 3 internal error (crash log named)
"""
# Loggers of the FEniCSx stack: their warnings and the JIT compiler's INFO lines are shown only
# with --verbose (the 2D model's first run compiles its forms)
RESULTS = Path("results")
REFINE_RANGE = (0, 6)  # as the scene's [reference2d] refine
ELEMENTS_RANGE = (2, 200_000)  # as the scene's [beam_model] elements
WORKERS_MAX = 512


class UsageError(ValueError):
    """A command-line option that cannot be used: which option and why."""


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
    return RESULTS / scene.name / model


def _in_range(value: int | None, option: str, lo: int, hi: int) -> int | None:
    if value is not None and not lo <= value <= hi:
        raise UsageError(f"option {option}: must be between {lo} and {hi}, got {value}")
    return value


def _overridden(scene: Scene, model: str, args: argparse.Namespace) -> Scene:
    """``scene`` with the resolution options given on the command line applied to ``model``."""
    level = getattr(args, "level", None)
    refine = _in_range(getattr(args, "refine", None), "--refine", *REFINE_RANGE)
    elements = _in_range(getattr(args, "elements", None), "--elements", *ELEMENTS_RANGE)
    if model == "2d":
        if elements is not None:
            raise UsageError("option --elements: sets the beam's elements, not the 2D model's")
        if level == "explicit" and scene.reference2d.core_size is None:
            raise UsageError("option --level: 'explicit' needs [reference2d] core_size in the "
                             "scene")
        return with_options(scene, "2d", level=level, refine=refine)
    if level is not None or refine is not None:
        raise UsageError("options --level/--refine: set the 2D mesh, not the beam's elements")
    return with_options(scene, "beam", elements=elements)


CLI_KEYS = {"elements": "beam_model.elements", "refine": "reference2d.refine",
            "level": "reference2d.level"}  # option -> the scene key it overrides


def _guard(scenes: list[Scene], models: tuple[str, ...], args: argparse.Namespace, *,
           copies: int = 1, where: str | None = None, label: str = "") -> None:
    """Refuse before any work a run estimated not to fit in memory; warn when it is close."""
    given = {key: f"--{opt}" for opt, key in CLI_KEYS.items()
             if getattr(args, opt, None) is not None}
    problems = []
    for scene in scenes:
        for model in models:
            verdict = check_memory(scene, model, given, copies=copies, where=where,
                                   label=label)
            if verdict.refusal is not None:
                problems.append(verdict.refusal)
            elif verdict.warning is not None and mpi_rank() == 0:
                print(f"warning: {where or scene.source}: {verdict.warning}", file=sys.stderr)
    if problems:
        raise SceneError(problems)


def cmd_validate(args: argparse.Namespace) -> int:
    """Check scene files and say which are usable."""
    for s in _load(args.scenes):
        _say(args, f"ok: {s.source} ({s.name}: {len(s.debonds)} debond(s), "
             f"{len(s.supports)} support(s), {len(s.loads)} load(s))")
    return EXIT_OK


def cmd_mesh(args: argparse.Namespace) -> int:
    """Mesh a scene for the 2D reference and print a quality report."""
    (scene,) = _load([args.scene])
    scene = _overridden(scene, "2d", args)
    _guard([scene], ("mesh",), args)
    out = Path(args.out) if args.out else RESULTS / scene.name / "mesh"
    check_output_folder(out)
    from sandwich.meshes import build_mesh, quality_report, write_mesh

    mesh = build_mesh(scene)
    files = write_mesh(mesh, out, scene.name)
    _say(args, str(quality_report(mesh)))
    for kind, path in files.items():
        _say(args, f"wrote {kind}: {path}")
    return EXIT_OK


class _StepBar:
    """Feeds the runner's step events to a progress bar."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, event) -> None:
        if event.phase == "step":
            self.bar(event)
        elif event.phase == "note":  # the bar restarts with the path
            self.bar(SimpleNamespace(step=0, load_factor=0.0, probes={}, message=event.message))


LARGE_BEAM = 20_000  # beam elements above which a solve takes minutes and gigabytes


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

    (scene,) = _load([args.scene])
    scene = _overridden(scene, args.model, args)
    _guard([scene], (args.model,), args)
    out = Path(args.out) if args.out else default_out(scene, args.model)
    check_output_folder(out)
    for line in warnings_before_solve(scene, args.model):
        print(f"warning: {scene.source}: {line}", file=sys.stderr)
    t0 = time.perf_counter()
    quiet = args.quiet or mpi_rank() != 0
    try:
        with PathProgress(scene, f"{scene.name} [{args.model}]", quiet=quiet) as bar:
            sol = run_model(scene, args.model, out, progress=_StepBar(bar))
    except KeyboardInterrupt:
        print(f"interrupted: every converged step is written to {out}/", file=sys.stderr)
        return EXIT_STOPPED
    _say(args, f"{args.model}: {len(sol.history)} converged step(s), final load factor "
         f"{sol.final_load_factor:.6g}, {sol.dofs} DOFs, {time.perf_counter() - t0:.1f} s")
    for lp in sol.limit_points:
        where = (f"in step {lp.step} (between load factors {lp.between[0]:.6g} and "
                 f"{lp.between[1]:.6g})" if lp.located_at is not None and lp.between
                 else f"at step {lp.step}")
        _say(args, f"  {lp.kind} {where}: load factor {lp.load_factor:.6g}")
    _say(args, f"results in {out}/ (history.csv, profiles.csv, summary.json)")
    if not sol.converged:
        print(f"stopped before the target: {sol.message}", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK


def _report_runs(args: argparse.Namespace, runs: dict[str, ModelRun]) -> None:
    for model, run in runs.items():
        if run.stale:
            _say(args, f"{model}: {run.stale}; solved again")
        elif run.origin == "reused":
            _say(args, f"{model}: reused {run.folder}/ (same scene, resolution and code)")


def _compare_and_report(args: argparse.Namespace, scene: Scene, out: Path,
                        results_root: Path | None) -> int:
    """Run (or reuse) both models on ``scene``, write the comparison and summarise it."""
    from sandwich.compare import compare
    from sandwich.models import text_progress

    _guard([scene], tuple(MODELS), args)
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
    curve = cmp.metrics.curve("load_factor")
    if curve is not None and curve.l2_relative is not None:
        _say(args, f"load-deflection curve, beam vs 2D: L2 error {100 * curve.l2_relative:.2f} %, "
             f"max {100 * curve.max_relative:.2f} % over the common range")
    for g in cmp.metrics.releases:  # energy release rate per debond tip (G_<tip>.png)
        if g.ratio_at_end is not None and g.l2_relative is not None:
            hi = g.common_range[1] if g.common_range else 0.0
            _say(args, f"G at debond tip {g.tip}, beam vs 2D: L2 error "
                 f"{100 * g.l2_relative:.1f} %, beam/2D {g.ratio_at_end:.3f} at {g.abscissa} = "
                 f"{hi:.4g}")
    if cmp.metrics.wall_ratio is not None:
        _say(args, f"cost: 2D took {cmp.metrics.wall_ratio:.1f}x the beam's wall time, "
             f"{cmp.metrics.dofs_ratio:.1f}x its DOFs")
    _say(args, f"pictures, CSVs and metrics.json: {out.resolve()}/")
    return EXIT_OK if not cmp.missing else EXIT_STOPPED


def cmd_compare(args: argparse.Namespace) -> int:
    """Run both models on a scene and overlay them."""
    (scene,) = _load([args.scene])
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
    scenes = _load(paths)
    _guard(scenes, tuple(MODELS), args)
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
    _say(args, f"gallery report: {g.report.resolve()}")
    return EXIT_OK


def cmd_demo(args: argparse.Namespace) -> int:
    """The README's first command: both models on the default scene, and where the pictures are."""
    path = Path(args.scene)
    if args.scene == DEMO_SCENE and not path.is_file():  # run from outside the repository
        path = PROJECT_ROOT / DEMO_SCENE
    (scene,) = _load([str(path)])
    return _compare_and_report(args, scene, RESULTS / scene.name / "compare", RESULTS)


DEMO_SCENE = "scenes/default.toml"


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return f"sandwich {version('sandwich-debond')}"
    except PackageNotFoundError:
        return "sandwich (not installed)"


def cmd_study(args: argparse.Namespace) -> int:
    """Run (or resume) a design study: every case, the 2D spot checks, table, plots."""
    from sandwich.studies.study import run_study
    from sandwich.studies.study_file import load_study

    study = load_study(args.study)
    if args.workers is not None and not 1 <= args.workers <= WORKERS_MAX:
        raise UsageError(f"option --workers: must be between 1 and {WORKERS_MAX}, "
                         f"got {args.workers}")
    if args.scheduler is None:  # a cluster's memory is not this machine's to judge
        _guard_study(study, args.workers or 2, args)
    out = Path(args.out) if args.out else RESULTS / "studies" / study.name
    check_output_folder(out)
    _say(args, f"{study.name}: {len(study.cases)} case(s), model {study.model}"
         + (f", {study.check} 2D spot check(s)" if study.check else "") + f"; results in {out}/")
    result = run_study(study, out, workers=args.workers or 2, scheduler=args.scheduler,
                       say=lambda m: _say(args, m), quiet=args.quiet)
    _say(args, f"table: {result.table}; summary: {result.summary}"
         + "".join(f"; plot: {p}" for p in result.plots))
    if result.interrupted:
        print("interrupted: the finished cases are kept; run the same command to resume",
              file=sys.stderr)
        return EXIT_STOPPED
    failed = sum(r.get("status") == "failed" for r in result.rows)
    if failed:
        print(f"{failed} case(s) failed (reasons in {result.table})", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK


STUDY_2D_SAMPLE = 400


def _guard_study(study, workers: int, args: argparse.Namespace) -> None:
    """The memory guard on a study's largest case, ``workers`` of them at once (and its checks)."""
    from sandwich.models import memory

    whats = (study.model,) + (("2d",) if study.check and study.model != "2d" else ())
    for what in whats:
        # every case's beam estimate is arithmetic; a 2D one lays the mesh out (~5 ms): at most
        # STUDY_2D_SAMPLE cases evenly spread are laid out
        cases = study.cases if what == "beam" else \
            study.cases[::max(1, len(study.cases) // STUDY_2D_SAMPLE)]
        try:
            if what == "2d" and study.max_cells is not None:  # larger meshes are not run
                cases = [c for c in cases if memory.mesh_size(c.scene)[0] <= study.max_cells]
            sizes = [(memory.estimate(c.scene, what).peak_bytes, c) for c in cases]
        except (ValueError, KeyError):  # a layout the mesher refuses says why when it runs
            continue
        if not sizes:
            continue
        _, worst = max(sizes, key=lambda t: t[0])
        copies = min(workers, len(study.cases) if what == study.model else study.check)
        _guard([worst.scene], (what,), args, copies=copies, where=str(study.source),
               label=f"case {worst.index}" + (" (its 2D check)" if what != study.model else ""))


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``sandwich`` command."""
    p = argparse.ArgumentParser(
        prog="sandwich", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Sandwich beams with face/core debonds: the paper's beam element and a 2D "
                    "plane-stress reference on one scene file.", epilog=EXAMPLES)
    p.add_argument("--version", action="version", version=_version())
    p.add_argument("--quiet", action="store_true", help="print only errors, no progress bar")
    p.add_argument("--verbose", action="store_true",
                   help="also show the FEniCSx stack's warnings and compiler logs")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS,
                        help="print only errors, no progress bar")
    common.add_argument("--verbose", action="store_true", default=argparse.SUPPRESS,
                        help="also show the FEniCSx stack's warnings and compiler logs")
    sub = p.add_subparsers(dest="command", required=True)

    v = sub.add_parser("validate", parents=[common], help="check scene files")
    v.add_argument("scenes", nargs="+", help="scene files (TOML)")
    v.set_defaults(func=cmd_validate)

    m = sub.add_parser("mesh", parents=[common],
                       help="mesh a scene for the 2D reference (.msh, .xdmf)")
    m.add_argument("scene", help="scene file (TOML)")
    m.add_argument("--level", choices=MESH_LEVELS, help="2D mesh level (overrides the scene)")
    m.add_argument("--refine", type=int, metavar="N",
                   help="uniform halvings of every element size, 0-6 (overrides the scene)")
    m.add_argument("--out", help="folder of the mesh files (default results/<scene>/mesh/)")
    m.set_defaults(func=cmd_mesh)

    s = sub.add_parser("solve", parents=[common], help="solve a scene with one model")
    s.add_argument("scene", help="scene file (TOML)")
    s.add_argument("--model", choices=tuple(MODELS), required=True,
                   help="beam: the sandwich beam element (the paper's, refined through the "
                   "thickness); 2d: the plane-stress reference (FEniCSx)")
    s.add_argument("--out", help="result folder (default results/<scene>/<model>/)")
    s.add_argument("--level", choices=MESH_LEVELS, help="2D mesh level (overrides the scene)")
    s.add_argument("--refine", type=int, metavar="N",
                   help="2D uniform refinements, 0-6, each halves every element size "
                        "(overrides the scene)")
    s.add_argument("--elements", type=int, metavar="N",
                   help="beam element count along the span, 2-200000 (overrides the scene's "
                        "[beam_model] elements)")
    s.set_defaults(func=cmd_solve)

    c = sub.add_parser("compare", parents=[common],
                       help="run both models on a scene and overlay them")
    c.add_argument("scene", help="scene file (TOML)")
    c.add_argument("--out", help="folder of the comparison and, inside it, of both models' "
                                 "results (default results/<scene>/compare/, the models in "
                                 "results/<scene>/<model>/)")
    c.add_argument("--no-reuse", action="store_true",
                   help="solve both models again even if their results match")
    c.set_defaults(func=cmd_compare)

    g = sub.add_parser("gallery", parents=[common],
                       help="run every paper-like scene and write a report")
    g.add_argument("--scenes", default="scenes/paper-*.toml", help="glob of scene files")
    g.add_argument("--out", help="report folder, with every scene's comparison and results "
                                 "(default results/gallery/)")
    g.set_defaults(func=cmd_gallery)

    d = sub.add_parser("demo", parents=[common], help="run the default scene end to end")
    d.add_argument("scene", nargs="?", default=DEMO_SCENE,
                   help=f"scene file (default {DEMO_SCENE}, also from outside the checkout)")
    d.set_defaults(func=cmd_demo)

    st = sub.add_parser("study", parents=[common],
                        help="sweep a scene over its parameters (a study file), in parallel")
    st.add_argument("study", help="study file (TOML, docs/studies.md)")
    st.add_argument("--out", help="study folder: cases, table, plots (default "
                                  "results/studies/<study>/); a rerun resumes it")
    st.add_argument("--workers", type=int, metavar="N",
                    help="local worker processes (default 2); ignored with --scheduler")
    st.add_argument("--scheduler", metavar="ADDRESS",
                    help="a Dask distributed scheduler (tcp://host:8786) to run the cases on")
    st.set_defaults(func=cmd_study)
    return p


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def _crash_log(args: argparse.Namespace, text: str) -> str:
    """Write the trace into the output folder, else a temporary file; never raise."""
    candidates = []
    if getattr(args, "out", None):
        candidates.append(Path(args.out) / "sandwich-crash.log")
    candidates.append(None)
    for path in candidates:
        try:
            if path is None:
                fd, name = tempfile.mkstemp(prefix="sandwich-crash-", suffix=".log")
                with open(fd, "w") as fh:
                    fh.write(text)
                return name
            if path.parent.is_dir():
                path.write_text(text)
                return str(path)
        except OSError:
            continue
    return "(no crash log could be written)"


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "verbose", False):
        unhush_libraries()
        hush_libraries()
    try:
        previous = signal.signal(signal.SIGTERM, _interrupt)
    except ValueError:  # not the main thread (tests driving main in a thread)
        previous = None
    try:
        return args.func(args)
    except SceneError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        return EXIT_BAD_INPUT
    except (UsageError, OutputError) as exc:
        print(f"sandwich {args.command}: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_STOPPED
    except Exception as exc:  # a bug, not bad input: say so plainly, keep the trace in a file
        log = _crash_log(args, traceback.format_exc())
        print(f"sandwich: internal error ({type(exc).__name__}: {exc}); details in {log}",
              file=sys.stderr)
        return EXIT_INTERNAL
    finally:
        unhush_libraries()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
