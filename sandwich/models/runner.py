"""The one runner: solve a scene with a registered model and write its result folder, or reuse it.

:func:`obtain` reuses a folder only when the :class:`~sandwich.results.RunIdentity` recorded in
its ``summary.json`` matches the one asked now exactly (model, scene content, the model's
options and resolution, code); otherwise it solves again and says why (a ``"stale"`` event).
:func:`run_model` always solves. Both write the result set as a whole (rank 0 under MPI) and
record the identity in ``summary.json``.

An interrupt (Ctrl-C, or SIGTERM turned into one by the command line) during a solve still
writes every converged state that the model reported (history only, ``converged = false``, the
message says so) before the interrupt is raised again.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from sandwich.fracture import growth_onset, ill_conditioned_releases, missing_releases
from sandwich.growth import (
    cohesive_growing,
    cohesive_summary,
    final_scene,
    grow,
    growing,
    growth_summary,
    onset_rows,
)
from sandwich.models.registry import get_model
from sandwich.results import (
    InterruptedSolve,
    OutputError,
    PathNote,
    ProgressItem,
    RunIdentity,
    Solution,
    StepRecord,
    check_output_folder,
    load_result,
    write_solution,
)
from sandwich.results.identity import IDENTITY_KEY
from sandwich.scene import Scene

PROJECT_ROOT = Path(__file__).resolve().parents[2]
Solver = Callable[..., Solution]


@dataclass(frozen=True)
class ProgressEvent:
    """What the runner is doing: which model, which phase, which step.

    ``phase`` is ``"start"``, ``"step"`` (a converged step), ``"note"`` (what a model says
    while solving, e.g. that it reruns the path), ``"done"``, ``"reused"``, ``"stale"`` (a
    result folder exists but is not reused; ``message`` says why), ``"missing"``, ``"failed"``
    or ``"interrupted"``.
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

    ``origin`` is ``"run"`` (solved now), ``"reused"`` (read from a folder of the same identity),
    ``"missing"`` (the model cannot be imported) or ``"failed"`` (its solve raised).
    ``solution`` is ``None`` exactly when ``origin`` is ``"missing"`` or ``"failed"``; ``reason``
    then says why. ``stale`` is why an existing folder was not reused (empty if none was there).
    """

    model: str
    folder: Path
    origin: str
    solution: Solution | None
    reason: str = ""
    seconds: float = 0.0
    stale: str = ""


def mpi_rank() -> int:
    """Rank of this process under mpirun (0 when run alone), from the launcher's environment."""
    for var in ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"):
        if var in os.environ:
            return int(os.environ[var])
    return 0


def stored_identity(folder: Path) -> RunIdentity | None:
    """The identity recorded in ``folder/summary.json``.

    ``None`` if none can be read, or if it belongs to an interrupted run (never reused).
    """
    try:
        data = json.loads((Path(folder) / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get(IDENTITY_KEY), dict):
        return None
    if data[IDENTITY_KEY].get("complete", True) is False:
        return None
    return RunIdentity.from_dict(data[IDENTITY_KEY])


def _partial(model: str, scene: Scene, states: list[StepRecord], seconds: float) -> Solution:
    """The solution of an interrupted run: the streamed steps with the columns they carry."""
    last = f" after step {states[-1].step}" if states else " before any step converged"
    solution = Solution(model, scene.name, list(states), [], False,
                        f"interrupted{last}: the converged steps are kept (no profiles)", [],
                        seconds, 0)
    if growing(scene):  # the onsets of the lengths grown so far
        solution.extra["debond_growth"] = growth_summary(
            scene, solution.history, len(onset_rows(solution.history)) - 1,
            f"interrupted{last}")
    elif cohesive_growing(scene):  # the tips the kept steps reached
        solution.extra["debond_growth"] = cohesive_summary(scene, solution.history)[0]
    elif onset := growth_onset(scene, solution.history):  # debonds with a toughness
        solution.extra["debond_growth"] = onset
    empty = missing_releases(solution.history)
    if empty:
        solution.extra["G_warning"] = (f"G could not be evaluated at {empty} (cells left empty)")
    return solution


def run_model(scene: Scene, model: str, folder: Path, *, progress: Progress | None = None,
              solver: Solver | None = None, root: Path = PROJECT_ROOT) -> Solution:
    """Solve ``scene`` with ``model`` and write the result set into ``folder``.

    Parameters
    ----------
    scene
        The scene, with any override already applied (:func:`sandwich.models.with_options`).
    model
        A registry name (``"beam"``, ``"2d"``).
    folder
        The result folder; checked before the solve (:func:`~sandwich.results.check_output_folder`).
    progress
        Receives a :class:`ProgressEvent` per converged step and at the end.
    solver
        ``solve(scene, progress=None)`` to use instead of the registered one (tests, benchmarks);
        the identity recorded is still the registered model's.
    root
        Project root whose package sources make the code digest.

    Raises
    ------
    KeyboardInterrupt
        After writing the converged steps reported so far.
    """
    spec = get_model(model)
    say = progress or (lambda event: None)
    folder = Path(folder)
    check_output_folder(folder)
    identity = spec.identity(scene, root)
    model_solve = solver or spec.solve
    if growing(scene):  # debonds grown by crack-length control: a path per length

        def solve(scene: Scene, progress=None) -> Solution:
            return grow(scene, model_solve, progress)
    else:
        solve = model_solve
    streamed: list[StepRecord] = []

    def on_state(item: ProgressItem) -> None:
        if isinstance(item, PathNote):
            if item.restart:  # the path starts again: its states supersede these
                streamed.clear()
            say(ProgressEvent(model, "note", message=item.message))
            return
        rec = StepRecord.of(item)  # the state's columns kept, e.g. G at the tips
        while streamed and streamed[-1].step >= rec.step:  # re-converged at raised levels
            streamed.pop()
        streamed.append(rec)
        say(ProgressEvent(model, "step", step=rec.step, load_factor=rec.load_factor,
                          probes=rec.probes))

    t0 = time.perf_counter()
    try:
        solution = solve(scene, progress=on_state)
    except InterruptedSolve as exc:  # the model kept a whole answer: written, never reused
        kept = exc.solution
        kept.extra[IDENTITY_KEY] = {**identity.to_dict(), "complete": False}
        if mpi_rank() == 0:
            _write(kept, folder, scene)
        say(ProgressEvent(model, "interrupted", step=len(kept.history),
                          message="; ".join([kept.message, *kept.warnings])))
        raise
    except KeyboardInterrupt:
        partial = _partial(model, scene, streamed, time.perf_counter() - t0)
        partial.extra[IDENTITY_KEY] = {**identity.to_dict(), "complete": False}
        if mpi_rank() == 0:
            _write(partial, folder, scene)
        say(ProgressEvent(model, "interrupted", step=len(streamed), message=partial.message))
        raise
    near = ill_conditioned_releases(solution.history, solution.limit_points)
    if near:  # either model: G close below a critical load
        solution.warnings.append(near)
    solution.extra[IDENTITY_KEY] = identity.to_dict()
    if mpi_rank() == 0:  # a grown debond's tips are where its growth left them
        _write(solution, folder, final_scene(scene, solution) if growing(scene) else scene)
    return solution


def _write(solution: Solution, folder: Path, scene: Scene | None = None) -> None:
    """Write the result set; a failing write (a full disk) is an :class:`OutputError`."""
    try:
        write_solution(solution, folder, scene)
    except OutputError:
        raise
    except OSError as exc:
        raise OutputError(f"{folder}: the result set could not be written "
                          f"({exc.strerror or exc}); a previous result there is unchanged"
                          ) from exc


def obtain(scene: Scene, model: str, folder: Path, *, reuse: bool = True,
           progress: Progress | None = None, solver: Solver | None = None,
           root: Path = PROJECT_ROOT) -> ModelRun:
    """Reuse ``folder`` when it holds this very result, or solve and write it.

    Never raises for a model's failure: a model that cannot be imported or raises is a
    :class:`ModelRun` without solution, with the reason in words.

    ``scene``, ``model``, ``progress``, ``solver``, ``root``: see :func:`run_model`; ``reuse``
    False always solves.
    """
    say = progress or (lambda event: None)
    folder = Path(folder)
    spec = get_model(model)
    stale = ""
    if reuse and (folder / "summary.json").is_file():
        wanted = spec.identity(scene, root)
        stored = stored_identity(folder)
        why = wanted.differences(stored)
        if not why:
            try:
                solution = load_result(folder)
            except (OSError, ValueError, KeyError) as exc:
                why = [f"it cannot be read ({exc})"]
            else:
                say(ProgressEvent(model, "reused", message=str(folder)))
                return ModelRun(model, folder, "reused", solution)
        stale = f"not reusing {folder}: " + "; ".join(why)
        say(ProgressEvent(model, "stale", message=stale))
    say(ProgressEvent(model, "start", message=scene.name))
    t0 = time.perf_counter()
    try:
        solution = run_model(scene, model, folder, progress=say, solver=solver, root=root)
    except ImportError as exc:
        reason = f"model '{model}': cannot import its package ({type(exc).__name__}: {exc})"
        say(ProgressEvent(model, "missing", message=reason))
        return ModelRun(model, folder, "missing", None, reason=reason, stale=stale)
    except (KeyboardInterrupt, OutputError):
        raise
    except Exception as exc:  # a crashing model is reported, the comparison goes on
        reason = f"model '{model}' failed on {scene.name}: {type(exc).__name__}: {exc}"
        say(ProgressEvent(model, "failed", message=reason))
        return ModelRun(model, folder, "failed", None, reason=reason,
                        seconds=time.perf_counter() - t0, stale=stale)
    say(ProgressEvent(model, "done", step=len(solution.history),
                      load_factor=solution.final_load_factor, message=solution.message))
    return ModelRun(model, folder, "run", solution, seconds=time.perf_counter() - t0,
                    stale=stale)


def text_progress(write: Callable[[str], object] = print) -> Progress:
    """A plain-text progress display: one line per phase, one per converged step."""

    def show(event: ProgressEvent) -> None:
        if event.phase == "step":
            probes = ", ".join(f"{k}={v:.4g}" for k, v in (event.probes or {}).items())
            write(f"[{event.model}] step {event.step}: λ={event.load_factor:.5g} {probes}")
        else:
            write(f"[{event.model}] {event.phase} {event.message}".rstrip())

    return show
