"""``auto``'s estimate under load control: the end load is the target, the probes are the answer.

Under load control every pass ends at the same load, so the change of the end load between
passes is zero whatever the error; the estimate is then the probes' change (relative to the
largest probe). Reference values: states built by hand (:func:`end_change`), and a real run
whose estimate must be neither zero nor missing once a raise was made.
"""

import dataclasses
from pathlib import Path

import pytest

from sandwich.beam import run
from sandwich.beam.core_controller import end_change
from sandwich.scene import Analysis
from sandwich.scene_file import load_scene
from sandwich.solver import PathState

FIG4 = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig4-bonded-3pb.toml"


def _state(lam, probes):
    return PathState(3, None, lam, 4, probes, None)


def test_at_a_load_target_the_probes_change_is_the_estimate():
    a = Analysis(kind="nonlinear", control="load", until_load_factor=1500.0)
    now = _state(1500.0, {"w_top": -8.0, "w_bottom": -0.01})
    before = {"w_top": -7.9, "w_bottom": -0.02}
    # the largest change (0.1 on w_top) over the largest magnitude (8.0), not 0.01 / 0.01
    assert end_change(a, now, 1500.0, before) == pytest.approx(0.1 / 8.0)


def test_at_a_probe_target_the_end_load_change_is_the_estimate():
    a = Analysis(kind="nonlinear", control="arc-length", until_probe="w_top", until_value=-8.0)
    now = _state(1200.0, {"w_top": -8.0, "w_bottom": -7.0})
    assert end_change(a, now, 1150.0, {"w_top": -8.0, "w_bottom": -6.0}) == pytest.approx(
        50.0 / 1200.0)


def test_nothing_moved_is_not_measured_rather_than_zero():
    a = Analysis(kind="nonlinear", control="load", until_load_factor=10.0)
    assert end_change(a, _state(10.0, {"w": 0.0}), 10.0, {"w": 0.0}) is None


def test_a_load_controlled_auto_run_reports_a_nonzero_estimate():
    scene = load_scene(FIG4)
    scene = dataclasses.replace(
        scene, analysis=dataclasses.replace(scene.analysis, control="load", until_probe=None,
                                            until_value=None, until_load_factor=1500.0),
        beam_model=dataclasses.replace(scene.beam_model, elements=80))
    sol = run(scene).solution
    assert sol.converged
    core = sol.extra["core"]
    assert len(core["passes"]) > 1  # a raise was made and checked
    assert core["estimated_error"] is not None and core["estimated_error"] > 0.0
