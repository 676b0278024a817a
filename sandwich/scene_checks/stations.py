"""The checks of what sits at stations along the beam: debonds, supports, loads and probes.

Also the check that the supports hold the beam (:func:`check_mechanism`).
"""

from __future__ import annotations

from typing import Any

from sandwich.cohesive_law import default_shear_strength, least_stiffness
from sandwich.scene import (
    FACES,
    GROWTH_METHODS,
    INTERFACES,
    SUPPORT_SITES,
    SUPPORT_TYPES,
    Debond,
    Growth,
    Load,
    Probe,
    Support,
    Toughness,
)
from sandwich.scene_checks.reader import Reader, check_name, join_key

__all__ = ["GEOMETRY_TOL", "check_mechanism", "read_debonds", "read_loads", "read_probes",
           "read_supports"]

GEOMETRY_TOL = 1e-9  # mm: two stations closer than this are the same station
COHESIVE_KEYS = ("sigma_c", "tau_c", "zone", "stiffness")


def _station(r: Reader, t: dict[str, Any], k: str, key: str, L: float | None) -> float | None:
    v = r.number(t, k, key)
    if v is not None and L is not None and not -GEOMETRY_TOL <= v <= L + GEOMETRY_TOL:
        r.fail(join_key(key, k), f"{v:g} is outside the beam [0, {L:g}]")
        return None
    return v


def read_debonds(r: Reader, arr: Any, L: float | None) -> list[Debond]:
    """``[[debonds]]`` on the beam [0, L]: none may overlap or touch another on its interface."""
    out: list[tuple[int, Debond]] = []
    for i, d in enumerate(r.array_of_tables(arr, "debonds")):
        key = f"debonds[{i}]"
        t = r.table(d, key, ("interface", "start", "end", "toughness", "growth"),
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
        grow = _growth(r, t, key, a, b, L, tough)
        if None not in (itf, a, b):
            out.append((i, Debond(itf, a, b, tough, grow)))
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


def _growth(r: Reader, t: dict[str, Any], key: str, a: float | None, b: float | None,
            L: float | None, tough: Toughness | None) -> Growth | None:
    """``growth = { ... }`` of a debond: crack-length control or a cohesive law.

    Crack-length: ``step``, ``max_length`` (mm). Cohesive: ``sigma_c`` (MPa, required),
    ``tau_c`` (MPa, default σ_c √(G_IIc/G_Ic)), ``zone`` (mm), ``stiffness`` (N/mm³).
    """
    if "growth" not in t:
        return None
    key = f"{key}.growth"
    gt = r.table(t["growth"], key, ("method", "step", "max_length") + COHESIVE_KEYS)
    if gt is None:
        return None
    if "toughness" not in t:
        r.fail(key, "growth needs the debond's toughness = { GIc, GIIc } (N/mm): it decides "
               "at what load each tip advances")
        return None
    method = r.choice(gt, "method", key, GROWTH_METHODS, default="crack-length")
    if method == "cohesive":
        return _cohesive_growth(r, gt, key, tough)
    if method is None:
        return None
    for k in COHESIVE_KEYS:
        if k in gt:
            r.fail(f"{key}.{k}", "a cohesive law's key: it needs method = \"cohesive\" "
                   "(crack-length control takes step and max_length)")
    step = r.number(gt, "step", key, default=2.0, positive=True)
    most = r.number(gt, "max_length", key, default=None, positive=True)
    if None in (step, a, b) or tough is None:
        return None
    if most is not None and most < b - a + step - GEOMETRY_TOL:
        r.fail(f"{key}.max_length", f"{most:g} mm leaves no room to grow the debond "
               f"[{a:g}, {b:g}] ({b - a:g} mm long) by one step of {step:g} mm")
        return None
    if L is not None and step > 0.25 * L:
        r.fail(f"{key}.step", f"{step:g} mm is more than a quarter of the beam ({L:g} mm)")
        return None
    return Growth(step, most)


def _cohesive_growth(r: Reader, gt: dict[str, Any], key: str,
                     tough: Toughness | None) -> Growth | None:
    """The cohesive law's keys of ``growth`` (method = "cohesive")."""
    for k in ("step", "max_length"):
        if k in gt:
            r.fail(f"{key}.{k}", "a crack-length control key: a cohesive tip moves with the "
                   "law along the one path (zone bounds how far it may run)")
    if "sigma_c" not in gt:
        r.fail(key, "a cohesive law needs its opening strength sigma_c (MPa)")
    sigma = r.number(gt, "sigma_c", key, default=None, positive=True)
    tau = r.number(gt, "tau_c", key, default=None, positive=True)
    zone = r.number(gt, "zone", key, default=None, positive=True)
    stiffness = r.number(gt, "stiffness", key, default=None, positive=True)
    if sigma is None or tough is None:
        return None
    if tau is None and "tau_c" not in gt:
        tau = default_shear_strength(sigma, tough.GIc, tough.GIIc)
    if tau is None:
        return None
    floor = least_stiffness(sigma, tau, tough.GIc, tough.GIIc)
    if stiffness is not None and stiffness <= floor:
        r.fail(f"{key}.stiffness", f"{stiffness:g} N/mm³ is below {floor:.4g} "
               "(σ_c²/(2 G_Ic), τ_c²/(2 G_IIc)): the law would soften before its strength")
        return None
    return Growth(method="cohesive", sigma_c=sigma, tau_c=tau, zone=zone, stiffness=stiffness)


def read_supports(r: Reader, arr: Any, L: float | None) -> list[Support]:
    """``[[supports]]`` on the beam [0, L]: at least one."""
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


def read_loads(r: Reader, arr: Any, L: float | None) -> list[Load]:
    """``[[loads]]`` on the beam [0, L], a patch inside it: at least one."""
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


def read_probes(r: Reader, arr: Any, L: float | None) -> list[Probe]:
    """``[[probes]]`` on the beam [0, L], each name used once."""
    out: list[Probe] = []
    for i, s in enumerate(r.array_of_tables(arr, "probes")):
        key = f"probes[{i}]"
        t = r.table(s, key, ("name", "on", "x"), required=("name", "on", "x"))
        if t is None:
            continue
        name = r.string(t, "name", key)
        if not check_name(r, name, f"{key}.name"):
            name = None
        on = r.choice(t, "on", key, FACES)
        x = _station(r, t, "x", key, L)
        if name is not None and any(p.name == name for p in out):
            r.fail(f"{key}.name", f"probe name '{name}' is used twice")
            continue
        if None not in (name, on, x):
            out.append(Probe(name, on, x))
    return out


def _covered(debonds: list[Debond], interface: str, L: float) -> bool:
    """Whether the debonds of ``interface`` leave no bonded stretch of positive length."""
    spans = sorted((d.start, d.end) for d in debonds if d.interface == interface)
    pos = 0.0
    for a, b in spans:
        if a > pos + GEOMETRY_TOL:
            return False
        pos = max(pos, b)
    return pos >= L - GEOMETRY_TOL


def check_mechanism(r: Reader, supports: list[Support], debonds: list[Debond], L: float) -> None:
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
