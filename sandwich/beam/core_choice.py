"""The core levels a run starts from: given, from ``[beam_model]``, or chosen by ``"auto"``.

``"auto"`` chooses on the linear step (:func:`sandwich.beam.core_levels.auto_levels` with
:func:`sandwich.beam.linear_step.active_set_solution`); along a nonlinear path the choice is
re-checked by :mod:`sandwich.beam.core_controller`. :func:`linear_responses` gives the linear
step's response at several uniform levels (the studies' error indicator).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from sandwich.beam import linear_step
from sandwich.beam.build import beam_mesh, build_model, scene_gauss_orders, scene_model_options
from sandwich.beam.core_levels import LevelChoice, auto_levels, zone_levels
from sandwich.beam.fracture import beam_tips, uniform_tip_levels
from sandwich.beam.model import BeamModel
from sandwich.scene import Scene


def choose_core_levels(scene: object, elements: int | None, options: dict) -> LevelChoice:
    """The core level of every element: given, from ``[beam_model]``, or chosen by "auto".

    ``options["core_level"]`` (an integer or one level per element) overrides the scene. Else
    ``[beam_model] core`` is a level or ``"auto"`` (:func:`~sandwich.beam.core_levels.auto_levels`
    on the linear step against ``tolerance``, up to ``max_core_level``); ``core_zones`` raise the
    levels over their stretches in both cases.
    """
    bm = scene.beam_model
    n = elements if elements is not None else getattr(bm, "elements", 240)
    mesh_options = {k: options[k] for k in ("grading", "growth", "size_ratio") if k in options}
    mesh = beam_mesh(scene, n, **mesh_options)
    given = options.get("core_level")
    if given is not None:
        levels = np.broadcast_to(np.asarray(given, dtype=int), (mesh.n_elements,)).copy()
        return LevelChoice(levels=levels, how="explicit")
    core = getattr(bm, "core", 1)
    zones = tuple(getattr(bm, "core_zones", ()))
    if core != "auto":
        return LevelChoice(levels=zone_levels(mesh, int(core), zones), how="explicit")
    gauss = scene_gauss_orders(scene)
    floor = zone_levels(mesh, 1, zones)

    built: dict[bytes, BeamModel] = {}  # the first level choice is the floor's model again

    def build(levels: np.ndarray) -> BeamModel:
        levels = np.maximum(levels, floor)
        key = levels.astype(np.int64).tobytes()
        if key not in built:
            built[key] = build_model(scene, elements=n, gauss=gauss,
                                     **{**options, "core_level": levels})
        return built[key]

    base = build(floor)
    sign, first = _load_sign(base, scene)
    settled: list[list[np.ndarray]] = []  # the last linear solve's active set
    solved: dict[int, np.ndarray] = {}
    if first is not None:  # the floor at λ = sign, from every pair open: solved for the sign
        solved[id(base)], active = first
        settled.append(active)

    def solve_linear(model: BeamModel) -> np.ndarray:
        if id(model) not in solved:
            u, _, active = linear_step.active_set_solution(model, sign,
                                                           settled[-1] if settled else None)
            settled[:] = [active]
            solved[id(model)] = u
        return solved[id(model)]

    choice = auto_levels(build, solve_linear, mesh.n_elements,
                         float(getattr(bm, "tolerance", 0.01)),
                         int(getattr(bm, "max_core_level", 3)), probe=scene.analysis.until_probe)
    # no level change next to a debond tip: it biases G (docs/fracture.md)
    choice.levels = uniform_tip_levels(base, beam_tips(scene, base),
                                       np.maximum(choice.levels, floor))
    return choice


def _load_sign(
    model: BeamModel, scene: object
) -> tuple[float, tuple[np.ndarray, list[np.ndarray]] | None]:
    """Sign of the load factor the analysis heads for (unilateral contact is not odd in λ).

    Also returns the linear solution at λ = sign and its active set where finding the sign
    solved it (an until probe), else None: the level choice's first solve is that one.
    """
    a = scene.analysis
    if a.until_probe is not None:
        try:
            sign, u1, _, active = linear_step.toward_target(model, a.until_probe, a.until_value)
            return sign, (u1, active)
        except ValueError:  # the path follower says so in its own words
            return 1.0, None
    if a.until_load_factor is not None and a.until_load_factor < 0:
        return -1.0, None
    return 1.0, None


def linear_responses(scene: Scene, cores: Sequence[int]) -> list[float]:
    """The linear step's response at each uniform core level of ``cores``, in that order.

    The model is the one :func:`sandwich.beam.solve.run` builds for ``scene`` with
    ``[beam_model] core`` set to the level (its ``core_zones`` kept). The response is the until
    probe's value c·u at the unit load factor that moves it towards its target (the linear
    stiffness, as the linear analysis scales it), else the compliance fᵀu at λ = ±1 (the sign
    of ``until_load_factor``). Each unilateral active-set solve starts from the set the one
    before settled on: the iteration has one fixed point
    (:func:`~sandwich.beam.linear_step.active_set_solution`), so each level's set is the one it
    finds from every pair open — knock-down cases of fig. 5 at level 3: 7, 6 and 4 passes
    instead of 7, 14 and 18 — and its solution the same to round-off (the envelope's order
    depends on the first matrix a model factorises).
    """
    a = scene.analysis
    options = scene_model_options(scene)
    out: list[float] = []
    settled = None
    for core in cores:
        s = dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model,
                                                                      core=int(core)))
        levels = choose_core_levels(s, None, options).levels
        model = build_model(s, gauss=scene_gauss_orders(s), **{**options, "core_level": levels})
        if a.until_probe is not None:
            _, u1, _, settled = linear_step.toward_target(model, a.until_probe, a.until_value,
                                                          settled)
            out.append(float(model.probe_vector(a.until_probe) @ u1))
        else:
            sign = -1.0 if a.until_load_factor is not None and a.until_load_factor < 0 else 1.0
            u1, _, settled = linear_step.active_set_solution(model, sign, settled)
            out.append(float(model.f_ref @ u1))
    return out
