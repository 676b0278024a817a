"""The checks of the analysis, the models' options and ``[accuracy]``."""

from __future__ import annotations

import dataclasses
import difflib
from typing import Any

from sandwich.scene import (
    ANALYSIS_KINDS,
    CONTACT_SEARCHES,
    CONTROLS,
    CORE_BASES,
    FACE_KINEMATICS,
    FACE_MEMBRANES,
    GRADINGS,
    MAX_CORE_LEVEL,
    MESH_LEVELS,
    Accuracy,
    Analysis,
    BeamModelOptions,
    CoreZone,
    Probe,
    Reference2DOptions,
)
from sandwich.scene_checks.reader import Reader

__all__ = ["MIN_TOL", "read_accuracy", "read_analysis", "read_beam_model",
           "read_reference2d"]

#: the range a relative tolerance of ``[accuracy]`` (and ``[beam_model] tolerance``) must lie in
TOLERANCE_RANGE = (1e-6, 0.5)
MIN_TOL = 1e-14  # the Newton tolerance cannot go below round-off


def read_analysis(r: Reader, tbl: Any, probes: list[Probe]) -> Analysis:
    """``[analysis]``: kind, control, target (``until``) and the path follower's settings."""
    key = "analysis"
    t = r.table(tbl, key, ("kind", "control", "until", "max_steps", "initial_increment",
                           "min_increment", "max_increment", "tol", "max_iterations",
                           "locate_critical_points"),
                required=("kind", "until"),
                # its former name (it narrows load extrema as well as bifurcations)
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


def read_beam_model(r: Reader, tbl: Any) -> BeamModelOptions:
    """``[beam_model]``: the beam model's options (defaults for those not given)."""
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
    if tolerance is not None and not TOLERANCE_RANGE[0] <= tolerance <= TOLERANCE_RANGE[1]:
        r.fail("beam_model.tolerance", f"must be between {TOLERANCE_RANGE[0]:g} and "
               f"{TOLERANCE_RANGE[1]:g} (a relative error), got {tolerance:g}")
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


def read_reference2d(r: Reader, tbl: Any) -> Reference2DOptions:
    """``[reference2d]``: the 2D model's options (defaults for those not given)."""
    key = "reference2d"
    t = r.table(tbl, key, ("level", "refine", "face_elements", "core_size", "face_size",
                           "tip_size", "half_model", "contact_penalty", "profile_every",
                           "closure_length", "error_estimate"))
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
        error_estimate=r.boolean(t, "error_estimate", key, default=d.error_estimate),
        **sizes,
    )



def read_accuracy(r: Reader, tbl: Any, beam_model: BeamModelOptions,
                  beam_tolerance_given: bool) -> tuple[Accuracy, BeamModelOptions]:
    """``[accuracy]``: the quantities a run estimates and their tolerances.

    ``load`` is the beam's ``[beam_model] tolerance`` as well (given twice: refused); ``G`` and
    ``stresses`` may be ``false`` (not estimated). Returns the table and the beam model's
    options with its tolerance.
    """
    key = "accuracy"
    t = r.table(tbl, key, ("load", "G", "stresses"))
    if t is None:
        return Accuracy(), beam_model
    lo, hi = TOLERANCE_RANGE
    values: dict[str, float | None] = {}
    estimated: dict[str, bool] = {}
    for k in ("load", "G", "stresses"):
        v = t.get(k)
        if v is False and k != "load":
            values[k], estimated[k] = None, False
            continue
        if isinstance(v, bool):
            r.fail(f"{key}.{k}", "expected a relative tolerance (a number)"
                   + (" or false (not estimated)" if k != "load" else
                      ": the load and probes are the path's answer, always estimated"))
            values[k], estimated[k] = None, True
            continue
        x = r.number(t, k, key, default=None, positive=True)
        if x is not None and not lo <= x <= hi:
            r.fail(f"{key}.{k}", f"must be between {lo:g} and {hi:g} (a relative error), "
                   f"got {x:g}")
            x = None
        values[k], estimated[k] = x, True
    if values["load"] is not None and beam_tolerance_given:
        r.fail(f"{key}.load", "the beam's tolerance of the load and probes is given twice (also "
               "[beam_model] tolerance): keep this one")
    elif values["load"] is not None:
        beam_model = dataclasses.replace(beam_model, tolerance=values["load"])
    return Accuracy(load=values["load"], G=values["G"], stresses=values["stresses"],
                    estimate_G=estimated["G"], estimate_stresses=estimated["stresses"]), beam_model
