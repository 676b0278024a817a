"""The model registry: one :class:`ModelSpec` per model, imported explicitly.

Each model is reached through a typed :class:`~sandwich.scene.Scene` only: its resolution and
numerics live in the scene's options table of that model (``[beam_model]``, ``[reference2d]``),
and a command-line override (``--level``, ``--refine``, ``--elements``) is applied to that table
(:func:`with_options`) before the model sees the scene, so that what is solved, what is recorded
in ``summary.json`` and what is checked before a reuse are one thing.

The model packages are imported when a model is solved, not when the registry is (the 2D model
loads FEniCSx); the imports are plain ``from ... import`` statements in :func:`_solve_beam` and
:func:`_solve_2d`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

from sandwich.results import ProgressItem, RunIdentity, Solution, scene_digest, source_digest
from sandwich.scene import Scene

StateCallback = Callable[[ProgressItem], None]  # each converged state, or a PathNote


def _solve_beam(scene: Scene, progress: StateCallback | None = None) -> Solution:
    """The beam element model (its field frames included)."""
    from sandwich.beam import solve

    return solve(scene, progress)


def _solve_2d(scene: Scene, progress: StateCallback | None = None) -> Solution:
    """The 2D plane-stress reference at the scene's ``[reference2d]`` level and refinement."""
    from sandwich.plane2d import solve

    return solve(scene, progress)


@dataclass(frozen=True)
class ModelSpec:
    """One model: how to solve a scene with it and what its result depends on.

    Attributes
    ----------
    name
        Registry name, also the result sub-folder (``results/<scene>/<name>/``).
    solve
        ``solve(scene, progress=None) -> Solution``; ``progress`` receives each converged state.
    options_table
        The scene attribute holding this model's options (``"beam_model"``, ``"reference2d"``).
    resolution_keys
        The options that set the discretisation (recorded and named in reuse messages).
    packages
        Packages and modules (paths under the project root) whose sources the result depends on
        (their digest is part of the identity).
    """

    name: str
    solve: Callable[..., Solution]
    options_table: str
    resolution_keys: tuple[str, ...]
    packages: tuple[str, ...]

    def options(self, scene: Scene) -> dict[str, object]:
        """The model's options table of ``scene`` as a plain dict."""
        return dataclasses.asdict(getattr(scene, self.options_table))

    def resolution(self, scene: Scene) -> dict[str, object]:
        """The resolution ``scene`` asks of this model (the keys it has of ``resolution_keys``)."""
        opts = self.options(scene)
        return {k: opts[k] for k in self.resolution_keys if k in opts}

    def identity(self, scene: Scene, root: object) -> RunIdentity:
        """The identity a result of ``scene`` solved by this model now would have."""
        from pathlib import Path

        return RunIdentity(model=self.name, scene=scene.name, scene_digest=scene_digest(scene),
                           options=self.options(scene), resolution=self.resolution(scene),
                           code=source_digest(Path(str(root)), self.packages))


# The contract every model is built on: paths under the project root, for the code digest.
CONTRACT = ("sandwich/__init__.py", "sandwich/scene.py", "sandwich/scene_checks",
            "sandwich/cohesive_law.py",
            "sandwich/scene_file.py", "sandwich/fracture.py", "sandwich/results", "sandwich/solver")

MODELS: dict[str, ModelSpec] = {
    "beam": ModelSpec("beam", _solve_beam, "beam_model",
                      ("elements", "grading", "core", "core_basis", "max_core_level",
                       "core_zones", "tolerance", "face_membrane", "faces", "contact_search"),
                      ("sandwich/beam", *CONTRACT)),
    "2d": ModelSpec("2d", _solve_2d, "reference2d",
                    ("level", "refine", "face_elements", "core_size", "face_size", "tip_size",
                     "half_model"),
                    ("sandwich/plane2d", "sandwich/meshes", *CONTRACT)),
}


def get_model(name: str) -> ModelSpec:
    """The registered model ``name``; ``KeyError`` naming the known ones otherwise."""
    try:
        return MODELS[name]
    except KeyError:
        raise KeyError(f"no model {name!r}; known: {', '.join(MODELS)}") from None


def with_options(scene: Scene, model: str, **overrides: object) -> Scene:
    """``scene`` with ``overrides`` (``None`` values ignored) set in ``model``'s options table."""
    given = {k: v for k, v in overrides.items() if v is not None}
    if not given:
        return scene
    spec = get_model(model)
    table = getattr(scene, spec.options_table)
    return dataclasses.replace(scene, **{spec.options_table: dataclasses.replace(table, **given)})
