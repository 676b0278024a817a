"""What produced a result folder, recorded in its ``summary.json`` and checked before any reuse.

A result is reused only when every part of its :class:`RunIdentity` matches what is asked now:
the model, the scene's content (a digest, not its name or file date), the model's own options
table of the scene (which holds its resolution: beam elements and core levels, 2D mesh level and
refinement), and the code that solved it (a digest of the model's package sources).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from sandwich.scene import Accuracy

IDENTITY_KEY = "identity"  # the summary.json key holding RunIdentity.to_dict()
# Scene fields that say nothing about the mechanics, or belong to one model only (compared
# through RunIdentity.options instead, so that a beam result survives a change of the 2D mesh).
_NOT_CONTENT = ("name", "description", "source", "beam_model", "reference2d")


def _canonical(value: object) -> object:
    """JSON-ready form with floats spelled exactly (``repr``) and tuples as lists."""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, list | tuple):
        return [_canonical(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def scene_digest(scene: object) -> str:
    """SHA-256 of the scene's mechanical content.

    Geometry, materials, debonds, supports, loads, probes, analysis, and ``[accuracy]`` where it
    is not the default (it decides the beam's levels; a scene without it keeps its digest); name,
    description, file and the models' option tables are left out.
    """
    data = {f.name: getattr(scene, f.name) for f in dataclasses.fields(scene)  # type: ignore[arg-type]
            if f.name not in _NOT_CONTENT}
    if data.get("accuracy") == Accuracy():
        data.pop("accuracy")
    data = {k: dataclasses.asdict(v) if dataclasses.is_dataclass(v) else
            [dataclasses.asdict(x) if dataclasses.is_dataclass(x) else x for x in v]
            if isinstance(v, tuple) else v for k, v in data.items()}
    text = json.dumps(_canonical(data), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


@lru_cache(maxsize=16)
def _digest_of(root: str, packages: tuple[str, ...]) -> str:
    h = hashlib.sha256()
    for pkg in packages:
        top = Path(root) / pkg
        for path in [top] if top.is_file() else sorted(top.rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(b"\0")
            h.update(path.read_bytes())
            h.update(b"\0")
    return h.hexdigest()


def source_digest(root: Path, packages: Iterable[str]) -> str:
    """SHA-256 of the ``*.py`` sources of ``packages`` (folders or files) under ``root``.

    Read once per process.
    """
    return _digest_of(str(Path(root).resolve()), tuple(packages))


@dataclass(frozen=True)
class RunIdentity:
    """What produced (or would produce) a result: compare two with :meth:`differences`.

    Attributes
    ----------
    model
        Registry name of the model (``"beam"``, ``"2d"``).
    scene
        The scene's name (for messages; not compared).
    scene_digest
        :func:`scene_digest` of the scene.
    options
        The model's options table of the scene (``[beam_model]`` or ``[reference2d]``), with any
        command-line override applied.
    resolution
        The part of ``options`` that sets the discretisation, for messages and for readers of
        ``summary.json`` (beam: elements, grading, core levels; 2D: mesh level, refinement).
    code
        :func:`source_digest` of the packages the model is built from.
    """

    model: str
    scene: str
    scene_digest: str
    options: dict[str, object] = field(default_factory=dict)
    resolution: dict[str, object] = field(default_factory=dict)
    code: str = ""

    def to_dict(self) -> dict[str, object]:
        """The JSON form written into ``summary.json``."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: object) -> RunIdentity | None:
        """The identity read back from ``summary.json``; ``None`` if absent or malformed."""
        if not isinstance(data, Mapping):
            return None
        try:
            return cls(model=str(data["model"]), scene=str(data.get("scene", "")),
                       scene_digest=str(data["scene_digest"]),
                       options=dict(data.get("options") or {}),
                       resolution=dict(data.get("resolution") or {}),
                       code=str(data.get("code", "")))
        except (KeyError, TypeError, ValueError):
            return None

    def differences(self, stored: RunIdentity | None) -> list[str]:
        """Why a result with identity ``stored`` cannot stand for this one (empty: it can)."""
        if stored is None:
            return ["it records no identity (an older version's or an interrupted run)"]
        out = []
        if stored.model != self.model:
            out.append(f"it is a {stored.model} result, not {self.model}")
        diff_res = _changed(stored.resolution, self.resolution)
        if diff_res:
            out.append("it was solved at " + ", ".join(f"{k}={a}" for k, a, _ in diff_res)
                       + ", the scene asks " + ", ".join(f"{k}={b}" for k, _, b in diff_res))
        other = [c for c in _changed(_canonical(stored.options), _canonical(self.options))
                 if c[0] not in self.resolution]
        if other:
            out.append("model options differ (" + ", ".join(f"{k}: {a} -> {b}"
                                                           for k, a, b in other) + ")")
        if stored.scene_digest != self.scene_digest:
            out.append("the scene's content differs (another scene of the same name, or edited)")
        if stored.code != self.code:
            out.append("the model's code changed since")
        return out


def _changed(old: object, new: object) -> list[tuple[str, object, object]]:
    old = old if isinstance(old, Mapping) else {}
    new = new if isinstance(new, Mapping) else {}
    return [(k, old.get(k), new.get(k)) for k in sorted(set(old) | set(new))
            if _canonical(old.get(k)) != _canonical(new.get(k))]
