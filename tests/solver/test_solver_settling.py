"""The step-size controller's settling allowance (the beam's ``[beam_model] settling_allowance``).

A corrector whose increment has converged may keep iterating to settle its residual (the beam's
contact pairs in the penalty law's knee) without moving the state; with an allowance k the
controller weighs such a step by the iterations its increment test took plus k, until the
path's first failed corrector. Checked: the rule itself (a follower's ``_weighed_iterations``),
the option's validation, that it is off by default, and on the beam (fig. 9 d10, the paper's
core, 60 elements) that the path takes fewer steps and ends at the same equilibrium as with the
plain controller (the reference: the same scene with the key off).
"""

import dataclasses
from pathlib import Path

import pytest

from sandwich.scene_file import load_scene
from sandwich.solver import PathOptions
from sandwich.solver.path import _Follower, _Trial

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _follower(allowance, failed=False):
    f = _Follower.__new__(_Follower)  # the rule reads only the options and the failure flag
    f.opt = PathOptions(settling_allowance=allowance, until_load_factor=1.0)
    f.failed_once = failed
    return f


def _trial(iterations, increment_iterations):
    return _Trial(None, 0.0, iterations, None, 0, increment_iterations)


def test_the_controller_weighs_a_step_by_its_increment_iterations_plus_the_allowance():
    assert _follower(2)._weighed_iterations(_trial(8, 1)) == 3
    assert _follower(2)._weighed_iterations(_trial(4, 3)) == 4  # never more than all of them
    assert _follower(0)._weighed_iterations(_trial(8, 5)) == 5


def test_without_the_allowance_or_after_a_failed_corrector_every_iteration_counts():
    assert _follower(None)._weighed_iterations(_trial(8, 1)) == 8
    assert _follower(2, failed=True)._weighed_iterations(_trial(8, 1)) == 8
    assert _follower(2)._weighed_iterations(_trial(8, None)) == 8


def test_a_negative_allowance_is_refused():
    with pytest.raises(ValueError, match="settling_allowance"):
        PathOptions(settling_allowance=-1, until_load_factor=1.0)


def test_the_scene_key_is_off_by_default_and_not_an_analysis_option():
    scene = load_scene(SCENES / "paper-fig5-top-debond-40-load-top.toml")
    assert scene.beam_model.settling_allowance is None
    assert PathOptions.from_analysis(scene.analysis).settling_allowance is None


def test_the_beam_path_takes_fewer_steps_to_the_same_end_state():
    """fig. 9 d10, the paper's core at 60 elements: a nearly linear path whose correctors settle
    contact pairs after their increment has converged."""
    from beam_element import run
    scene = load_scene(SCENES / "paper-fig9-clamped-d10.toml")
    scene = dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, core=1, core_zones=(), elements=60, settling_allowance=None))
    plain = run(scene).solution
    settled = run(dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, settling_allowance=2))).solution
    assert plain.converged and settled.converged
    assert len(settled.history) < 0.8 * len(plain.history)
    assert settled.final_load_factor == pytest.approx(plain.final_load_factor, rel=1e-8)
