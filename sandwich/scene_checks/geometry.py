"""The checks of the beam's geometry, its materials and its layers."""

from __future__ import annotations

import difflib
from typing import Any

from sandwich.scene import (
    Layer,
    Material,
)
from sandwich.scene_checks.reader import Reader, join_key, typename

__all__ = ["MIN_SIZE", "MIN_STIFFNESS_DET", "read_beam", "read_layers", "read_materials"]

MIN_SIZE = 1e-6  # mm: the smallest length, width or thickness (1 nm)
MIN_STIFFNESS_DET = 1e-6  # 1 - (Ex/Ez) nu_zx^2 below this: a nearly singular material


def read_beam(r: Reader, tbl: Any) -> tuple[float, float]:
    """``[beam]``: length and width (mm); 0.0 for one that is refused."""
    t = r.table(tbl, "beam", ("length", "width"), required=("length", "width"))
    if t is None:
        return 0.0, 0.0
    return (_size(r, t, "length", "beam") or 0.0, _size(r, t, "width", "beam") or 0.0)


def _size(r: Reader, t: dict[str, Any], k: str, key: str) -> float | None:
    """A positive length (mm) no smaller than ``MIN_SIZE``."""
    v = r.number(t, k, key, positive=True)
    if v is not None and v < MIN_SIZE:
        r.fail(join_key(key, k), f"{v:g} mm is below the smallest size {MIN_SIZE:g} mm")
        return None
    return v


def read_materials(r: Reader, tbl: Any) -> dict[str, Material]:
    """``[materials]``: isotropic (E, nu) or orthotropic (Ex, Ez, Gzx, nu_zx), by name."""
    t = r.table(tbl, "materials", tuple(tbl) if isinstance(tbl, dict) else ())
    out: dict[str, Material] = {}
    if t is None:
        return out
    if not t:
        r.fail("materials", "no material defined")
    for mname, m in t.items():
        key = f"materials.{mname}"
        if not isinstance(m, dict):
            r.fail(key, f"expected a table, got {typename(m)}")
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


def read_layers(r: Reader, tbl: Any, materials: dict[str, Material]) -> dict[str, Layer]:
    """``[layers]``: top, core and bottom (a placeholder layer for one that is refused)."""
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
