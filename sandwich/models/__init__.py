"""The models the tool can run, and the one runner that solves a scene and writes its result.

Layer order: scene (``sandwich``) → models (``sandwich.beam``, ``sandwich.plane2d``) → **this
registry
and runner** → ``sandwich.compare`` → the command line (``sandwich.cli``). Every path that solves a
scene and writes a result folder goes through :func:`obtain` / :func:`run_model`: the ``solve``,
``compare``, ``gallery`` and ``demo`` commands and the benchmarks.
"""

from sandwich.models.registry import MODELS, ModelSpec, get_model, with_options
from sandwich.models.runner import (
    PROJECT_ROOT,
    ModelRun,
    Progress,
    ProgressEvent,
    Solver,
    mpi_rank,
    obtain,
    run_model,
    stored_identity,
    text_progress,
)

__all__ = ["MODELS", "PROJECT_ROOT", "ModelRun", "ModelSpec", "Progress", "ProgressEvent",
           "Solver", "get_model", "mpi_rank", "obtain", "run_model", "stored_identity",
           "text_progress", "with_options"]
