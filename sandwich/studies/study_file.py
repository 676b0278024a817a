"""Study files (TOML): a base scene, axes over its values, what to report; every case checked.

A study is refused before anything runs, one line per problem naming the study file, the key and
the reason (:class:`StudyError`, a :class:`~sandwich.scene.SceneError`): a path that names
nothing in the base scene, an empty axis, two axes setting the same thing, and every case whose
scene the scene checks refuse (the case, its axis values and the scene's own key and reason).
The format is described in ``docs/studies.md``; what an axis sets is
:mod:`sandwich.studies.study_params`.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sandwich.models import get_model
from sandwich.scene import NAME_PATTERN, Problem, Scene, SceneError, is_finite_number
from sandwich.scene_checks import build_scene
from sandwich.scene_file import read_toml_file
from sandwich.studies.study_params import (
    DERIVED,
    DERIVED_KEYS,
    PathError,
    base_value,
    resolve,
    set_path,
)

MODELS = ("beam", "2d")
TOP_KEYS = ("name", "description", "scene", "model", "check", "timeout", "max_cells", "fields",
            "axis", "analysis", "beam_model", "reference2d", "report")
AXIS_KEYS = ("name", "path", "derived", "values", "range", "logrange", "scale", "debond",
             "centre", "interfaces")
REPORT_KEYS = ("quantity", "reference", "threshold")
QUANTITIES = ("capacity", "first_limit_load", "load_at_until", "initial_stiffness",
              "peak_sigma_zz", "peak_sigma_zz_5mm", "peak_tau_core", "peak_tau_core_5mm",
              "contact_length", "first_growth_load", "residual_strength")
MAX_CASES = 20_000
MAX_AXIS_VALUES = 10_000
MAX_SHOWN = 12  # refused cases listed one per line, the rest counted


class StudyError(SceneError):
    """A study that cannot run; ``problems`` lists every reason (file, key, reason)."""


@dataclass(frozen=True)
class Axis:
    """One axis of the grid: what it sets and its values."""

    name: str
    values: tuple[Any, ...]
    path: str | None = None  # a scene path, or
    derived: str | None = None  # a derived parameter of sandwich.studies.study_params.DERIVED
    scale: bool = False  # path axes: the values multiply the base scene's value
    options: dict[str, Any] = field(default_factory=dict)  # debond, centre, interfaces


@dataclass(frozen=True)
class Report:
    """What the table and plots report: a quantity, its knock-down reference and threshold."""

    quantity: str = "capacity"
    reference: dict[str, Any] = field(default_factory=dict)  # axis name -> value
    threshold: float | None = None  # knock-down ratio whose crossing along axis 0 is reported


@dataclass(frozen=True)
class Case:
    """One case of the grid: its index, axis values, validated scene and storage key."""

    index: int
    values: dict[str, Any]
    scene: Scene
    key: str


@dataclass(frozen=True)
class Study:
    """A validated study: its cases are built and checked."""

    name: str
    description: str
    source: Path
    scene_path: Path
    model: str
    check: int
    axes: tuple[Axis, ...]
    report: Report
    cases: tuple[Case, ...]
    check_options: dict[str, Any] = field(default_factory=dict)  # [reference2d] of the checks
    check_all: bool = False  # check = "all": every case, whatever the beam did
    timeout: float | None = None  # wall-time cap of a case (s), checked at each converged step
    max_cells: int | None = None  # 2D checks: a mesh above this many cells is not run
    fields: bool = False  # keep each case's field frames (fields.pvd; ~2 MB a beam case)


def case_key(scene: Scene, model: str, options: dict[str, Any]) -> str:
    """The folder name of a case: a hash of its scene content, the model and its options.

    The same digest of the scene's mechanical content as the runner's result identity
    (:func:`sandwich.results.scene_digest`); the code digest is not part of the key (a case
    solved by older code is found and solved again, the reason said).
    """
    from sandwich.results import scene_digest

    text = json.dumps({"scene": scene_digest(scene), "model": model, "options": options},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def _read_toml(path: Path, what: str) -> dict[str, Any]:
    return read_toml_file(path, what, StudyError)


class _Problems:
    def __init__(self, fname: str):
        self.fname = fname
        self.items: list[Problem] = []

    def fail(self, key: str, reason: str) -> None:
        self.items.append(Problem(self.fname, key, reason))


def _unknown(p: _Problems, table: dict[str, Any], allowed: tuple[str, ...], key: str) -> None:
    for k in table:
        if k not in allowed:
            near = difflib.get_close_matches(k, allowed, n=1, cutoff=0.6)
            hint = f" (did you mean '{near[0]}'?)" if near else f" (allowed: {', '.join(allowed)})"
            p.fail(f"{key}.{k}" if key else k, f"unknown key{hint}")


def _number(v: Any) -> bool:
    return is_finite_number(v)


def _values(p: _Problems, t: dict[str, Any], key: str) -> tuple[Any, ...] | None:
    """The values of an axis table: ``values``, ``range`` or ``logrange`` (exactly one)."""
    given = [k for k in ("values", "range", "logrange") if k in t]
    if len(given) != 1:
        p.fail(key, "give exactly one of values = [...], range = {start, stop, step | num}, "
               "logrange = {start, stop, num}" + (f" (got {', '.join(given)})" if given else ""))
        return None
    kind = given[0]
    spec = t[kind]
    if kind == "values":
        if not isinstance(spec, list):
            p.fail(f"{key}.values", "expected an array of values")
            return None
        if not spec:
            p.fail(f"{key}.values", "empty axis: no value")
            return None
        bad = [v for v in spec if not (_number(v) or isinstance(v, str))]
        if bad:
            p.fail(f"{key}.values", f"expected finite numbers or strings, got {bad[0]!r}")
            return None
        if len(set(map(repr, spec))) != len(spec):
            p.fail(f"{key}.values", "a value is given twice (two cases would be one)")
            return None
        return tuple(spec)
    if not isinstance(spec, dict):
        p.fail(f"{key}.{kind}", "expected a table {start, stop, ...}")
        return None
    allowed = ("start", "stop", "step", "num") if kind == "range" else ("start", "stop", "num")
    _unknown(p, spec, allowed, f"{key}.{kind}")
    start, stop = spec.get("start"), spec.get("stop")
    if not (_number(start) and _number(stop)):
        p.fail(f"{key}.{kind}", "start and stop must be finite numbers")
        return None
    step, num = spec.get("step"), spec.get("num")
    if kind == "range" and (step is None) == (num is None):
        p.fail(f"{key}.range", "give either step or num")
        return None
    if num is not None:
        if isinstance(num, bool) or not isinstance(num, int) or num < 0:
            p.fail(f"{key}.{kind}.num", f"expected a count >= 0, got {num!r}")
            return None
        if num == 0:
            p.fail(f"{key}.{kind}.num", "empty axis: num = 0")
            return None
        if num > MAX_AXIS_VALUES:
            p.fail(f"{key}.{kind}.num", f"{num} values: more than {MAX_AXIS_VALUES}")
            return None
    if kind == "logrange":
        if start <= 0 or stop <= 0:
            p.fail(f"{key}.logrange", "start and stop must be positive (a log range)")
            return None
        if num == 1:
            return (float(start),)
        a, b = math.log10(start), math.log10(stop)
        return tuple(float(10 ** (a + (b - a) * i / (num - 1))) for i in range(num))
    if num is not None:
        if num == 1:
            return (float(start),)
        return tuple(float(start + (stop - start) * i / (num - 1)) for i in range(num))
    if not _number(step) or step == 0:
        p.fail(f"{key}.range.step", "expected a finite non-zero number")
        return None
    count = math.floor((stop - start) / step * (1 + 1e-12) + 1e-9) + 1
    if count <= 0:
        p.fail(f"{key}.range", f"empty axis: no value from {start:g} to {stop:g} in steps of "
               f"{step:g}")
        return None
    if count > MAX_AXIS_VALUES:
        p.fail(f"{key}.range", f"{count} values: more than {MAX_AXIS_VALUES}")
        return None
    return tuple(round(float(start + i * step), 12) for i in range(count))


def _axes(p: _Problems, raw: Any, base: dict[str, Any]) -> list[Axis]:
    if not isinstance(raw, list) or not raw or not all(isinstance(a, dict) for a in raw):
        p.fail("axis", "expected one or more [[axis]] tables")
        return []
    out: list[Axis] = []
    seen_names: dict[str, int] = {}
    seen_targets: dict[str, int] = {}
    for i, t in enumerate(raw):
        key = f"axis.{i}"
        _unknown(p, t, AXIS_KEYS, key)
        path, derived = t.get("path"), t.get("derived")
        if (path is None) == (derived is None):
            p.fail(key, "give exactly one of path = \"...\" (a scene value) or derived = "
                   f"\"...\" ({', '.join(DERIVED)})")
            continue
        options = {k: t[k] for k in ("debond", "centre", "interfaces") if k in t}
        if path is not None:
            if not isinstance(path, str):
                p.fail(f"{key}.path", "expected a dotted path string, e.g. debonds.0.start")
                continue
            try:
                resolve(copy.deepcopy(base), path)
            except PathError as exc:
                p.fail(f"{key}.path", f"unknown path '{path}': {exc}")
                continue
            target = _canonical_path(base, path)
            if options:
                p.fail(key, f"{', '.join(options)}: only for derived parameters")
        else:
            if derived not in DERIVED:
                near = difflib.get_close_matches(str(derived), DERIVED, n=1, cutoff=0.5)
                hint = f" (did you mean '{near[0]}'?)" if near else ""
                p.fail(f"{key}.derived", f"unknown derived parameter '{derived}'{hint}; known: "
                       f"{', '.join(DERIVED)}")
                continue
            wrong = [k for k in options if k not in DERIVED_KEYS.get(derived, ())]
            if wrong:
                p.fail(f"{key}.{wrong[0]}", f"not an option of {derived}")
            if "debond" in options:
                n = len(base.get("debonds", []))
                d = options["debond"]
                if isinstance(d, bool) or not isinstance(d, int) or not 0 <= d < max(n, 1):
                    p.fail(f"{key}.debond", f"expected a debond index 0..{n - 1}, got {d!r}")
                    continue
            if derived.startswith("debond_") and not base.get("debonds"):
                p.fail(f"{key}.derived", f"{derived}: the base scene has no [[debonds]]")
                continue
            target = f"{derived}:{options.get('debond', 0)}"
            if derived == "periodic_debonds":
                target = "debonds"
        scale = t.get("scale", False)
        if not isinstance(scale, bool):
            p.fail(f"{key}.scale", "expected true or false")
            scale = False
        if scale and path is None:
            p.fail(f"{key}.scale", "only for path axes (the values multiply the base value)")
        elif scale and not _number(base_value(copy.deepcopy(base), path)):
            p.fail(f"{key}.scale", f"the base scene has no number at {path} to multiply")
        name = t.get("name", path if path is not None else derived)
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_.]{0,63}", name):
            p.fail(f"{key}.name", f"{name!r}: use a column name (letters, digits, '_', '.')")
            continue
        values = _values(p, t, key)
        if name in seen_names:
            p.fail(f"{key}.name", f"duplicate axis: '{name}' is also axis.{seen_names[name]}")
            continue
        if target in seen_targets:
            p.fail(key, f"duplicate axis: it sets what axis.{seen_targets[target]} sets "
                   f"({target})")
            continue
        seen_names[name], seen_targets[target] = i, i
        if values is None:
            continue
        if derived is not None and not all(_number(v) for v in values):
            p.fail(f"{key}.values", f"{derived} takes numbers")
            continue
        out.append(Axis(name=name, values=values, path=path, derived=derived, scale=scale,
                        options=options))
    # periodic_debonds replaces every debond: no other axis may move one
    if any(a.derived == "periodic_debonds" for a in out) and any(
            (a.path or "").startswith("debonds") or (a.derived or "").startswith("debond_")
            for a in out):
        p.fail("axis", "duplicate axis: periodic_debonds sets every debond, another axis sets "
               "one of them")
    return out


def _canonical_path(base: dict[str, Any], path: str) -> str:
    """``path`` with ``materials.<layer>`` spelled as the material's own name (for duplicates)."""
    parts = path.split(".")
    if len(parts) > 1 and parts[0] == "materials" and parts[1] in ("top", "core", "bottom"):
        m = base.get("layers", {}).get(parts[1], {}).get("material")
        if isinstance(m, str) and parts[1] not in base.get("materials", {}):
            parts[1] = m
    return ".".join(parts)


def apply(base: dict[str, Any], axes: tuple[Axis, ...] | list[Axis],
          values: dict[str, Any]) -> dict[str, Any]:
    """A deep copy of the base scene's data with every axis set to its value in ``values``."""
    data = copy.deepcopy(base)
    for axis in axes:
        v = values[axis.name]
        if axis.derived is not None:
            DERIVED[axis.derived](data, float(v), axis.options)
        elif axis.scale:
            set_path(data, axis.path, float(base_value(data, axis.path)) * float(v))
        else:
            set_path(data, axis.path, v)
    return data


def _fmt(values: dict[str, Any]) -> str:
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in values.items())


def load_study(path: str | Path) -> Study:
    """Read, check and expand the study in ``path``; raise :class:`StudyError` if it is bad.

    The base scene is read like any scene file; each case's scene is built from its data with
    the axes applied and the study's ``[analysis]`` / ``[beam_model]`` / ``[reference2d]``
    merged into the scene's tables, then checked by the scene checks.
    """
    path = Path(path)
    fname = str(path)
    data = _read_toml(path, "study")
    p = _Problems(fname)
    _unknown(p, data, TOP_KEYS, "")
    for k in ("scene", "axis"):
        if k not in data:
            p.fail(k, "missing required key")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not re.fullmatch(NAME_PATTERN, name):
        p.fail("name", f"{name!r} cannot name a result folder (letters, digits, '.', '_', '-')")
        name = "study"
    description = data.get("description", "")
    if not isinstance(description, str):
        p.fail("description", "expected a string")
    model = data.get("model", "beam")
    if model not in MODELS:
        p.fail("model", f"{model!r} is not one of {', '.join(MODELS)}")
        model = "beam"
    check = data.get("check", 0)
    check_all = check == "all"
    if check_all:
        check = MAX_CASES
    elif isinstance(check, bool) or not isinstance(check, int) or check < 0:
        p.fail("check", f"expected a count of cases >= 0 or \"all\", got {check!r}")
        check = 0
    timeout = data.get("timeout")
    if timeout is not None and (not _number(timeout) or timeout <= 0):
        p.fail("timeout", f"expected a wall-time cap in seconds > 0, got {timeout!r}")
        timeout = None
    fields = data.get("fields", False)
    if not isinstance(fields, bool):
        p.fail("fields", "expected true or false")
        fields = False
    max_cells = data.get("max_cells")
    if max_cells is not None and (isinstance(max_cells, bool) or not isinstance(max_cells, int)
                                  or max_cells < 1):
        p.fail("max_cells", f"expected a cell count >= 1, got {max_cells!r}")
        max_cells = None
    if check and model != "beam":
        p.fail("check", "2D spot checks are of a beam study (model = \"beam\")")
    tables = {}
    for t in ("analysis", "beam_model", "reference2d"):
        v = data.get(t, {})
        if not isinstance(v, dict):
            p.fail(t, "expected a table")
            v = {}
        tables[t] = v
    scene_rel = data.get("scene")
    base: dict[str, Any] = {}
    scene_path = path
    if scene_rel is not None:
        if not isinstance(scene_rel, str) or not scene_rel:
            p.fail("scene", "expected the path of the base scene file")
        else:
            scene_path = (path.parent / scene_rel) if not Path(scene_rel).is_absolute() else (
                Path(scene_rel))
            try:
                base = _read_toml(scene_path, "scene")
                build_scene(copy.deepcopy(base), str(scene_path), source=scene_path)
            except SceneError as exc:
                for prob in exc.problems:
                    p.fail("scene", f"the base scene is refused: {prob}")
                base = {}
    report = _report(p, data.get("report", {}))
    if p.items or not base:
        raise StudyError(p.items or [Problem(fname, "scene", "no base scene")])
    axes = _axes(p, data.get("axis"), base)
    if p.items:
        raise StudyError(p.items)
    for k, v in report.reference.items():
        axis = next((a for a in axes if a.name == k), None)
        if axis is None:
            p.fail(f"report.reference.{k}", f"no axis named '{k}' (axes: "
                   f"{', '.join(a.name for a in axes)})")
        elif not any(_same(v, x) for x in axis.values):
            p.fail(f"report.reference.{k}", f"{v!r} is not a value of axis '{k}'")
    n = math.prod(len(a.values) for a in axes)
    if n > MAX_CASES:
        p.fail("axis", f"{n} cases: more than {MAX_CASES}")
    if p.items:
        raise StudyError(p.items)
    cases: list[Case] = []
    refused: dict[tuple[str, ...], list[str]] = {}  # the problems -> the cases that give them
    for index, combo in enumerate(itertools.product(*(a.values for a in axes))):
        values = dict(zip((a.name for a in axes), combo, strict=True))
        case_data = apply(base, axes, values)
        for t, v in tables.items():
            if v:
                case_data[t] = {**case_data.get(t, {}), **v}
        case_data["name"] = f"{name}-{index:05d}"[:100]
        try:
            scene = build_scene(case_data, fname, source=None)
        except SceneError as exc:
            why = tuple(f"{q.key}: {q.reason}" for q in exc.problems[:3])
            refused.setdefault(why, []).append(f"case {index} ({_fmt(values)})")
            continue
        except (ValueError, TypeError, KeyError, ZeroDivisionError) as exc:
            refused.setdefault((f"cannot be built: {exc}",), []).append(
                f"case {index} ({_fmt(values)})")
            continue
        spec = get_model(model)
        cases.append(Case(index, values, scene, case_key(scene, model, spec.options(scene))))
    _report_refused(p, refused, n, tables)
    if p.items:
        raise StudyError(p.items)
    return Study(name=name, description=description, source=path, scene_path=scene_path,
                 model=model, check=check, axes=tuple(axes), report=report,
                 cases=tuple(cases), check_options=dict(tables["reference2d"]),
                 check_all=check_all, timeout=None if timeout is None else float(timeout),
                 max_cells=max_cells, fields=fields)


def _report_refused(p: _Problems, refused: dict[tuple[str, ...], list[str]], n: int,
                    tables: dict[str, dict[str, Any]]) -> None:
    """One problem per distinct reason the checks gave, not one per case.

    A reason every case gives, about a key the study's own tables set (``[beam_model]``,
    ``[reference2d]``, ``[analysis]``), is that table's key; any other names the axes and
    the first cases that give it.
    """
    for shown, (why, which) in enumerate(refused.items()):
        if shown == MAX_SHOWN:
            p.fail("axis", f"... and {len(refused) - MAX_SHOWN} more reasons")
            return
        key = why[0].split(":", 1)[0]
        table = key.split(".", 1)[0]
        if len(which) == n and table in tables and key.split(".", 1)[-1] in tables[table]:
            for reason in why:
                k, _, r = reason.partition(": ")
                p.fail(k, f"{r} (the study's [{table}] table, for every case)")
            continue
        cases = ", ".join(which[:3]) + (f" and {len(which) - 3} more" if len(which) > 3 else "")
        verb = "cases give" if len(which) > 1 else "case gives"
        p.fail("axis", f"{len(which)} of {n} {verb} a scene the checks refuse "
                       f"({'; '.join(why)}): {cases}")


def _same(a: Any, b: Any) -> bool:
    if _number(a) and _number(b):
        return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
    return a == b


def _report(p: _Problems, raw: Any) -> Report:
    if not isinstance(raw, dict):
        p.fail("report", "expected a table")
        return Report()
    _unknown(p, raw, REPORT_KEYS, "report")
    q = raw.get("quantity", "capacity")
    if q not in QUANTITIES:
        near = difflib.get_close_matches(str(q), QUANTITIES, n=1, cutoff=0.5)
        hint = f" (did you mean '{near[0]}'?)" if near else ""
        p.fail("report.quantity", f"{q!r} is not one of {', '.join(QUANTITIES)}{hint}")
        q = "capacity"
    ref = raw.get("reference", {})
    if not isinstance(ref, dict):
        p.fail("report.reference", "expected a table {axis = value}")
        ref = {}
    thr = raw.get("threshold")
    if thr is not None and (not _number(thr) or not 0 < thr < 10):
        p.fail("report.threshold", f"expected a ratio such as 0.8, got {thr!r}")
        thr = None
    if thr is not None and not ref:
        p.fail("report.threshold", "needs report.reference: the case the ratio is taken to")
    return Report(quantity=q, reference=dict(ref), threshold=None if thr is None else float(thr))


def reference_case(study: Study, case: Case) -> Case | None:
    """The case whose quantity is the knock-down reference of ``case`` (None: no reference).

    It has the reference's values on the axes the reference names and ``case``'s on the others.
    """
    if not study.report.reference:
        return None
    want = {**case.values, **study.report.reference}
    for c in study.cases:
        if all(_same(c.values[k], want[k]) for k in want):
            return c
    return None
