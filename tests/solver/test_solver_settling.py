"""The step-size controller's settling allowance (the beam's ``[beam_model] settling_allowance``).

A corrector whose increment has converged may keep iterating to settle its residual (the beam's
contact pairs in the penalty law's knee) without moving the state; with an allowance k the
controller weighs such a step by the iterations its increment test took plus k, until the
path's first failed corrector and only where the load curve's last two steps turn by less than
``SETTLING_BEND``; a step so grown whose secant turns from its predictor by more is cut.
Checked: the rule itself (a follower's ``_weighed_iterations``) and both angles (closed-form
angles of synthetic states), the option's validation, that it is on (k = 2) for the beam by
default and not an ``[analysis]`` option, and on the beam (fig. 9 d10, the paper's core, 60
elements) that the path takes fewer steps and ends at the same equilibrium as with the plain
controller (the reference: the same scene with the allowance off).
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from sandwich.scene_file import load_scene
from sandwich.solver import PathOptions
from sandwich.solver.path import HALF_REACH, SETTLING_BEND, PathFollower, PathState, Trial

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _state(w, lam):
    return PathState(0, None, lam, 0, {"w": w}, None, 0)


def _follower(allowance, failed=False, turn=0.0):
    """A follower whose last two steps (of the load curve w ↦ λ, both scaled to 1 at the
    target) turn by ``turn`` radians; the rule reads only these, the options and the flag."""
    f = PathFollower.__new__(PathFollower)
    f.opt = PathOptions(settling_allowance=allowance, until_probe="w", until_value=-2.0)
    f.failed_once = failed
    f.lam_est, f.curve_probe = 10.0, ("w", 2.0)
    a = math.radians(30.0)  # the first step's direction in the scaled plane
    f.states = [_state(0.0, 0.0), _state(-0.2 * math.cos(a), 1.0 * math.sin(a))]
    f.states.append(_state(f.states[1].probes["w"] - 0.2 * math.cos(a + turn),
                           f.states[1].load_factor + 1.0 * math.sin(a + turn)))
    return f


def _trial(iterations, increment_iterations):
    return Trial(None, 0.0, iterations, None, 0, increment_iterations)


def test_the_controller_weighs_a_step_by_its_increment_iterations_plus_the_allowance():
    assert _follower(2).weighed_iterations(_trial(8, 1)) == 3
    assert _follower(2).weighed_iterations(_trial(4, 3)) == 4  # never more than all of them
    assert _follower(0).weighed_iterations(_trial(8, 5)) == 5


def test_without_the_allowance_or_after_a_failed_corrector_every_iteration_counts():
    assert _follower(None).weighed_iterations(_trial(8, 1)) == 8
    assert _follower(2, failed=True).weighed_iterations(_trial(8, 1)) == 8
    assert _follower(2).weighed_iterations(_trial(8, None)) == 8


def test_where_the_load_curve_bends_every_iteration_counts():
    """The angle between the last two steps in the scaled (w, λ) plane, either way round."""
    for turn, allowed in ((0.0, True), (0.9 * SETTLING_BEND, True), (-0.9 * SETTLING_BEND, True),
                          (1.1 * SETTLING_BEND, False), (-1.1 * SETTLING_BEND, False),
                          (math.pi / 2, False)):
        assert _follower(2, turn=turn).weighed_iterations(_trial(8, 1)) == (3 if allowed else 8)
    f = _follower(2)
    f.states = f.states[:2]  # one step: no bend known yet
    assert f.weighed_iterations(_trial(8, 1)) == 8
    f = _follower(2)
    f.curve_probe = (None, 0.0)  # no probe to draw the curve with
    assert f.weighed_iterations(_trial(8, 1)) == 8



def test_a_grown_step_is_cut_where_its_secant_turns_from_its_predictor():
    """Predictor along the tangent (dw/dλ = −0.04, i.e. 45° in the scaled plane: w / 2, λ / 10);
    the converged step's secant turned by ±0.9 or ±1.1 × SETTLING_BEND, or reversed."""
    f = _follower(2)
    f.c, f.dot = {"w": np.ones(1)}, np.dot
    t = np.array([-0.2])  # scaled (c·t / 2, 1 / 10) = (−0.1, 0.1): the direction 135°
    last = _state(0.0, 0.0)
    for turn, bent in ((0.0, False), (0.9, False), (-0.9, False), (1.1, True), (-1.1, True)):
        a = math.radians(135.0) + turn * SETTLING_BEND  # the predictor's direction, turned
        trial = Trial(np.array([2.0 * 0.1 * math.cos(a)]), 10.0 * 0.1 * math.sin(a), 3, None)
        assert f.bends_within(last, trial, t) is bent, turn
    back = Trial(np.array([0.1]), -0.5, 3, None)  # straight back along the tangent: no bend
    assert f.bends_within(last, back, t) is False
    f.curve_probe = (None, 0.0)
    assert f.bends_within(last, Trial(np.array([1.0]), 0.0, 3, None), t) is False


def test_a_negative_allowance_is_refused():
    with pytest.raises(ValueError, match="settling_allowance"):
        PathOptions(settling_allowance=-1, until_load_factor=1.0)


def test_the_scene_key_is_two_by_default_and_not_an_analysis_option():
    scene = load_scene(SCENES / "paper-fig5-top-debond-40-load-top.toml")
    assert scene.beam_model.settling_allowance == 2
    assert PathOptions.from_analysis(scene.analysis).settling_allowance is None


def test_the_beam_path_takes_fewer_steps_to_the_same_end_state():
    """fig. 9 d10, the paper's core at 60 elements: a nearly linear path whose correctors settle
    contact pairs after their increment has converged."""
    from sandwich.beam import run
    scene = load_scene(SCENES / "paper-fig9-clamped-d10.toml")
    scene = dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, core=1, core_zones=(), elements=60, settling_allowance=None))
    plain = run(scene).solution
    settled = run(dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, settling_allowance=2))).solution
    assert plain.converged and settled.converged
    assert len(settled.history) < 0.8 * len(plain.history)
    assert settled.final_load_factor == pytest.approx(plain.final_load_factor, rel=1e-8)


def test_an_allowance_of_max_iterations_is_the_controller_without_it():
    """docs/scenes.md: a value at or above [analysis] max_iterations turns it off — the same
    states as without the allowance (fig. 9 d10, the paper's core, 60 elements)."""
    from sandwich.beam import run
    scene = load_scene(SCENES / "paper-fig9-clamped-d10.toml")
    scene = dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, core=1, core_zones=(), elements=60, settling_allowance=None))
    plain = run(scene).solution
    off = run(dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, settling_allowance=scene.analysis.max_iterations))).solution
    assert [s.load_factor for s in off.history] == [s.load_factor for s in plain.history]


def _bent_follower(control="arc-length"):
    """A follower at the retry's state M of a step cut as BENT from ``start``, with the bent
    step's converged state X kept: the path w ↦ λ with M at (−1, 1) (ψ = 1, one DOF u = w)."""
    f = PathFollower.__new__(PathFollower)
    f.opt = PathOptions(control=control, settling_allowance=2, until_probe="w",
                        until_value=-10.0)
    f.c, f.dot, f.psi = {"w": np.ones(1)}, np.dot, 1.0
    f.states = [PathState(0, np.zeros(1), 0.0, 0, {"w": 0.0}, 0),
                PathState(1, np.array([-1.0]), 1.0, 5, {"w": -1.0}, 0, 1)]
    return f


def _kept(f, w, lam, start_step=0):
    x = Trial(np.array([w]), lam, 9, None)
    f.bent = (start_step, x)
    return x


def test_the_bent_steps_state_is_the_retrys_next_state_within_the_controllers_increment():
    """X is taken when the step M → X is at most HALF_REACH × the increment h the controller
    asks for (in the control's units: the arc ‖(Δu, ψΔλ)‖, Δλ under load control), ahead of M
    (Δu·(M − start) ≥ 0) and with no target between; once only, and only right after the
    retry from the bent step's start."""
    f = _bent_follower()
    h = 1.0
    x = _kept(f, -2.0, 1.5)  # |X − M| = √1.25 = 1.118 h
    assert f.bent_half(f.states[-1], h) is x
    assert f.bent_half(f.states[-1], h) is None  # taken once
    far = math.sqrt(HALF_REACH**2 - 1.0)  # Δλ putting |X − M| at HALF_REACH h
    _kept(f, -2.0, 1.0 + 1.001 * far)
    assert f.bent_half(f.states[-1], h) is None
    _kept(f, -2.0, 1.0 + 0.999 * far)
    assert f.bent_half(f.states[-1], h) is not None
    _kept(f, -0.5, 1.5)  # Δu = +0.5 against the retry's −1: behind M
    assert f.bent_half(f.states[-1], h) is None
    _kept(f, -2.0, 1.5, start_step=1)  # kept from another start than the retry's
    assert f.bent_half(f.states[-1], h) is None
    f.opt = PathOptions(control="arc-length", settling_allowance=2, until_probe="w",
                        until_value=-1.5)
    _kept(f, -2.0, 1.5)  # the target w = −1.5 lies between M and X: the target logic's
    assert f.bent_half(f.states[-1], h) is None
    f = _bent_follower(control="load")  # the increment is Δλ: 1.2 ≤ 1.25 × 1, 1.3 is not
    _kept(f, -5.0, 2.2)
    assert f.bent_half(f.states[-1], h) is not None
    _kept(f, -5.0, 2.3)
    assert f.bent_half(f.states[-1], h) is None


def test_fig5_keeps_its_bent_steps_state_and_ends_where_the_path_without_it_ends(monkeypatch):
    """fig. 5 at the paper's core (240 elements): the step grown across the debonded face's
    buckling is cut as BENT; with its state kept after the retry the path takes that state as
    a step, spends fewer corrector iterations, and ends at the equilibrium the path without
    the kept state (HALF_REACH = 0: never taken) ends at."""
    from sandwich.beam import run
    from sandwich.solver.path import attempts, step_size
    scene = load_scene(SCENES / "paper-fig5-top-debond-40-load-top.toml")
    scene = dataclasses.replace(scene, beam_model=dataclasses.replace(
        scene.beam_model, core=1, core_zones=()))
    spent, taken = [0], []
    correct, bent_half = attempts.newton_correct, PathFollower.bent_half

    def counted(*args, **kwargs):
        res = correct(*args, **kwargs)
        spent[-1] += res.iterations
        return res

    def recorded(self, last, h):
        kept = bent_half(self, last, h)
        taken.append(kept)
        return kept

    monkeypatch.setattr(attempts, "newton_correct", counted)
    monkeypatch.setattr(PathFollower, "bent_half", recorded)
    kept = run(scene).solution
    monkeypatch.setattr(step_size, "HALF_REACH", 0.0)
    spent.append(0)
    plain = run(scene).solution
    assert kept.converged and plain.converged
    states = [t for t in taken if t is not None]
    assert len(states) == 1  # fig. 5's one bent step, taken in the first run only
    assert states[0].load_factor in [s.load_factor for s in kept.history]
    assert spent[0] < spent[1]
    assert kept.final_load_factor == pytest.approx(plain.final_load_factor, rel=1e-9)
