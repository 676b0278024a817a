"""The numbers a study reports per case, read off one :class:`~sandwich.results.Solution`.

Loads are load factors λ (they multiply every load's force; N for a scene whose loads sum to 1 N),
deflections are the scene's ``until`` probe (the first probe if it has none), in mm.

- ``initial_stiffness``: λ₁ |ΣF| / |w₁ − w₀| over the first converged step (N/mm);
- ``first_limit_load`` / ``first_limit_kind`` / ``first_limit_w``: the first limit point or
  bifurcation the model reports along the path (empty when none before the end);
- ``load_at_until``: λ at the end of a path that reached its target (empty otherwise);
- ``capacity``: ``first_limit_load`` if there is one, else ``load_at_until`` (a lower bound of the
  buckling load: the panel did not buckle before the target); in a scene that grows its
  debonds, the ``residual_strength``;
- ``first_growth_load`` / ``residual_strength``: of a scene that grows its debonds
  (:mod:`sandwich.growth.envelope`; empty otherwise, and the residual strength empty where no
  debond grew);
- ``peak_sigma_zz`` (either interface) and ``peak_tau_core`` at the last profile (the last
  converged step), raw and averaged over 5 mm (:func:`sandwich.results.peaks.peak`, the window
  the
  comparisons use: the raw peak at a debond tip grows under mesh refinement, the average converges);
- ``contact_length``: length of x (mm) where either face presses on the core (contact pressure
  > 0) at the last profile, for the models that report it: the trapezoid of the contact flag
  over the profile's samples (within one sample spacing);
- ``core_crushed_load``: λ at the first state whose core lost ellipticity (the 2D model's
  crushing diagnostic, ``sandwich/plane2d/core_crushing.py``; empty where the core did not crush,
  and
  for the beam, whose core is a through-thickness polynomial and does not report it);
- ``steps``, ``converged``, ``stop_reason``, ``solve_seconds``.
"""

from __future__ import annotations

import math

import numpy as np

from sandwich.compare.paths import crushed_state
from sandwich.results import Solution
from sandwich.results.peaks import peak
from sandwich.scene import Scene

PEAK_WINDOW = 5.0  # mm


def _probe(scene: Scene, sol: Solution) -> str | None:
    a = scene.analysis
    if a.until_probe is not None:
        return a.until_probe
    return scene.probes[0].name if scene.probes else None


def _finite(v: float | None) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def _signed_peak(sol: Solution, columns: tuple[str, ...], window: float) -> float | None:
    if not sol.profiles:
        return None
    prof = sol.profiles[-1]
    best = None
    for col in columns:
        if col not in prof.columns:
            continue
        try:
            v, _ = peak(prof, col, window)
        except ValueError:  # a profile shorter than the window
            continue
        if best is None or abs(v) > abs(best):
            best = v
    return _finite(best)


def contact_length(sol: Solution) -> float | None:
    """Length (mm) of x where a face presses on the core at the last profile (None: not known)."""
    if not sol.profiles:
        return None
    cols = sol.profiles[-1].columns
    press = [c for c in ("p_contact_top", "p_contact_bottom") if c in cols]
    if not press or "x" not in cols:
        return None
    x = np.asarray(cols["x"], dtype=float)
    order = np.argsort(x, kind="stable")
    x = x[order]
    total = 0.0
    for c in press:
        on = (np.abs(np.asarray(cols[c], dtype=float)[order]) > 0.0).astype(float)
        total += float(np.sum(0.5 * (on[1:] + on[:-1]) * np.diff(x)))  # trapezoid of the flag
    return total


def case_metrics(scene: Scene, sol: Solution) -> dict[str, object]:
    """The study's row of one solved case (see the module docstring)."""
    force = sum(abs(ld.force) for ld in scene.loads)
    probe = _probe(scene, sol)
    out: dict[str, object] = {"converged": bool(sol.converged), "steps": max(len(sol.history) - 1,
                                                                                0),
                              "stop_reason": " ".join(sol.message.split()),
                              "warnings": list(sol.warnings)}
    hist = sol.history
    k0 = None
    if probe is not None and len(hist) >= 2 and probe in hist[1].probes:
        dw = abs(hist[1].probes[probe] - hist[0].probes.get(probe, 0.0))
        if dw > 0:
            k0 = abs(hist[1].load_factor - hist[0].load_factor) * force / dw
    out["initial_stiffness"] = _finite(k0)
    limits = sorted(sol.limit_points, key=lambda lp: lp.step)
    first = limits[0] if limits else None
    out["first_limit_kind"] = first.kind if first else ""
    out["first_limit_load"] = _finite(first.load_factor) if first else None
    out["first_limit_w"] = (_finite(first.probes.get(probe)) if first and probe else None)
    out["load_at_until"] = _finite(sol.final_load_factor) if sol.converged and hist else None
    out["capacity"] = out["first_limit_load"] if first else out["load_at_until"]
    growth = sol.extra.get("debond_growth")
    grown = isinstance(growth, dict) and "method" in growth
    out["first_growth_load"] = _finite(growth["first_growth_load"]) if grown else None
    out["residual_strength"] = _finite(growth["residual_strength"]) if grown else None
    if grown:  # residual strength: what the damaged panel carries
        out["capacity"] = out["residual_strength"]
        if "tips" not in growth:  # crack-length control: the history is the envelope, no path
            out["load_at_until"] = None
    out["peak_sigma_zz"] = _signed_peak(sol, ("sigma_zz_top", "sigma_zz_bottom"), 0.0)
    out["peak_sigma_zz_5mm"] = _signed_peak(sol, ("sigma_zz_top", "sigma_zz_bottom"), PEAK_WINDOW)
    out["peak_tau_core"] = _signed_peak(sol, ("tau_core",), 0.0)
    out["peak_tau_core_5mm"] = _signed_peak(sol, ("tau_core",), PEAK_WINDOW)
    out["contact_length"] = contact_length(sol)
    crushed = crushed_state(sol)
    out["core_crushed_load"] = _finite(crushed.load_factor) if crushed else None
    out["solve_seconds"] = round(float(sol.wall_seconds), 3)
    return out
