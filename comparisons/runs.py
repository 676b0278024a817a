"""Run a model on a scene, or reuse its result folder when that is still fresh.

A result folder is *fresh* when its three result files are all newer than the scene file and
than every Python source of the packages the model is built from. A model whose ``solve`` cannot
be imported, or whose solve raises, is recorded as a :class:`ModelRun` without a solution and
with the reason in words: the harness goes on with what it has.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from comparisons.reading import RESULT_FILES, ResultMissing, load_result
from comparisons.snapshots import SNAPSHOT_FILE, beam_solver_with_fields, save_snapshot
from sandwich.results import Solution, write_solution
from sandwich.scene import Scene

PROJECT_ROOT = Path(__file__).resolve().parents[1]
BEAM, REFERENCE = "beam", "2d"
MODELS = (BEAM, REFERENCE)
# model name -> (module providing solve(scene, progress=None, ...), packages its results depend on)
MODEL_SOURCES: dict[str, tuple[str, tuple[str, ...]]] = {
    BEAM: ("beam_element", ("beam_element", "sandwich")),
    REFERENCE: ("reference2d", ("reference2d", "meshes", "sandwich")),
}

Solver = Callable[..., Solution]


@dataclass(frozen=True)
class ProgressEvent:
    """What the harness is doing: which model, which phase, which step.

    ``phase`` is ``"start"``, ``"step"`` (a converged step), ``"done"``, ``"reused"``,
    ``"missing"`` or ``"failed"``.
    """

    model: str
    phase: str
    step: int | None = None
    load_factor: float | None = None
    probes: Mapping[str, float] | None = None
    message: str = ""


Progress = Callable[[ProgressEvent], None]


@dataclass
class ModelRun:
    """One model's outcome on one scene.

    ``origin`` is ``"run"`` (solved now), ``"reused"`` (read from a fresh folder), ``"missing"``
    (its solve is not importable) or ``"failed"`` (its solve raised). ``solution`` is ``None``
    exactly when ``origin`` is ``"missing"`` or ``"failed"``; ``reason`` then says why.
    """

    model: str
    folder: Path
    origin: str
    solution: Solution | None
    reason: str = ""
    seconds: float = 0.0


def result_folder(scene: Scene, model: str, results_root: Path) -> Path:
    """The default folder ``<results_root>/<scene>/<model>/`` of a model's results."""
    return Path(results_root) / scene.name / model


def newest_source_mtime(packages: tuple[str, ...], root: Path = PROJECT_ROOT) -> float:
    """Latest modification time of the ``*.py`` files of ``packages`` under ``root`` (0 if none)."""
    times = [p.stat().st_mtime for pkg in packages for p in (root / pkg).rglob("*.py")]
    return max(times, default=0.0)


def freshness(folder: Path, scene: Scene, packages: tuple[str, ...],
              root: Path = PROJECT_ROOT) -> tuple[bool, str]:
    """Whether ``folder`` holds results newer than the scene file and the model's sources.

    Returns
    -------
    (bool, str)
        The verdict and, when stale, the reason in words.
    """
    files = [folder / n for n in RESULT_FILES]
    if not all(f.is_file() for f in files):
        return False, f"{folder} has no complete result"
    if scene.source is None:
        return False, "the scene has no file to compare dates with"
    written = min(f.stat().st_mtime for f in files)
    if Path(scene.source).stat().st_mtime > written:
        return False, f"{scene.source} is newer than the results"
    if newest_source_mtime(packages, root) > written:
        return False, f"sources of {', '.join(packages)} are newer than the results"
    return True, "fresh"


def import_solver(model: str) -> Solver:
    """Import ``solve`` of ``model``; raise ``ImportError`` with a readable reason if absent."""
    module_name, _ = MODEL_SOURCES[model]
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:  # any failure to import is a missing model, said in words
        raise ImportError(f"model '{model}': cannot import {module_name} "
                          f"({type(exc).__name__}: {exc})") from exc
    solve = getattr(module, "solve", None)
    if not callable(solve):
        raise ImportError(f"model '{model}': {module_name} has no solve() yet")
    if model == BEAM:  # keep the section's 2D fields for the deformed pictures when offered
        return beam_solver_with_fields(module) or solve
    return solve


def obtain(scene: Scene, model: str, *, results_root: Path, reuse: bool = True,
           progress: Progress | None = None, solver: Solver | None = None,
           root: Path = PROJECT_ROOT) -> ModelRun:
    """Reuse a fresh result folder of ``model`` on ``scene``, or solve and write a new one.

    Parameters
    ----------
    scene
        The scene to solve.
    model
        ``"beam"`` or ``"2d"``.
    results_root
        Root of the result folders (``<root>/<scene>/<model>/``).
    reuse
        Reuse a fresh folder instead of solving again.
    progress
        Receives a :class:`ProgressEvent` per phase and per converged step.
    solver
        ``solve(scene, progress=...)`` to use instead of the model's own (tests, benchmarks).
    root
        Project root whose package sources decide freshness.
    """
    say = progress or (lambda event: None)
    folder = result_folder(scene, model, results_root)
    _, packages = MODEL_SOURCES[model]
    if reuse:
        fresh, _why = freshness(folder, scene, packages, root)
        if fresh:
            try:
                solution = load_result(folder)
            except (ResultMissing, ValueError, KeyError) as exc:
                say(ProgressEvent(model, "start", message=f"cannot reuse {folder}: {exc}"))
            else:
                say(ProgressEvent(model, "reused", message=str(folder)))
                return ModelRun(model, folder, "reused", solution)
    if solver is None:
        try:
            solver = import_solver(model)
        except ImportError as exc:
            say(ProgressEvent(model, "missing", message=str(exc)))
            return ModelRun(model, folder, "missing", None, reason=str(exc))

    def on_step(state: object) -> None:
        say(ProgressEvent(model, "step", step=int(state.step),  # type: ignore[attr-defined]
                          load_factor=float(state.load_factor),  # type: ignore[attr-defined]
                          probes=dict(state.probes)))  # type: ignore[attr-defined]

    say(ProgressEvent(model, "start", message=scene.name))
    t0 = time.perf_counter()
    try:
        solution = solver(scene, progress=on_step)
    except Exception as exc:  # a crashing model is reported, the comparison goes on
        reason = f"model '{model}' failed on {scene.name}: {type(exc).__name__}: {exc}"
        say(ProgressEvent(model, "failed", message=reason))
        return ModelRun(model, folder, "failed", None, reason=reason,
                        seconds=time.perf_counter() - t0)
    seconds = time.perf_counter() - t0
    snapshot = solution.extra.pop("field_snapshot", None)  # arrays: fields.npz, not summary.json
    write_solution(solution, folder)
    if snapshot is not None:
        save_snapshot(snapshot, folder)
    elif (folder / SNAPSHOT_FILE).exists():
        (folder / SNAPSHOT_FILE).unlink()  # a stale picture of an older run
    say(ProgressEvent(model, "done", step=len(solution.history),
                      load_factor=solution.final_load_factor, message=solution.message))
    return ModelRun(model, folder, "run", solution, seconds=seconds)


def text_progress(write: Callable[[str], object] = print) -> Progress:
    """A plain-text progress display: one line per phase, one per converged step."""

    def show(event: ProgressEvent) -> None:
        if event.phase == "step":
            probes = ", ".join(f"{k}={v:.4g}" for k, v in (event.probes or {}).items())
            write(f"[{event.model}] step {event.step}: λ={event.load_factor:.5g} {probes}")
        else:
            write(f"[{event.model}] {event.phase} {event.message}".rstrip())

    return show
