"""What the commands share: exit codes, loading scenes, the resolution options, the memory guard.

Every command refuses a bad scene, bad option or unusable output folder before any work (exit
code 2, one line per problem naming the file or option, the key and the reason), and so does
every command that solves or meshes for a run estimated not to fit in the memory available
(:func:`guard_memory`, :mod:`sandwich.cli.memory_guard`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from sandwich.cli.memory_guard import check_memory
from sandwich.models import mpi_rank, with_options
from sandwich.results import Solution
from sandwich.scene import Scene, SceneError
from sandwich.scene_file import load_scene

__all__ = ["CLI_KEYS", "ELEMENTS_RANGE", "EXIT_BAD_INPUT", "EXIT_INTERNAL", "EXIT_OK",
           "EXIT_STOPPED", "REFINE_RANGE", "RESULTS", "UsageError", "default_out", "guard_memory",
           "load_scenes", "overridden", "say"]

EXIT_OK, EXIT_STOPPED, EXIT_BAD_INPUT, EXIT_INTERNAL = 0, 1, 2, 3
RESULTS = Path("results")
REFINE_RANGE = (0, 6)  # as the scene's [reference2d] refine
ELEMENTS_RANGE = (2, 200_000)  # as the scene's [beam_model] elements
CLI_KEYS = {"elements": "beam_model.elements", "refine": "reference2d.refine",
            "level": "reference2d.level"}  # option -> the scene key it overrides


class UsageError(ValueError):
    """A command-line option that cannot be used: which option and why."""


def say(args: argparse.Namespace, msg: str) -> None:
    """Print ``msg`` unless the command is ``--quiet`` (or not MPI rank 0)."""
    if not getattr(args, "quiet", False) and mpi_rank() == 0:
        print(msg, flush=True)


def load_scenes(paths: list[str]) -> list[Scene]:
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


def overridden(scene: Scene, model: str, args: argparse.Namespace) -> Scene:
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


def accuracy_line(model: str, sol: Solution) -> str:
    """What a run says of its own accuracy: its estimates per quantity, or why there are none."""
    mesh = sol.extra.get("mesh_error")
    if isinstance(mesh, dict):
        if mesh.get("not_measured"):
            return f"{model}: the mesh's error is not estimated: {mesh['not_measured']}"
        return (f"{model}: estimated error at the target (change from level "
                f"{mesh.get('against')}): " + _per_quantity(mesh.get("quantities") or {}))
    core = sol.extra.get("core")
    if not isinstance(core, dict) or core.get("how") != "auto":
        return (f"{model}: no error estimate at a fixed resolution (compare with another "
                "resolution, or with the other model: sandwich compare)")
    est, tol = core.get("estimated_error"), core.get("tolerance")
    if est is None:
        return f"{model}: the core levels' error could not be estimated (see the warnings)"
    quantities = core.get("quantities") or {}
    what = "estimated error at the target (core levels and element length)"
    if not quantities:
        quantities = {"load and probes": {"estimated_error": est, "tolerance": tol}}
        what = "estimated error of the core levels"
    return f"{model}: {what}: " + _per_quantity(quantities)


def _per_quantity(quantities: dict) -> str:
    """"name e % (within/above t %)" for every quantity with an estimate, comma-separated."""
    parts = []
    for name, q in quantities.items():
        e, t = q.get("estimated_error"), q.get("tolerance")
        if e is None:
            if q.get("core_levels") is not None:
                parts.append(f"{name} ≥ {100 * q['core_levels']:.2g} % (core levels; element "
                             "length not measured)")
            continue
        said = f"{name} {100 * e:.2g} %"
        if t is not None:
            said += f" ({'within' if e <= t else 'above'} {100 * t:.2g} %)"
        parts.append(said)
    return ", ".join(parts)


def overridden_both(scene: Scene, args: argparse.Namespace) -> Scene:
    """``scene`` with ``--level``/``--refine`` on the 2D model and ``--elements`` on the beam."""
    only_2d = argparse.Namespace(level=getattr(args, "level", None),
                                 refine=getattr(args, "refine", None))
    only_beam = argparse.Namespace(elements=getattr(args, "elements", None))
    return overridden(overridden(scene, "2d", only_2d), "beam", only_beam)


def guard_memory(scenes: list[Scene], models: tuple[str, ...], args: argparse.Namespace, *,
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
