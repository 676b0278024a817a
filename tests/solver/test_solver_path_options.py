"""A scene's ``[analysis]`` reaches the path follower whole: ``PathOptions.from_analysis`` takes
every field of ``sandwich.scene.Analysis`` that is a path option, read from the dataclass itself
(reference: the dataclass's fields and an Analysis whose every value differs from the default)."""

import dataclasses

from sandwich.scene import Analysis
from sandwich.solver import PathOptions
from sandwich.solver.path.options import ANALYSIS_FIELDS


def test_every_analysis_field_but_its_kind_is_a_path_option():
    assert set(ANALYSIS_FIELDS) == {f.name for f in dataclasses.fields(Analysis)} - {"kind"}


def test_each_analysis_value_is_taken_and_a_models_overrides_go_on_top():
    analysis = Analysis(control="arc-length", until_probe="w", until_value=-3.0, max_steps=7,
                        initial_increment=0.5, min_increment=0.01, max_increment=2.0, tol=1e-9,
                        max_iterations=12, locate_critical_points=True)
    defaults = Analysis()
    changed = {n for n in ANALYSIS_FIELDS if getattr(analysis, n) != getattr(defaults, n)}
    assert changed == set(ANALYSIS_FIELDS) - {"until_load_factor"}  # None: both ways
    options = PathOptions.from_analysis(analysis, tol=1e-7, desired_iterations=4)
    for name in set(ANALYSIS_FIELDS) - {"tol"}:
        assert getattr(options, name) == getattr(analysis, name), name
    assert options.tol == 1e-7 and options.desired_iterations == 4
