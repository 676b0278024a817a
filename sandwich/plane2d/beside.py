"""The mesh estimate's coarser path, followed in a second process beside the run's own path.

The 2D model's mesh estimate (:mod:`sandwich.plane2d.mesh_error`) follows the scene's path once
more one level coarser. Where a core is free, that path runs in a spawned interpreter
(:class:`Beside`: it builds its own mesh and forms) while this process follows its own, so the
estimate adds little wall time to the run; the two models are then held at once
(:func:`sandwich.models.memory.reference2d_estimate` counts both). Not under ``mpirun`` (more than
one rank), not in a daemonic process (a study's Dask worker, which may not start one) and not on
one core (:func:`can_run_beside`): there the coarser path is followed after the run's own.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable
from typing import Any

from sandwich.meshes.levels import Coarser
from sandwich.results import Solution
from sandwich.scene import Scene

#: seconds the process beside is given to end after its answer is taken or it is stopped
JOIN_SECONDS = 30.0


def can_run_beside() -> bool:
    """Whether a second process may follow the coarser path now: one rank, not a daemon, ≥ 2 cores.

    ``SANDWICH_ESTIMATE_BESIDE=0`` in the environment turns it off.
    """
    if os.environ.get("SANDWICH_ESTIMATE_BESIDE", "1") == "0":
        return False
    if multiprocessing.current_process().daemon or (os.cpu_count() or 1) < 2:
        return False
    from mpi4py import MPI

    return MPI.COMM_WORLD.size == 1


class Beside:
    """The coarser path at ``against`` followed in a spawned process by ``solve``, started at once.

    ``solve`` is the 2D model's :func:`sandwich.plane2d.solve.solve` (passed in, so that this
    module does not import the one that uses it), called with ``estimate=False``.

    :meth:`result` waits for its :class:`Solution` (or the reason it has none); :meth:`stop`
    ends it unheard (the run's own path did not reach its target, or was interrupted).
    """

    def __init__(self, solve: Callable[..., Solution], scene: Scene, against: Coarser,
                 options: dict[str, Any]) -> None:
        self.against = against
        context = multiprocessing.get_context("spawn")
        self._conn, child = context.Pipe(duplex=False)
        self._process = context.Process(
            target=_follow, args=(child, solve, scene, against.level, against.refine, options),
            name=f"sandwich 2D mesh estimate ({against})", daemon=True)
        self._process.start()
        child.close()

    def result(self) -> Solution | str:
        """The coarser path's solution, or why there is none (its process failed or died)."""
        try:
            kind, value = self._conn.recv()
        except EOFError:
            kind, value = "error", "the process ended without an answer"
        finally:
            self._conn.close()
            self._process.join(JOIN_SECONDS)
        if kind == "ok":
            return value
        return f"the coarser path's process failed ({value})"

    def stop(self) -> None:
        """End the process beside without its answer."""
        if self._process.is_alive():
            self._process.terminate()
        self._process.join(JOIN_SECONDS)
        self._conn.close()


def _follow(conn: Any, solve: Callable[..., Solution], scene: Scene, level: str, refine: int,
            options: dict[str, Any]) -> None:
    """In the process beside: the path at ``level`` + ``refine``, sent back through ``conn``."""
    try:
        solution = solve(scene, level=level, refine=refine, estimate=False, **options)
        conn.send(("ok", solution))
    except BaseException as exc:  # noqa: BLE001 - every failure is the estimate's, said there
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()
