"""Turn parsed TOML into a :class:`~sandwich.scene.Scene`, collecting every problem on the way.

Each check names the key in dotted form (``debonds[2].end``) and says why it is refused, so that a
bad scene is answered with one line per problem before any model does any work.
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path
from typing import Any

from sandwich.scene import (
    ANALYSIS_KINDS,
    CONTACT_SEARCHES,
    CONTROLS,
    CORE_BASES,
    FACE_KINEMATICS,
    FACE_MEMBRANES,
    FACES,
    GRADINGS,
    INTERFACES,
    MAX_CORE_LEVEL,
    MESH_LEVELS,
    NAME_PATTERN,
    SUPPORT_SITES,
    SUPPORT_TYPES,
    Analysis,
    BeamModelOptions,
    CoreZone,
    Debond,
    Layer,
    Load,
    Material,
    Probe,
    Problem,
    Reference2DOptions,
    Scene,
    SceneError,
    Support,
    Toughness,
    is_finite_number,
)

TOP_KEYS = ("name", "description", "beam", "layers", "materials", "debonds", "supports", "loads",
            "analysis", "probes", "beam_model", "reference2d")
GEOMETRY_TOL = 1e-9  # mm: two stations closer than this are the same station
MAX_MAGNITUDE = 1e12  # any number of a scene (N, mm, MPa): beyond it sizes overflow the meshers
MIN_SIZE = 1e-6  # mm: the smallest length, width or thickness (1 nm)
MIN_STIFFNESS_DET = 1e-6  # 1 - (Ex/Ez) nu_zx^2 below this: a nearly singular material
MIN_TOL = 1e-14  # the Newton tolerance cannot go below round-off
_MISSING = object()


class Reader:
    """Collects problems while reading values out of nested TOML tables."""

    def __init__(self, fname: str):
        self.fname = fname
        self.problems: list[Problem] = []

    def fail(self, key: str, reason: str) -> None:
        """Record a problem at ``key``."""
        self.problems.append(Problem(self.fname, key, reason))

    def table(self, value: Any, key: str, allowed: tuple[str, ...],
              required: tuple[str, ...] = (),
              renamed: dict[str, str] | None = None) -> dict[str, Any] | None:
        """Check that ``value`` is a table with only ``allowed`` keys and all ``required`` ones.

        ``renamed`` maps a key's former name to its name now: the old one is refused with it.
        """
        if not isinstance(value, dict):
            self.fail(key, f"expected a table, got {_typename(value)}")
            return None
        for k in value:
            if renamed and k in renamed:
                self.fail(_join(key, k), f"renamed '{renamed[k]}'")
            elif k not in allowed:
                near = difflib.get_close_matches(k, allowed, n=1, cutoff=0.6)
                hint = (f" (did you mean '{near[0]}'?)" if near
                        else f" (allowed: {', '.join(allowed)})")
                self.fail(_join(key, k), f"unknown key{hint}")
        for k in required:
            if k not in value:
                self.fail(_join(key, k), "missing required key")
        return value

    def number(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING,
               positive: bool = False, nonneg: bool = False, nonzero: bool = False) -> Any:
        """Read a finite number (int or float), with optional sign checks."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = _join(key, k)
        if not is_finite_number(v):
            self.fail(full, "expected a finite number" if isinstance(v, float)
                      else f"expected a number, got {_typename(v)}")
            return None
        v = float(v)
        if abs(v) > MAX_MAGNITUDE:
            self.fail(full, f"{v:g} is beyond any physical scale of this tool (|value| <= "
                      f"{MAX_MAGNITUDE:g} in N, mm, MPa)")
            return None
        if positive and v <= 0:
            self.fail(full, f"must be positive, got {v:g}")
            return None
        if nonneg and v < 0:
            self.fail(full, f"must not be negative, got {v:g}")
            return None
        if nonzero and v == 0:
            self.fail(full, "must not be zero")
            return None
        return v

    def integer(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING,
                lo: int | None = None, hi: int | None = None) -> Any:
        """Read an integer within [lo, hi]."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = _join(key, k)
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(full, f"expected an integer, got {_typename(v)}")
            return None
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            self.fail(full, f"must be between {lo} and {hi}, got {v}")
            return None
        return v

    def boolean(self, tbl: dict[str, Any], k: str, key: str, *, default: bool) -> bool:
        """Read true or false."""
        v = tbl.get(k, default)
        if not isinstance(v, bool):
            self.fail(_join(key, k), f"expected true or false, got {_typename(v)}")
            return default
        return v

    def choice(self, tbl: dict[str, Any], k: str, key: str, options: tuple[str, ...], *,
               default: Any = _MISSING) -> Any:
        """Read a string that must be one of ``options``."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = _join(key, k)
        if not isinstance(v, str):
            self.fail(full, f"expected one of {', '.join(options)}, got {_typename(v)}")
            return None
        if v not in options:
            near = difflib.get_close_matches(v, options, n=1, cutoff=0.5)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            self.fail(full, f"'{v}' is not one of {', '.join(options)}{hint}")
            return None
        return v

    def string(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING) -> Any:
        """Read a non-empty string."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        if not isinstance(v, str) or not v.strip():
            self.fail(_join(key, k), f"expected a non-empty string, got {_typename(v)}")
            return None
        return v

    def array_of_tables(self, value: Any, key: str) -> list[Any]:
        """Check that ``value`` is an array of tables (``[[key]]``)."""
        if not isinstance(value, list) or not all(isinstance(x, dict) for x in value):
            self.fail(key, f"expected an array of tables ([[{key}]]), got {_typename(value)}")
            return []
        return value


def _join(key: str, k: str) -> str:
    return f"{key}.{k}" if key else k


def _typename(v: Any) -> str:
    return {bool: "boolean", int: "integer", float: "number", str: "string", list: "array",
            dict: "table"}.get(type(v), type(v).__name__)


def build_scene(data: dict[str, Any], fname: str, source: Path | None = None) -> Scene:
    """Validate parsed TOML ``data`` and build the :class:`Scene`; raise :class:`SceneError`."""
    r = Reader(fname)
    r.table(data, "", TOP_KEYS, required=("name", "beam", "layers", "materials", "supports",
                                          "loads", "analysis"))
    name = r.string(data, "name", "", default="")
    _check_name(r, name, "name")
    description = data.get("description", "")
    if not isinstance(description, str):
        r.fail("description", f"expected a string, got {_typename(description)}")
        description = ""
    length, width = _beam(r, data.get("beam", {}))
    materials = _materials(r, data.get("materials", {}))
    layers = _layers(r, data.get("layers", {}), materials)
    L = length if length else None
    debonds = _debonds(r, data.get("debonds", []), L)
    supports = _supports(r, data.get("supports", []), L)
    loads = _loads(r, data.get("loads", []), L)
    probes = _probes(r, data.get("probes", []), L)
    analysis = _analysis(r, data.get("analysis", {}), probes)
    beam_model = _beam_model(r, data.get("beam_model", {}))
    for i, z in enumerate(beam_model.core_zones):
        if L is not None and (z.start < 0 or z.end > L):
            r.fail(f"beam_model.core_zones.{i}", f"[{z.start:g}, {z.end:g}] is not inside the "
                   f"beam [0, {L:g}]")
    reference2d = _reference2d(r, data.get("reference2d", {}))
    if not r.problems:
        _check_mechanism(r, supports, debonds, length)
    if r.problems:
        raise SceneError(r.problems)
    return Scene(name=name, description=description, length=length, width=width,
                 top=layers["top"], core=layers["core"], bottom=layers["bottom"],
                 debonds=tuple(debonds), supports=tuple(supports), loads=tuple(loads),
                 probes=tuple(probes), analysis=analysis, beam_model=beam_model,
                 reference2d=reference2d, source=source)


def _check_name(r: Reader, name: Any, key: str) -> bool:
    """Refuse a name that cannot be a folder or file name (it becomes one in the results)."""
    if isinstance(name, str) and name and not re.fullmatch(NAME_PATTERN, name):
        r.fail(key, f"'{name[:40]}' cannot name a result folder or file: use 1-100 letters, "
               "digits, '.', '_' or '-', starting with a letter or digit")
        return False
    return True


def _beam(r: Reader, tbl: Any) -> tuple[float, float]:
    t = r.table(tbl, "beam", ("length", "width"), required=("length", "width"))
    if t is None:
        return 0.0, 0.0
    return (_size(r, t, "length", "beam") or 0.0, _size(r, t, "width", "beam") or 0.0)


def _size(r: Reader, t: dict[str, Any], k: str, key: str) -> float | None:
    """A positive length (mm) no smaller than ``MIN_SIZE``."""
    v = r.number(t, k, key, positive=True)
    if v is not None and v < MIN_SIZE:
        r.fail(_join(key, k), f"{v:g} mm is below the smallest size {MIN_SIZE:g} mm")
        return None
    return v


def _materials(r: Reader, tbl: Any) -> dict[str, Material]:
    t = r.table(tbl, "materials", tuple(tbl) if isinstance(tbl, dict) else ())
    out: dict[str, Material] = {}
    if t is None:
        return out
    if not t:
        r.fail("materials", "no material defined")
    for mname, m in t.items():
        key = f"materials.{mname}"
        if not isinstance(m, dict):
            r.fail(key, f"expected a table, got {_typename(m)}")
            continue
        if "E" in m or "nu" in m:
            mt = r.table(m, key, ("E", "nu"), required=("E", "nu"))
            E = r.number(mt, "E", key, positive=True)
            nu = r.number(mt, "nu", key)
            if nu is not None and not -1.0 < nu < 1.0:
                r.fail(f"{key}.nu", f"{nu:g} makes the plane-stress stiffness not positive "
                       "definite (need -1 < nu < 1)")
                nu = None
            elif nu is not None and 1.0 - nu**2 < MIN_STIFFNESS_DET:
                r.fail(f"{key}.nu", f"{nu:g} makes the plane-stress stiffness nearly singular "
                       f"(1 - nu^2 = {1 - nu**2:.3g} < {MIN_STIFFNESS_DET:g})")
                nu = None
            if E is not None and nu is not None:
                out[mname] = Material(mname, "isotropic", E, E, E / (2 * (1 + nu)), nu)
        else:
            mt = r.table(m, key, ("Ex", "Ez", "Gzx", "nu_zx"),
                         required=("Ex", "Ez", "Gzx", "nu_zx"))
            Ex = r.number(mt, "Ex", key, positive=True)
            Ez = r.number(mt, "Ez", key, positive=True)
            G = r.number(mt, "Gzx", key, positive=True)
            nu = r.number(mt, "nu_zx", key)
            if None in (Ex, Ez, G, nu):
                continue
            if 1.0 - (Ex / Ez) * nu**2 <= 0.0:
                r.fail(f"{key}.nu_zx", f"1 - (Ex/Ez) nu_zx^2 = {1 - Ex / Ez * nu**2:.3g} <= 0: "
                       "the plane-stress stiffness is not positive definite")
                continue
            if 1.0 - (Ex / Ez) * nu**2 < MIN_STIFFNESS_DET:
                r.fail(f"{key}.nu_zx", f"1 - (Ex/Ez) nu_zx^2 = {1 - Ex / Ez * nu**2:.3g} < "
                       f"{MIN_STIFFNESS_DET:g}: the plane-stress stiffness is nearly singular")
                continue
            out[mname] = Material(mname, "orthotropic", Ex, Ez, G, nu)
    return out


def _layers(r: Reader, tbl: Any, materials: dict[str, Material]) -> dict[str, Layer]:
    dummy = Layer(1.0, Material("-", "isotropic", 1.0, 1.0, 0.5, 0.0))
    out = {"top": dummy, "core": dummy, "bottom": dummy}
    t = r.table(tbl, "layers", ("top", "core", "bottom"), required=("top", "core", "bottom"))
    if t is None:
        return out
    for lname in ("top", "core", "bottom"):
        if lname not in t:
            continue
        key = f"layers.{lname}"
        lt = r.table(t[lname], key, ("thickness", "material"), required=("thickness", "material"))
        if lt is None:
            continue
        h = _size(r, lt, "thickness", key)
        mname = r.string(lt, "material", key)
        mat = None
        if isinstance(mname, str):
            mat = materials.get(mname)
            if mat is None and isinstance(tbl, dict):
                near = difflib.get_close_matches(mname, list(materials), n=1, cutoff=0.5)
                hint = f" (did you mean '{near[0]}'?)" if near else ""
                r.fail(f"{key}.material", f"no material '{mname}' in [materials]{hint}")
        if h is not None and mat is not None:
            out[lname] = Layer(h, mat)
    return out


def _station(r: Reader, t: dict[str, Any], k: str, key: str, L: float | None) -> float | None:
    v = r.number(t, k, key)
    if v is not None and L is not None and not -GEOMETRY_TOL <= v <= L + GEOMETRY_TOL:
        r.fail(_join(key, k), f"{v:g} is outside the beam [0, {L:g}]")
        return None
    return v


def _debonds(r: Reader, arr: Any, L: float | None) -> list[Debond]:
    out: list[tuple[int, Debond]] = []
    for i, d in enumerate(r.array_of_tables(arr, "debonds")):
        key = f"debonds[{i}]"
        t = r.table(d, key, ("interface", "start", "end", "toughness"),
                    required=("interface", "start", "end"))
        if t is None:
            continue
        itf = r.choice(t, "interface", key, INTERFACES)
        a = _station(r, t, "start", key, L)
        b = _station(r, t, "end", key, L)
        if a is not None and b is not None and b < a:
            r.fail(f"{key}.end", f"end {b:g} is before start {a:g}")
            continue
        tough = _toughness(r, t, key, a, b)
        if None not in (itf, a, b):
            out.append((i, Debond(itf, a, b, tough)))
    for itf in INTERFACES:
        same = sorted((x for x in out if x[1].interface == itf), key=lambda x: x[1].start)
        for (i, d1), (j, d2) in zip(same, same[1:], strict=False):
            if d2.start <= d1.end + GEOMETRY_TOL:
                r.fail(f"debonds[{j}]", f"overlaps or touches debonds[{i}] on the {itf} interface "
                       f"([{d1.start:g}, {d1.end:g}] and [{d2.start:g}, {d2.end:g}]); "
                       "merge them into one debond")
    return [d for _, d in out]


def _toughness(r: Reader, t: dict[str, Any], key: str, a: float | None,
               b: float | None) -> Toughness | None:
    """``toughness = { GIc, GIIc, eta }`` of a debond (N/mm; eta the Benzeggagh–Kenane exponent)."""
    if "toughness" not in t:
        return None
    key = f"{key}.toughness"
    tt = r.table(t["toughness"], key, ("GIc", "GIIc", "eta"), required=("GIc", "GIIc"))
    if tt is None:
        return None
    gic = r.number(tt, "GIc", key, positive=True)
    giic = r.number(tt, "GIIc", key, positive=True)
    eta = r.number(tt, "eta", key, default=2.0, positive=True)
    if a is not None and b is not None and b - a <= GEOMETRY_TOL:
        r.fail(key, "a zero-length debond is bonded: it has no tip whose growth to judge")
        return None
    if None in (gic, giic, eta):
        return None
    return Toughness(gic, giic, eta)


def _supports(r: Reader, arr: Any, L: float | None) -> list[Support]:
    out = []
    items = r.array_of_tables(arr, "supports")
    if isinstance(arr, list) and not arr:
        r.fail("supports", "no support: the beam is a free body (a mechanism)")
    for i, s in enumerate(items):
        key = f"supports[{i}]"
        t = r.table(s, key, ("x", "on", "type"), required=("x", "on", "type"))
        if t is None:
            continue
        x = _station(r, t, "x", key, L)
        on = r.choice(t, "on", key, SUPPORT_SITES)
        typ = r.choice(t, "type", key, SUPPORT_TYPES)
        if None not in (x, on, typ):
            out.append(Support(x, on, typ))
    return out


def _loads(r: Reader, arr: Any, L: float | None) -> list[Load]:
    out = []
    items = r.array_of_tables(arr, "loads")
    if isinstance(arr, list) and not arr:
        r.fail("loads", "no load: nothing to solve for")
    for i, s in enumerate(items):
        key = f"loads[{i}]"
        t = r.table(s, key, ("on", "x", "width", "force"), required=("on", "x", "force"))
        if t is None:
            continue
        on = r.choice(t, "on", key, FACES)
        x = _station(r, t, "x", key, L)
        w = r.number(t, "width", key, default=0.0, nonneg=True)
        f = r.number(t, "force", key, nonzero=True)
        if x is not None and w is not None and L is not None:
            if x - w / 2 < -GEOMETRY_TOL or x + w / 2 > L + GEOMETRY_TOL:
                r.fail(f"{key}.width", f"the patch [{x - w / 2:g}, {x + w / 2:g}] reaches outside "
                       f"the beam [0, {L:g}]")
                continue
        if None not in (on, x, w, f):
            out.append(Load(on, x, w, f))
    return out


def _probes(r: Reader, arr: Any, L: float | None) -> list[Probe]:
    out: list[Probe] = []
    for i, s in enumerate(r.array_of_tables(arr, "probes")):
        key = f"probes[{i}]"
        t = r.table(s, key, ("name", "on", "x"), required=("name", "on", "x"))
        if t is None:
            continue
        name = r.string(t, "name", key)
        if not _check_name(r, name, f"{key}.name"):
            name = None
        on = r.choice(t, "on", key, FACES)
        x = _station(r, t, "x", key, L)
        if name is not None and any(p.name == name for p in out):
            r.fail(f"{key}.name", f"probe name '{name}' is used twice")
            continue
        if None not in (name, on, x):
            out.append(Probe(name, on, x))
    return out


def _analysis(r: Reader, tbl: Any, probes: list[Probe]) -> Analysis:
    key = "analysis"
    t = r.table(tbl, key, ("kind", "control", "until", "max_steps", "initial_increment",
                           "min_increment", "max_increment", "tol", "max_iterations",
                           "locate_critical_points"),
                required=("kind", "until"),
                # until 2026-12-05 (it narrows load extrema as well now)
                renamed={"locate_bifurcations": "locate_critical_points"})
    if t is None:
        return Analysis()
    kind = r.choice(t, "kind", key, ANALYSIS_KINDS, default=Analysis.kind)
    control = r.choice(t, "control", key, CONTROLS, default=Analysis.control)
    until_probe = until_value = until_lf = None
    if "until" in t:
        u = r.table(t["until"], "analysis.until", ("probe", "value", "load_factor"))
        if u is not None:
            if "load_factor" in u and ("probe" in u or "value" in u):
                r.fail("analysis.until", "give either load_factor or probe + value, not both")
            elif "load_factor" in u:
                until_lf = r.number(u, "load_factor", "analysis.until", nonzero=True)
            elif "probe" in u or "value" in u:
                until_probe = r.string(u, "probe", "analysis.until")
                until_value = r.number(u, "value", "analysis.until", nonzero=True)
                if "probe" not in u:
                    r.fail("analysis.until.probe", "missing: which probe should reach the value?")
                if "value" not in u:
                    r.fail("analysis.until.value", "missing: which value should the probe reach?")
                names = [p.name for p in probes]
                if isinstance(until_probe, str) and until_probe not in names:
                    near = difflib.get_close_matches(until_probe, names, n=1, cutoff=0.5)
                    hint = f" (did you mean '{near[0]}'?)" if near else (
                        f" (probes: {', '.join(names)})" if names else " (no [[probes]] defined)")
                    r.fail("analysis.until.probe", f"no probe named '{until_probe}'{hint}")
            else:
                r.fail("analysis.until", "empty: give load_factor, or probe and value")
    if control == "displacement" and kind == "nonlinear" and "until" in t and until_probe is None:
        r.fail("analysis.control", "displacement control needs until = { probe, value }: "
               "the probe is the controlled displacement")
    d = Analysis()
    max_steps = r.integer(t, "max_steps", key, default=d.max_steps, lo=1, hi=100_000)
    inc = r.number(t, "initial_increment", key, default=None, positive=True)
    lo = r.number(t, "min_increment", key, default=None, positive=True)
    hi = r.number(t, "max_increment", key, default=None, positive=True)
    if lo is not None and hi is not None and lo > hi:
        r.fail("analysis.min_increment", f"{lo:g} is larger than max_increment {hi:g}")
    tol = r.number(t, "tol", key, default=d.tol, positive=True)
    if tol is not None and tol >= 1e-2:
        r.fail("analysis.tol", f"{tol:g} is too loose for equilibrium (use < 1e-2)")
    elif tol is not None and tol < MIN_TOL:
        r.fail("analysis.tol", f"{tol:g} is below round-off: Newton cannot reach it "
               f"(use >= {MIN_TOL:g})")
    max_it = r.integer(t, "max_iterations", key, default=d.max_iterations, lo=1, hi=1000)
    return Analysis(kind=kind or d.kind, control=control or d.control, until_probe=until_probe,
                    until_value=until_value, until_load_factor=until_lf,
                    max_steps=max_steps or d.max_steps, initial_increment=inc, min_increment=lo,
                    max_increment=hi, tol=tol or d.tol, max_iterations=max_it or d.max_iterations,
                    locate_critical_points=r.boolean(t, "locate_critical_points", key,
                                                  default=d.locate_critical_points))


def _beam_model(r: Reader, tbl: Any) -> BeamModelOptions:
    key = "beam_model"
    t = r.table(tbl, key, ("elements", "grading", "face_membrane", "faces", "contact_search",
                           "gauss_x", "gauss_z",
                           "contact_penalty", "profile_every", "core", "core_basis", "tolerance",
                           "max_core_level", "core_zones", "settling_allowance"))
    if t is None:
        return BeamModelOptions()
    d = BeamModelOptions()
    core: Any = d.core
    if "core" in t:
        core = t["core"]
        if core != "auto" and (isinstance(core, bool) or not isinstance(core, int)
                               or not 1 <= core <= MAX_CORE_LEVEL):
            r.fail("beam_model.core", f"expected \"auto\" or a core level 1..{MAX_CORE_LEVEL}, "
                   f"got {core!r}")
            core = d.core
    tolerance = r.number(t, "tolerance", key, default=d.tolerance, positive=True)
    if tolerance is not None and not 1e-6 <= tolerance <= 0.5:
        r.fail("beam_model.tolerance", f"must be between 1e-6 and 0.5 (a relative error), "
               f"got {tolerance:g}")
        tolerance = None
    zones = []
    for i, z in enumerate(r.array_of_tables(t.get("core_zones", []), "beam_model.core_zones")):
        zkey = f"beam_model.core_zones.{i}"
        zt = r.table(z, zkey, ("start", "end", "level"), required=("start", "end", "level"))
        if zt is None:
            continue
        a, b = r.number(zt, "start", zkey), r.number(zt, "end", zkey)
        level = r.integer(zt, "level", zkey, lo=1, hi=MAX_CORE_LEVEL)
        if a is not None and b is not None and b <= a:
            r.fail(f"{zkey}.end", f"must be greater than start ({b:g} <= {a:g})")
        elif None not in (a, b, level):
            zones.append(CoreZone(start=a, end=b, level=level))
    return BeamModelOptions(
        core=core,
        core_basis=r.choice(t, "core_basis", key, CORE_BASES, default=d.core_basis)
        or d.core_basis,
        tolerance=tolerance or d.tolerance,
        max_core_level=r.integer(t, "max_core_level", key, default=d.max_core_level, lo=1,
                                 hi=MAX_CORE_LEVEL) or d.max_core_level,
        core_zones=tuple(zones),
        elements=r.integer(t, "elements", key, default=d.elements, lo=2, hi=200_000) or d.elements,
        grading=r.choice(t, "grading", key, GRADINGS, default=d.grading)
        or d.grading,
        face_membrane=r.choice(t, "face_membrane", key, FACE_MEMBRANES,
                               default=d.face_membrane) or d.face_membrane,
        faces=r.choice(t, "faces", key, FACE_KINEMATICS, default=d.faces) or d.faces,
        contact_search=r.choice(t, "contact_search", key, CONTACT_SEARCHES,
                                default=d.contact_search) or d.contact_search,
        gauss_x=r.integer(t, "gauss_x", key, default=None, lo=2, hi=12),
        gauss_z=r.integer(t, "gauss_z", key, default=None, lo=2, hi=12),
        contact_penalty=r.number(t, "contact_penalty", key, default=None, positive=True),
        profile_every=r.integer(t, "profile_every", key, default=0, lo=0) or 0,
        settling_allowance=r.integer(t, "settling_allowance", key,
                                     default=d.settling_allowance, lo=0, hi=1000),
    )


def _reference2d(r: Reader, tbl: Any) -> Reference2DOptions:
    key = "reference2d"
    t = r.table(tbl, key, ("level", "refine", "face_elements", "core_size", "face_size",
                           "tip_size", "half_model", "contact_penalty", "profile_every",
                           "closure_length"))
    if t is None:
        return Reference2DOptions()
    d = Reference2DOptions()
    level = r.choice(t, "level", key, MESH_LEVELS, default=d.level)
    sizes = {k: r.number(t, k, key, default=None, positive=True)
             for k in ("core_size", "face_size", "tip_size")}
    if level == "explicit" and sizes["core_size"] is None:
        r.fail("reference2d.core_size", "level 'explicit' needs core_size (mm)")
    half = r.boolean(t, "half_model", key, default=False)
    return Reference2DOptions(
        level=level or d.level,
        refine=r.integer(t, "refine", key, default=d.refine, lo=0, hi=6) or 0,
        face_elements=r.integer(t, "face_elements", key, default=d.face_elements, lo=1, hi=16)
        or d.face_elements,
        half_model=half,
        contact_penalty=r.number(t, "contact_penalty", key, default=None, positive=True),
        profile_every=r.integer(t, "profile_every", key, default=0, lo=0) or 0,
        closure_length=r.number(t, "closure_length", key, default=None, positive=True),
        **sizes,
    )


def _covered(debonds: list[Debond], interface: str, L: float) -> bool:
    """Whether the debonds of ``interface`` leave no bonded stretch of positive length."""
    spans = sorted((d.start, d.end) for d in debonds if d.interface == interface)
    pos = 0.0
    for a, b in spans:
        if a > pos + GEOMETRY_TOL:
            return False
        pos = max(pos, b)
    return pos >= L - GEOMETRY_TOL


def _check_mechanism(r: Reader, supports: list[Support], debonds: list[Debond], L: float) -> None:
    """Refuse supports that leave a rigid-body motion free (a mechanism)."""
    if not supports:
        return
    clamps = [s for s in supports if s.type == "clamp"]
    w_stations = {round(s.x, 9) for s in supports}
    if not clamps and len(w_stations) < 2:
        r.fail("supports", "a mechanism: w is held at one station only and nothing is clamped, "
               "so the beam can rotate; add a second support or a clamp")
    if not any(s.type in ("pin", "clamp") for s in supports):
        r.fail("supports", "a mechanism: only rollers, so the beam can slide along x; "
               "make one support a pin or a clamp")
    free_top = _covered(debonds, "top", L)
    free_bottom = _covered(debonds, "bottom", L)
    for face, free in (("top", free_top), ("bottom", free_bottom)):
        if free and not any(face in s.faces for s in supports):
            r.fail("debonds", f"the {face} face is debonded over the whole length and has no "
                   "support of its own: it is a free body (a mechanism)")
    if free_top and free_bottom:
        r.fail("debonds", "both interfaces are debonded over the whole length: the core is a "
               "free body (a mechanism)")
