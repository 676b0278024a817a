"""Parsed TOML → a :class:`~sandwich.scene.Scene` (:func:`build_scene`), every problem collected."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sandwich.scene import (
    Scene,
    SceneError,
)
from sandwich.scene_checks.geometry import read_beam, read_layers, read_materials
from sandwich.scene_checks.options import (
    read_accuracy,
    read_analysis,
    read_beam_model,
    read_reference2d,
)
from sandwich.scene_checks.reader import Reader, check_name, typename
from sandwich.scene_checks.stations import (
    check_mechanism,
    read_debonds,
    read_loads,
    read_probes,
    read_supports,
)

__all__ = ["TOP_KEYS", "build_scene"]

TOP_KEYS = ("name", "description", "beam", "layers", "materials", "debonds", "supports", "loads",
            "analysis", "probes", "beam_model", "reference2d", "accuracy")


def build_scene(data: dict[str, Any], fname: str, source: Path | None = None) -> Scene:
    """Validate parsed TOML ``data`` and build the :class:`Scene`; raise :class:`SceneError`."""
    r = Reader(fname)
    r.table(data, "", TOP_KEYS, required=("name", "beam", "layers", "materials", "supports",
                                          "loads", "analysis"))
    name = r.string(data, "name", "", default="")
    check_name(r, name, "name")
    description = data.get("description", "")
    if not isinstance(description, str):
        r.fail("description", f"expected a string, got {typename(description)}")
        description = ""
    length, width = read_beam(r, data.get("beam", {}))
    materials = read_materials(r, data.get("materials", {}))
    layers = read_layers(r, data.get("layers", {}), materials)
    L = length if length else None
    debonds = read_debonds(r, data.get("debonds", []), L)
    supports = read_supports(r, data.get("supports", []), L)
    loads = read_loads(r, data.get("loads", []), L)
    probes = read_probes(r, data.get("probes", []), L)
    analysis = read_analysis(r, data.get("analysis", {}), probes)
    beam_model = read_beam_model(r, data.get("beam_model", {}))
    for i, z in enumerate(beam_model.core_zones):
        if L is not None and (z.start < 0 or z.end > L):
            r.fail(f"beam_model.core_zones.{i}", f"[{z.start:g}, {z.end:g}] is not inside the "
                   f"beam [0, {L:g}]")
    reference2d = read_reference2d(r, data.get("reference2d", {}))
    beam_tolerance_given = isinstance(data.get("beam_model"), dict) and (
        "tolerance" in data["beam_model"])
    accuracy, beam_model = read_accuracy(r, data.get("accuracy", {}), beam_model,
                                         beam_tolerance_given)
    if analysis is not None and getattr(analysis, "kind", None) == "linear":
        for i, d in enumerate(debonds):
            if d.growth is not None and d.growth.cohesive:
                r.fail(f"debonds[{i}].growth.method", "a cohesive law is nonlinear (its damage "
                       "grows along the path): it needs analysis kind = \"nonlinear\"")
    methods = {d.growth.method for d in debonds if d.growth is not None}
    if len(methods) > 1:
        r.fail("debonds", "growing debonds use one method per scene (crack-length control "
               "solves a path per length, a cohesive law grows along one path): got "
               + " and ".join(sorted(methods)))
    if not r.problems:
        check_mechanism(r, supports, debonds, length)
    if r.problems:
        raise SceneError(r.problems)
    return Scene(name=name, description=description, length=length, width=width,
                 top=layers["top"], core=layers["core"], bottom=layers["bottom"],
                 debonds=tuple(debonds), supports=tuple(supports), loads=tuple(loads),
                 probes=tuple(probes), analysis=analysis, beam_model=beam_model,
                 reference2d=reference2d, accuracy=accuracy, source=source)
