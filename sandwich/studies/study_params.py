"""What a study axis sets in a scene: a value at a scene path, or a derived parameter.

Both act on the scene's parsed TOML (a nested dict), never on the typed scene: every case is then
built and validated by :func:`sandwich.scene_checks.build_scene` like any scene file, so a case
that makes no sense is refused with the scene's own key and reason.

A **path** names a value as the scene file spells it, dots between keys and array indices:
``debonds.0.start``, ``layers.core.thickness``, ``loads.0.x``, ``analysis.until.value``,
``beam_model.elements``. ``materials.<layer>`` (``top``, ``core``, ``bottom``) is the material
that layer uses, e.g. ``materials.core.Ex`` (a material shared by two layers changes in both).

The **derived parameters** (:data:`DERIVED`), each a function ``(data, value, axis) -> None``:

- ``debond_length``: debond ``debond`` (index, default 0) gets this length (mm), centre kept;
- ``debond_centre``: debond ``debond`` moved so that its centre is at this x (mm), length kept;
- ``periodic_debonds``: every debond replaced by debonds of length d alternating with bonded
  stretches of length d, a bonded stretch centred at ``centre`` (default mid-span), on
  ``interfaces`` (default both), clipped to the beam (the paper's Fig. 9 pattern; d = 0: none);
- ``core_stiffness_ratio``: E_core / E_face: the core's Ex = Ez = ratio × the top face's E (or
  Ex), Gzx scaled with them;
- ``thickness_ratio``: t_core / t_face: both faces get the core thickness / ratio;
- ``slenderness``: L / h: every station along x (length, debonds, supports, loads and their
  widths, probes, core zones) and the until deflection scaled so that L = value × h.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import fields
from typing import Any

from sandwich.scene import Analysis, BeamModelOptions, Reference2DOptions

LAYERS = ("top", "core", "bottom")
# keys a scene table may hold though the base scene leaves them out (their defaults apply)
OPTIONAL_KEYS = {
    "beam_model": tuple(f.name for f in fields(BeamModelOptions)),
    "reference2d": tuple(f.name for f in fields(Reference2DOptions)),
    "analysis": tuple(f.name for f in fields(Analysis)
                      if not f.name.startswith("until")) + ("until",),
}


class PathError(ValueError):
    """A path that names nothing in the base scene (the message says what is there)."""


def _key(part: str) -> str | int:
    return int(part) if part.isdigit() else part


def resolve(data: dict[str, Any], path: str) -> tuple[Any, str | int]:
    """The container and the key that ``path`` names in ``data``.

    Tables the base scene leaves out (``[beam_model]``, ``[reference2d]``) are created empty;
    a last key the base scene leaves out is allowed only where the scene format has it with a
    default (:data:`OPTIONAL_KEYS`).

    Raises
    ------
    PathError
        The path names no value of the base scene.
    """
    parts = [p for p in path.split(".")]
    if not parts or any(not p for p in parts):
        raise PathError(f"'{path}' is not a dotted path (e.g. debonds.0.start)")
    node: Any = data
    where = ""
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if where == "materials" and part in LAYERS and part not in node:
            material = data.get("layers", {}).get(part, {}).get("material")
            if isinstance(material, str) and material in node:
                part = material  # materials.core -> the material the core uses
        if isinstance(node, list):
            if not part.isdigit():
                raise PathError(f"{where} is an array: expected an index 0..{len(node) - 1}, "
                                f"got '{part}'")
            if int(part) >= len(node):
                raise PathError(f"{where} has {len(node)} entr{'y' if len(node) == 1 else 'ies'}"
                                f": no index {part}")
            if last:
                return node, int(part)
            node, where = node[int(part)], f"{where}.{part}"
            continue
        if not isinstance(node, dict):
            raise PathError(f"{where} is a value, not a table: nothing inside it to set")
        if part not in node:
            table = where.split(".")[0] if where else part
            allowed = OPTIONAL_KEYS.get(table, ())
            if where == "" and part in OPTIONAL_KEYS:
                node[part] = {}
            elif last and where in OPTIONAL_KEYS and part in allowed:
                return node, part
            else:
                known = sorted(set(node) | (set(allowed) if where in OPTIONAL_KEYS else set()))
                near = difflib.get_close_matches(part, known, n=1, cutoff=0.6)
                hint = f" (did you mean '{near[0]}'?)" if near else (
                    f" (it has: {', '.join(map(str, known))})" if known else "")
                raise PathError(f"{where or 'the scene'} has no key '{part}'{hint}")
        if last:
            if isinstance(node[part], dict | list):
                raise PathError(f"{_join(where, part)} is a table or an array, not a value")
            return node, part
        node, where = node[part], _join(where, part)
    raise PathError(f"'{path}' names nothing")  # pragma: no cover - the loop returns


def _join(a: str, b: str) -> str:
    return f"{a}.{b}" if a else b


def base_value(data: dict[str, Any], path: str) -> Any:
    """The base scene's value at ``path`` (``None`` where it is left to its default)."""
    node, key = resolve(data, path)
    if isinstance(node, list):
        return node[key]  # type: ignore[index]
    return node.get(key)


def set_path(data: dict[str, Any], path: str, value: Any) -> None:
    """Set ``value`` at ``path`` in ``data`` (in place)."""
    node, key = resolve(data, path)
    node[key] = value


# -- derived parameters ---------------------------------------------------------------------------

def _debond(data: dict[str, Any], axis: dict[str, Any]) -> dict[str, Any]:
    i = int(axis.get("debond", 0))
    debonds = data.get("debonds", [])
    if not isinstance(debonds, list) or not 0 <= i < len(debonds):
        raise PathError(f"debond {i}: the base scene has {len(debonds)} debond(s)")
    return debonds[i]


def _debond_length(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    d = _debond(data, axis)
    centre = 0.5 * (float(d["start"]) + float(d["end"]))
    d["start"], d["end"] = centre - 0.5 * value, centre + 0.5 * value


def _debond_centre(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    d = _debond(data, axis)
    half = 0.5 * (float(d["end"]) - float(d["start"]))
    d["start"], d["end"] = value - half, value + half


def _periodic_debonds(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    L = float(data["beam"]["length"])
    centre = float(axis.get("centre", 0.5 * L))
    interfaces = axis.get("interfaces", ["top", "bottom"])
    d = float(value)
    out = []
    if d > 0:
        # debond k spans [centre + d/2 + 2 d k, centre + 3 d/2 + 2 d k], k over the integers
        k_lo = int((0.0 - centre - 1.5 * d) // (2 * d))
        k_hi = int((L - centre - 0.5 * d) // (2 * d)) + 1
        for k in range(k_lo, k_hi + 1):
            a = max(centre + 0.5 * d + 2 * d * k, 0.0)
            b = min(centre + 1.5 * d + 2 * d * k, L)
            if b - a > 1e-9 * L:
                out.extend({"interface": itf, "start": a, "end": b} for itf in interfaces)
    data["debonds"] = out


def _material_of(data: dict[str, Any], layer: str) -> dict[str, Any]:
    name = data["layers"][layer]["material"]
    return data["materials"][name]


def _core_stiffness_ratio(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    face = _material_of(data, "top")
    if data["layers"]["core"]["material"] == data["layers"]["top"]["material"]:
        raise PathError("the core and the top face share one material: give the core its own")
    E = value * float(face.get("Ex", face.get("E")))
    core = _material_of(data, "core")
    if "E" in core:
        core["E"] = E
    else:
        scale = E / float(core["Ex"])
        core["Ex"], core["Ez"], core["Gzx"] = E, E, float(core["Gzx"]) * scale


def _thickness_ratio(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    t = float(data["layers"]["core"]["thickness"]) / value
    for face in ("top", "bottom"):
        data["layers"][face]["thickness"] = t


def _slenderness(data: dict[str, Any], value: float, axis: dict[str, Any]) -> None:
    h = sum(float(data["layers"][k]["thickness"]) for k in LAYERS)
    s = value * h / float(data["beam"]["length"])
    data["beam"]["length"] = float(data["beam"]["length"]) * s
    for table, keys in (("debonds", ("start", "end")), ("supports", ("x",)),
                        ("loads", ("x", "width")), ("probes", ("x",))):
        for item in data.get(table, []):
            for k in keys:
                if k in item:
                    item[k] = float(item[k]) * s
    for z in data.get("beam_model", {}).get("core_zones", []):
        z["start"], z["end"] = float(z["start"]) * s, float(z["end"]) * s
    until = data.get("analysis", {}).get("until", {})
    if "value" in until:
        until["value"] = float(until["value"]) * s


DERIVED: dict[str, Callable[[dict[str, Any], float, dict[str, Any]], None]] = {
    "debond_length": _debond_length,
    "debond_centre": _debond_centre,
    "periodic_debonds": _periodic_debonds,
    "core_stiffness_ratio": _core_stiffness_ratio,
    "thickness_ratio": _thickness_ratio,
    "slenderness": _slenderness,
}
# the unit of each derived parameter's values ("" for a ratio)
DERIVED_UNITS = {"debond_length": "mm", "debond_centre": "mm", "periodic_debonds": "mm",
                 "core_stiffness_ratio": "", "thickness_ratio": "", "slenderness": ""}
# the unit of a scene path's value, by its last key (the scene format's units: mm, MPa, N)
PATH_UNITS = {"start": "mm", "end": "mm", "x": "mm", "length": "mm", "thickness": "mm",
              "width": "mm", "value": "mm", "E": "MPa", "Ex": "MPa", "Ez": "MPa", "G": "MPa",
              "Gzx": "MPa", "force": "N"}
# the extra keys each derived parameter reads from its axis table
DERIVED_KEYS = {"debond_length": ("debond",), "debond_centre": ("debond",),
                "periodic_debonds": ("centre", "interfaces")}


def axis_label(name: str, path: str | None, derived: str | None, scale: bool) -> str:
    """An axis title with its unit: ``"length (mm)"``, ``"Ex (× base)"``, ``"ratio"``."""
    if scale:
        return f"{name} (× base value)"
    unit = DERIVED_UNITS.get(derived or "", "") if derived else PATH_UNITS.get(
        (path or "").rsplit(".", 1)[-1], "")
    return f"{name} ({unit})" if unit else name
