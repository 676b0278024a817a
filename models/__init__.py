"""The models the tool can run, and the one runner that solves a scene and writes its result.

Layer order: scene (``sandwich``) → models (``beam_element``, ``reference2d``) → **this registry
and runner** → ``comparisons`` → the command line (``sandwich_cli``). Every path that solves a
scene and writes a result folder goes through :func:`obtain` / :func:`run_model`: the ``solve``,
``compare``, ``gallery`` and ``demo`` commands and the benchmarks.
"""

from models.registry import MODELS, ModelSpec, get_model, with_options
from models.runner import (
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
