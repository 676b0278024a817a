"""The paper's high-order sandwich beam element with debonds and contact (NumPy/SciPy only).

Public API
----------
solve(scene, progress=None) -> sandwich.results.Solution
run(scene, progress=None, elements=None, auto=None) -> BeamRun (solution, model, converged
    states); ``auto``: AutoSettings (``one_pass=False``: auto's reruns instead of one pass)
build_model(scene, elements=None, gauss=None, contact_penalty=None) -> BeamModel
scene_model_options(scene) -> the build_model options a scene's [beam_model] sets
linear_solution(model, load_factor) -> the small-displacement step with unilateral contact
profile_columns(model, u, nonlinear=True) / section_fields(model, u) / layer_grid(...)
"""

from sandwich.beam.build import build_model, scene_model_options
from sandwich.beam.core_controller import AutoSettings
from sandwich.beam.dofs import DOF_NAMES, DOF_TABLE
from sandwich.beam.fields import SectionFields, layer_grid, profile_columns, section_fields
from sandwich.beam.linear_step import linear_solution
from sandwich.beam.model import BeamModel
from sandwich.beam.solve import BeamRun, run, solve

__all__ = ["DOF_NAMES", "DOF_TABLE", "AutoSettings", "BeamModel", "BeamRun", "SectionFields",
           "build_model", "layer_grid", "linear_solution", "profile_columns", "run",
           "scene_model_options", "section_fields", "solve"]
