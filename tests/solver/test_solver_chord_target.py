"""A crossed stopping target hit by one corrector from the chord (``PathFollower.chord_target``).

When a step overshoots ``until``, the follower first runs one corrector under control of the
crossed quantity from the point where the chord last → trial meets the target, and only if
that fails (or the step passed a critical point) shortens the arc by regula falsi. Toy: the
two-DOF von Mises truss behind a spring (closed-form path: λ P = f_bar(w1), w2 = w1 + λP/k).
References: the closed form (end state), the regula-falsi route of the same follower (the
same end state to the target tolerance, more correctors), and the inertia of the tangent.
"""

import math

import numpy as np
import pytest
from solver_toys import VonMisesTruss

import sandwich.solver.path.attempts as attempts_module
from sandwich.solver import PathOptions, follow_path
from sandwich.solver.path import PathFollower, PathState, Trial

TOL = 1e-10


def _closed_form(truss: VonMisesTruss, w2: float) -> tuple[float, float]:
    """(λ, w1) of the equilibrium with the loaded DOF at ``w2``, before the load maximum."""
    from scipy.optimize import brentq

    w_max, _ = truss.limit_points()[0]
    w1 = brentq(lambda w: w + truss.bar_force(w) / truss.ks - w2, 0.0, w_max, xtol=1e-15)
    return float(truss.bar_force(w1)) / truss.p_ref, w1


def _run(monkeypatch, chord: bool):
    truss = VonMisesTruss(spring=2000.0)
    target = 0.3 * truss.limit_points()[0][0]  # w2 well before the limit point
    calls = []
    real = attempts_module.newton_correct

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(attempts_module, "newton_correct", counting)
    if not chord:
        monkeypatch.setattr(PathFollower, "chord_target", lambda *a, **k: None)
    opts = PathOptions(control="arc-length", until_probe="w2", until_value=target, tol=TOL,
                       initial_increment=0.15 * target)
    result = follow_path(truss, opts, ["w1", "w2"])
    return truss, target, result, len(calls)


def test_the_crossed_target_is_hit_by_one_corrector_on_the_closed_form(monkeypatch):
    truss, target, result, correctors = _run(monkeypatch, chord=True)
    assert result.reached_target, result.message
    end = result.states[-1]
    lam, w1 = _closed_form(truss, target)
    # the target exactly (it is the corrector's control equation), the path to Newton's tol
    assert math.isclose(end.probes["w2"], target, rel_tol=1e-12)
    assert math.isclose(end.load_factor, lam, rel_tol=1e-8)
    assert math.isclose(end.u[0], w1, rel_tol=1e-8)
    steps = len(result.states) - 1
    assert correctors == steps + 1  # one attempt per step, plus the chord's corrector


def test_regula_falsi_reaches_the_same_state_with_more_correctors(monkeypatch):
    truss, target, chord_result, chord_correctors = _run(monkeypatch, chord=True)
    monkeypatch.undo()
    _, _, falsi_result, falsi_correctors = _run(monkeypatch, chord=False)
    a, b = chord_result.states[-1], falsi_result.states[-1]
    scale = abs(target)
    assert abs(b.probes["w2"] - target) <= 1e-6 * scale  # regula falsi: within target_tol
    assert abs(a.load_factor - b.load_factor) <= 1e-5 * abs(a.load_factor)
    assert falsi_correctors > chord_correctors


def _step(past: bool, trial_w1: float | None = None, psi: float = 1.0):
    """A follower at a state before the truss's load maximum and an equilibrium past it (or,
    ``past`` False, one still before it; or the one at ``trial_w1``)."""
    truss = VonMisesTruss(spring=2000.0)
    (w_max, _), (w_min, _) = truss.limit_points()
    opts = PathOptions(control="arc-length", until_probe="w1", until_value=w_min, tol=TOL)
    f = PathFollower(truss, opts, ["w1", "w2"], None)
    f.psi, f.prev_step, f.sigma = psi, None, 1.0

    def state(w1):
        lam = float(truss.bar_force(w1)) / truss.p_ref
        return np.array([w1, w1 + lam * truss.p_ref / truss.ks]), lam

    u0, lam0 = state(0.5 * w_max)
    fac0 = truss.factorize(truss.tangent(u0))
    last = PathState(0, u0, lam0, 0, f.probes(u0), fac0.negative_pivots)
    f.states = [last]
    u1, lam1 = state(trial_w1 if trial_w1 is not None
                     else 0.5 * (w_max + w_min) if past else 0.8 * w_max)
    fac1 = truss.factorize(truss.tangent(u1))
    return truss, f, last, Trial(u1, lam1, 3, fac1), fac0, fac1


def test_a_step_across_a_critical_point_is_left_to_regula_falsi():
    truss, f, last, trial, fac0, fac1 = _step(past=True)
    assert (fac0.negative_pivots, fac1.negative_pivots) == (0, 1)  # the toy crosses the max
    frac, name, target = 0.5, "w1", 0.5 * (last.u[0] + trial.u[0])
    before = truss.evaluations
    assert f.chord_target(name, target, frac, last, trial) is None
    assert truss.evaluations == before  # refused before any corrector


def _chord(f, last, trial):
    return f.chord_target("w1", 0.5 * (last.u[0] + trial.u[0]), 0.5, last, trial)


def test_a_regular_step_is_hit_from_its_chord():
    truss, f, last, trial, fac0, fac1 = _step(past=False)
    assert fac0.negative_pivots == fac1.negative_pivots == 0
    hit = _chord(f, last, trial)
    assert hit is not None
    assert math.isclose(hit.u[0], 0.5 * (last.u[0] + trial.u[0]), rel_tol=1e-12)
    assert math.isclose(hit.load_factor, float(truss.bar_force(hit.u[0])), rel_tol=1e-8)


def _beyond_the_snap(truss):
    """w1 past the truss's snap, in tension: positive stiffness, λ above the maximum."""
    (w_max, l_max), (w_min, _) = truss.limit_points()
    from scipy.optimize import brentq

    return brentq(lambda w: truss.bar_force(w) - 1.5 * l_max * truss.p_ref, w_min, 10 * w_min)


def test_a_result_outside_the_steps_load_bracket_is_refused():
    # last before the maximum, trial past the snap (both positive definite); the target just
    # past the minimum: positive stiffness again, but λ < 0, below both ends of the step. A
    # small λ weight ψ: the corrector's move (mostly in λ) passes the distance guard
    truss = VonMisesTruss(spring=2000.0)
    _, f, last, trial, fac0, fac1 = _step(past=True, trial_w1=_beyond_the_snap(truss), psi=1e-3)
    assert fac0.negative_pivots == fac1.negative_pivots == 0
    (_, _), (w_min, _) = truss.limit_points()
    target = 1.02 * w_min
    frac = (target - last.u[0]) / (trial.u[0] - last.u[0])
    assert f.chord_target("w1", target, frac, last, trial) is None
    assert float(truss.bar_force(target)) < min(last.load_factor, trial.load_factor)


def test_a_result_with_other_inertia_than_the_step_is_refused():
    # the same step; the target just past the maximum: λ inside the bracket, one negative pivot
    truss = VonMisesTruss(spring=2000.0)
    _, f, last, trial, _, _ = _step(past=True, trial_w1=_beyond_the_snap(truss), psi=1e-3)
    (w_max, _), _ = truss.limit_points()
    target = 1.05 * w_max
    lam = float(truss.bar_force(target)) / truss.p_ref
    assert last.load_factor < lam < trial.load_factor
    assert truss.factorize(truss.tangent(np.array([target, target + lam / truss.ks]))) \
        .negative_pivots == 1
    frac = (target - last.u[0]) / (trial.u[0] - last.u[0])
    assert f.chord_target("w1", target, frac, last, trial) is None


@pytest.mark.parametrize("which", ["last", "trial"])
def test_unknown_inertia_is_left_to_regula_falsi(which):
    truss, f, last, trial, _, fac1 = _step(past=False)
    if which == "last":
        last = PathState(0, last.u, last.load_factor, 0, last.probes, None)
    else:
        trial = Trial(trial.u, trial.load_factor, 3, _NoInertia(fac1))
    before = truss.evaluations
    assert _chord(f, last, trial) is None
    assert truss.evaluations == before


class _NoInertia:
    """A factorisation whose inertia is unknown (as SuperLU's pivoting LU)."""

    negative_pivots = None

    def __init__(self, fac):
        self.solve = fac.solve


def _across(target_fraction=0.5):
    """A follower whose step from before the truss's maximum to past it crosses until = w2."""
    truss, f0, last, trial, fac0, fac1 = _step(past=True)
    assert (fac0.negative_pivots, fac1.negative_pivots) == (0, 1)
    target = last.u[1] + target_fraction * (trial.u[1] - last.u[1])
    opts = PathOptions(control="arc-length", until_probe="w2", until_value=target, tol=TOL)
    f = PathFollower(truss, opts, ["w1", "w2"], None)
    f.psi, f.prev_step, f.sigma = 1.0, None, 1.0
    last = PathState(0, last.u, last.load_factor, 0, f.probes(last.u), 0)
    f.states = [last]
    t = np.linalg.solve(truss.tangent(last.u), truss.f_ref)
    return truss, f, last, trial, t, target


def test_a_step_across_the_maximum_hits_the_target_under_its_own_control(monkeypatch):
    truss, f, last, trial, t, target = _across()
    arcs = []
    real = PathFollower.attempt
    monkeypatch.setattr(PathFollower, "attempt", lambda self, *a, **k: arcs.append(1) or
                        real(self, *a, **k))
    monkeypatch.setattr(PathFollower, "chord_target", lambda *a, **k: pytest.fail("chord"))
    goals = []
    control = PathFollower.control_to
    monkeypatch.setattr(PathFollower, "control_to", lambda self, name, goal, *a: goals.append(goal)
                        or control(self, name, goal, *a))
    hit, _, name = f.hit_crossed_target(trial, 1.0, last, t)
    assert name == "w2" and not arcs  # neither the chord nor regula falsi's arcs
    # the first sub-increment covers half the distance (last's tangent, before the maximum)
    assert math.isclose(goals[0], 0.5 * (last.u[1] + target), rel_tol=1e-12)
    # closed form: w2 = w1 + λ P / k is monotone in w1 here (k > max |f'|), λ P = f_bar(w1)
    from scipy.optimize import brentq

    w1 = brentq(lambda w: w + truss.bar_force(w) / truss.ks - target, last.u[0], trial.u[0],
                xtol=1e-15)
    assert math.isclose(hit.u[1], target, rel_tol=1e-12)
    assert math.isclose(hit.u[0], w1, rel_tol=1e-8)
    assert math.isclose(hit.load_factor, float(truss.bar_force(w1)) / truss.p_ref, rel_tol=1e-8)


def test_across_the_maximum_a_failed_target_control_falls_back_to_regula_falsi(monkeypatch):
    truss, f, last, trial, t, target = _across()
    tries, arcs = [], []
    monkeypatch.setattr(PathFollower, "attempt_target", lambda *a, **k: tries.append(1))
    real = PathFollower.attempt
    monkeypatch.setattr(PathFollower, "attempt", lambda self, *a, **k: arcs.append(1) or
                        real(self, *a, **k))
    h = f.wnorm(trial.u - last.u, trial.load_factor - last.load_factor)
    _, _, name = f.hit_crossed_target(trial, h, last, t)
    assert name == "w2"
    assert tries == [1]  # tried once, first, not again after regula falsi
    assert arcs  # regula falsi's shortened arcs
