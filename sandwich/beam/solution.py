"""The beam's result in the project's common form: :func:`beam_solution`.

Per converged state the history's record (probes, contact, energy release rates at the debond
tips), the profiles and the ParaView field frames of the chosen states, and the summary entries.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.build import scene_gauss_orders
from sandwich.beam.cohesive import GROWTH_COLUMNS
from sandwich.beam.contact_summary import CONTACT_COLUMNS, contact_columns
from sandwich.beam.fields import profile_columns, section_fields
from sandwich.beam.fracture import beam_tips, column_names, release_columns
from sandwich.beam.model import BeamModel
from sandwich.results import FieldFrame, LimitPoint, Profile, Solution, StepRecord
from sandwich.solver import PathState


def _field_frame(model: BeamModel, state: PathState, nonlinear: bool) -> FieldFrame:
    """Faces and core of ``state`` on one quad grid (``section_fields``) as a ParaView frame.

    Point data: σ_x, σ_z, τ, von Mises (MPa, 2nd Piola-Kirchhoff); cell data: ``region``
    (0 core, 1 top face, 2 bottom face) and ``core_level`` (0 on faces). Points are reference
    (x, z), displacement (u, w) in mm.
    """
    f = section_fields(model, state.u, nonlinear=nonlinear)
    return FieldFrame(
        step=state.step, load_factor=state.load_factor, points=f.points, cells=f.cells,
        displacement=f.displacement,
        point_data={"sigma_x": f.sigma_x, "sigma_z": f.sigma_z, "tau": f.tau,
                    "von_mises": f.von_mises},
        cell_data={"region": f.region.astype(float), "core_level": f.core_level.astype(float)},
    )


def beam_solution(
    scene: object, model: BeamModel, states: list[PathState], nonlinear: bool,
    converged: bool, message: str, limit_points: list[LimitPoint],
) -> Solution:
    """The common :class:`~sandwich.results.Solution` of ``states`` (model "beam").

    The history's contact and energy release rate columns are the path's where it kept them
    (:meth:`~sandwich.beam.model.BeamModel.state_columns`), else evaluated (a linear analysis
    has no contact columns: zeros); profiles and field frames every ``profile_every`` steps and
    at the last state; a penetration beyond the model's bound is one of its warnings.
    """
    history = []
    max_pen = max_slide = 0.0
    tips = beam_tips(scene, model)  # energy release rate at every debond tip (N/mm)
    names = {n for t in tips for n in column_names(t.debond, t.tip)}
    for s in states:
        # the path's columns of this state (model.state_columns), else evaluated
        contact = ({n: s.extra[n] for n in CONTACT_COLUMNS} if set(CONTACT_COLUMNS) <=
                   s.extra.keys() else _contact_columns(model, s.u, nonlinear))
        max_pen = max(max_pen, contact["max_penetration"])
        max_slide = max(max_slide, contact["max_sliding"])
        extra = {**contact,
                 **({n: s.extra[n] for n in names} if names <= s.extra.keys()
                    else release_columns(model, s.u, tips)),
                 **{n: v for n, v in s.extra.items() if n.startswith(GROWTH_COLUMNS)}}
        history.append(StepRecord(step=s.step, load_factor=s.load_factor, probes=dict(s.probes),
                                  iterations=s.iterations, extra=extra))
    every = int(getattr(getattr(scene, "beam_model", None), "profile_every", 0) or 0)
    chosen = [s for s in states if every and s.step % every == 0 and s is not states[-1]]
    chosen.append(states[-1])
    profiles = [Profile(step=s.step, columns=profile_columns(model, s.u, nonlinear))
                for s in chosen]
    fields = [_field_frame(model, s, nonlinear) for s in chosen]
    bound = model.penetration_bound()
    warnings = [f"contact penetration {max_pen:.3g} mm exceeds {bound:.3g} mm (raise "
                "beam_model.contact_penalty)"] if max_pen > bound else []
    return Solution(
        model="beam", scene=scene.name, history=history, profiles=profiles, converged=converged,
        message=message, limit_points=limit_points, wall_seconds=0.0, dofs=model.size,
        fields=fields, warnings=warnings,
        extra={
            "elements": model.mesh.n_elements,
            "nodes": model.mesh.n_nodes,
            "analysis": "nonlinear" if nonlinear else "linear",
            **{f"gauss_{layer}_{axis}": n for layer, orders in scene_gauss_orders(scene).items()
               for axis, n in zip(("x", "z"), orders, strict=True)},
            "contact_pairs": int(sum(p.size for p in model.pairs)),
            "contact_penalty": model.penalty,
            "max_penetration": max_pen,
            "penetration_bound": bound,
            "max_sliding": max_slide,
            "total_newton_iterations": int(sum(s.iterations for s in states)),
        },
    )


def _contact_columns(model: BeamModel, u: np.ndarray, nonlinear: bool) -> dict[str, float]:
    """A state's contact history columns, evaluated (a linear analysis: none, zeros)."""
    return contact_columns(model.contact_summary(u) if nonlinear else {})


def growth_summary(scene: object, solution: Solution, model: BeamModel) -> dict[str, object]:
    """Summary entry of the debond growth: a cohesive path's, else the criterion's onsets.

    Debonds grown by a cohesive law: :func:`sandwich.growth.cohesive_summary`, with a warning
    (into ``solution.warnings``) where a tip reached its span's end or where the longest
    process zone spans fewer than ``PROCESS_ZONE_ELEMENTS`` elements (the law's tractions and
    the growth load are then mesh-dependent: more elements, or a lower strength, would
    resolve it). Else the first step where G reaches the toughness (debonds with one).
    """
    from sandwich.fracture import growth_onset
    from sandwich.growth import cohesive_growing, cohesive_summary
    from sandwich.growth.cohesive import process_zone_warnings

    if cohesive_growing(scene):
        spans = [p for p in model.pairs if p.cohesive is not None]
        size = max((float(np.max(np.diff(model.mesh.x[p.nodes]), initial=0.0)) for p in spans),
                   default=0.0)
        out, warnings = cohesive_summary(scene, solution.history, size)
        warnings += process_zone_warnings(out, size, "more [beam_model] elements")
        solution.warnings.extend(warnings)
        return {"debond_growth": out}
    onset = growth_onset(scene, solution.history)
    return {"debond_growth": onset} if onset else {}
