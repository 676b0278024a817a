"""One case of a study, solved where a worker runs it, and its record on disk.

:func:`solve_case` is what the execution engine sends to a worker (a local process or a node of a
Dask cluster): it solves the case's scene with the one runner (:func:`sandwich.models.obtain`, which
writes the result set and its :class:`~sandwich.results.RunIdentity`), reads the study's numbers
off the solution (:mod:`sandwich.studies.study_metrics`) and writes ``case.json`` beside the result
set
last, so a case folder with a ``case.json`` whose identity matches is a finished case. It never
raises for a case's failure: a failing case is a record with its reason.
"""

from __future__ import annotations

import json
import math
import os
import signal
import threading
import time
import traceback
from pathlib import Path
from typing import Any

from sandwich.models import PROJECT_ROOT, get_model, obtain, stored_identity
from sandwich.quiet_logs import hush_libraries
from sandwich.results import load_result
from sandwich.scene import MAX_CORE_LEVEL, Scene
from sandwich.studies.study_metrics import case_metrics

CASE_FILE = "case.json"
LOOKAHEAD = 2  # the indicator compares the case's core level with this many levels more


class CaseTimeout(KeyboardInterrupt):
    """The study's wall-time cap of a case, raised at a converged step past it.

    A ``KeyboardInterrupt``: the runner then writes every converged step so far (history only,
    never reused) as it does for Ctrl-C; the cap is checked at each converged step, so a single
    step that hangs is not stopped by it.
    """


def _write_json(path: Path, data: dict[str, Any]) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=1, default=str) + "\n", encoding="utf-8")
    os.replace(tmp, path)


def read_record(folder: Path) -> dict[str, Any] | None:
    """The ``case.json`` of a case folder (None if absent or unreadable)."""
    try:
        data = json.loads((Path(folder) / CASE_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def reusable(scene: Scene, model: str, folder: Path, root: Path = PROJECT_ROOT,
             need_indicator: bool = False) -> tuple[dict[str, Any] | None, str]:
    """``(record, "")`` when ``folder`` holds this very case finished, else ``(None, why)``.

    Finished: a ``case.json`` that is not a failure, beside a result set whose identity is the
    one the runner would record now (scene content, options, resolution, code).
    """
    rec = read_record(folder)
    if rec is None:
        return None, ""
    if rec.get("status") == "failed":
        return None, "it failed before (tried again)"
    why = get_model(model).identity(scene, root).differences(stored_identity(folder))
    if why:
        return None, "; ".join(why)
    if (need_indicator and rec.get("indicator") is None and rec.get("status") == "done"
            and not rec.get("indicator_note")):
        return None, "it has no error indicator (asked by check)"
    return rec, ""


def linear_indicator(scene: Scene) -> float | None:
    """The beam's core-level error indicator of ``scene`` (relative, None if not known).

    The relative change of the linear stiffness when every core level is raised by
    :data:`LOOKAHEAD` (the saturation estimate the ``"auto"`` core uses,
    :mod:`sandwich.beam.core_levels`), on the small-displacement step: of the until probe's
    response, else of the compliance (:func:`sandwich.beam.core_choice.linear_responses`; the two
    solves, the second started from the first one's contact set, are all it computes).
    """
    from sandwich.beam.core_choice import linear_responses  # (the beam's kernels: when needed)

    level = scene.beam_model.core
    raised = min(level + LOOKAHEAD, MAX_CORE_LEVEL) if isinstance(level, int) else None
    if raised is None or raised == level:  # "auto", or no level above to compare with
        return None
    lo, hi = linear_responses(scene, (level, raised))
    if lo == 0.0:
        return None
    err = abs(hi - lo) / abs(lo)
    return err if math.isfinite(err) else None


_REAL_SIGNAL = signal.signal


def _signal_on_main_thread_only(signum, handler):  # type: ignore[no-untyped-def]
    """``signal.signal`` that leaves the handlers as they are when called off the main thread."""
    if threading.current_thread() is threading.main_thread():
        return _REAL_SIGNAL(signum, handler)
    return signal.getsignal(signum)


def _over_budget(scene: Scene, model: str, max_cells: object) -> str:
    """Why a 2D case is not run (its mesh exceeds the study's ``max_cells``), or ``""``."""
    if model != "2d" or not isinstance(max_cells, int):
        return ""
    from sandwich.meshes import build_mesh

    cells = len(build_mesh(scene).cells)
    if cells > max_cells:
        return (f"2D mesh at level {scene.reference2d.level} has {cells} cells, above the "
                f"study's max_cells = {max_cells}")
    return ""


def prepare_2d() -> bool:
    """Let the 2D model run on a worker thread of this process (a Dask worker's tasks do).

    gmsh sets and restores a SIGINT handler at import, ``initialize`` and ``finalize``, which
    Python allows only on the main thread: off it, the worker's ``signal.signal`` leaves the
    handlers unchanged instead of raising (a worker's tasks are never interrupted by Ctrl-C).
    """
    signal.signal = _signal_on_main_thread_only
    hush_libraries()  # the FEniCSx stack's notes, held back as the command line does
    return True


def solve_case(task: dict[str, Any]) -> dict[str, Any]:
    """Solve one case and write its record; returns the record (see the module docstring).

    ``task`` holds ``index``, ``key``, ``values`` (axis values), ``scene``, ``model``,
    ``folder``, ``indicator`` (compute the error indicator), ``fields`` (keep the field frames,
    else the result set is history, profiles and summary) and optionally ``root``,
    ``timeout`` and ``max_cells``.
    """
    scene: Scene = task["scene"]
    model: str = task["model"]
    folder = Path(task["folder"])
    root = Path(task.get("root") or PROJECT_ROOT)
    rec: dict[str, Any] = {"index": task["index"], "key": task["key"], "values": task["values"],
                           "model": model, "host": os.uname().nodename, "pid": os.getpid()}
    t0 = time.perf_counter()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / CASE_FILE).unlink(missing_ok=True)
        if model == "2d" and threading.current_thread() is not threading.main_thread():
            prepare_2d()
        skip = _over_budget(scene, model, task.get("max_cells"))
        if skip:
            rec.update(status="skipped", reason=skip)
            rec["wall_seconds"] = round(time.perf_counter() - t0, 3)
            _write_json(folder / CASE_FILE, rec)
            return rec
        cap = task.get("timeout")
        steps = [0]

        def watch(event: Any) -> None:
            if event.phase != "step":
                return
            steps[0] += 1
            if cap and time.perf_counter() - t0 > cap:
                raise CaseTimeout(f"stopped by the study's wall-time cap of {cap:g} s after "
                                  f"{steps[0]} converged steps")

        spec = get_model(model)

        def solver(sc: Scene, progress: Any = None) -> Any:
            sol = spec.solve(sc, progress)
            if not task.get("fields"):  # a study keeps no field frames unless asked
                sol.fields = []
            return sol

        try:
            run = obtain(scene, model, folder, reuse=False, root=root, progress=watch,
                         solver=solver)
        except CaseTimeout as exc:
            rec.update(status="timeout", reason=str(exc))
            try:
                rec.update({k: v for k, v in case_metrics(scene, load_result(folder)).items()
                            if k not in ("converged", "stop_reason")})
            except (OSError, ValueError, KeyError):
                pass
            run = None
        if run is None:
            pass
        elif run.solution is None:
            rec.update(status="failed", reason=run.reason)
        else:
            rec.update(case_metrics(scene, run.solution))
            rec["status"] = "done" if run.solution.converged else "stopped"
            rec["reason"] = "" if run.solution.converged else rec["stop_reason"]
            core = run.solution.extra.get("core")
            est = core.get("estimated_error") if isinstance(core, dict) else None
            rec["indicator"] = est
            if est is None and task.get("indicator") and model == "beam":
                try:
                    rec["indicator"] = linear_indicator(scene)
                except Exception as exc:  # noqa: BLE001 - the case is solved; no indicator
                    rec["indicator_note"] = f"no indicator: {type(exc).__name__}: {exc}"
    except Exception as exc:  # noqa: BLE001 - a failing case is a record, never a stopped study
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" ({Path(tb[-1].filename).name}:{tb[-1].lineno})" if tb else ""
        rec.update(status="failed", reason=f"{type(exc).__name__}: {exc}{where}")
    rec["wall_seconds"] = round(time.perf_counter() - t0, 3)
    try:
        _write_json(folder / CASE_FILE, rec)
    except OSError as exc:
        rec.update(status="failed", reason=f"its record could not be written ({exc})")
    return rec
