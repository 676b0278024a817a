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
import signal
import sys
import tempfile
import traceback
from pathlib import Path

from sandwich.cli.common import (
    EXIT_BAD_INPUT,
    EXIT_INTERNAL,
    EXIT_OK,
    EXIT_STOPPED,
    UsageError,
)
from sandwich.cli.compare_commands import DEMO_SCENE, cmd_compare, cmd_demo, cmd_gallery
from sandwich.cli.scene_commands import cmd_mesh, cmd_solve, cmd_validate
from sandwich.cli.study_command import cmd_study
from sandwich.models import MODELS
from sandwich.quiet_logs import hush_libraries, unhush_libraries
from sandwich.results import OutputError
from sandwich.scene import MESH_LEVELS, SceneError

__all__ = ["EXIT_BAD_INPUT", "EXIT_INTERNAL", "EXIT_OK", "EXIT_STOPPED", "EXAMPLES",
           "build_parser", "main"]

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


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return f"sandwich {version('sandwich-debond')}"
    except PackageNotFoundError:
        return "sandwich (not installed)"


def _resolution_options(p: argparse.ArgumentParser) -> None:
    """``--level``/``--refine`` (the 2D mesh) and ``--elements`` (the beam) of one command."""
    p.add_argument("--level", choices=MESH_LEVELS, help="2D mesh level (overrides the scene)")
    p.add_argument("--refine", type=int, metavar="N",
                   help="2D uniform refinements, 0-6, each halves every element size "
                        "(overrides the scene)")
    p.add_argument("--elements", type=int, metavar="N",
                   help="beam element count along the span, 2-200000 (overrides the scene's "
                        "[beam_model] elements)")


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
    _resolution_options(s)
    s.set_defaults(func=cmd_solve)

    c = sub.add_parser("compare", parents=[common],
                       help="run both models on a scene and overlay them")
    c.add_argument("scene", help="scene file (TOML)")
    c.add_argument("--out", help="folder of the comparison and, inside it, of both models' "
                                 "results (default results/<scene>/compare/, the models in "
                                 "results/<scene>/<model>/)")
    c.add_argument("--no-reuse", action="store_true",
                   help="solve both models again even if their results match")
    _resolution_options(c)
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
    d.add_argument("--out", help="folder of the comparison and, inside it, of both models' "
                                 "results (default results/<scene>/compare/)")
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
        # the FEniCSx stack's warnings and the JIT compiler's INFO lines are shown only with
        # --verbose (the 2D model's first run compiles its forms)
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
