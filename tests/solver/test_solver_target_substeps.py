"""Hitting a crossed target under its own control, in sub-increments.

When the step that crosses a stopping target cannot be shortened onto it by arc-length (the
shortened arcs' correctors fail), the follower reaches the target by controlling the crossed
quantity itself from the last state, halving the sub-increment on a failure
(``PathFollower.attempt_target``; needed by the beam's fig. 7 c4 scene at 40 elements). Toy: two
springs in series, the inner one stiffening sharply (a smoothed contact) beyond a gap: under
control of the loaded DOF, Newton from the linear predictor over the whole distance fails within
a few iterations while small sub-increments converge. Reference: the closed-form equilibrium
λ = k1 (a − b) with b solving k1 (a − b) = k2 b + c(b).
"""

import math

import numpy as np
from scipy.optimize import brentq
from solver_toys import ToySystem

from sandwich.solver import PathOptions
from sandwich.solver.path import PathFollower, PathState

K1, K2, KC, GAP, S = 1.0, 0.05, 1e3, 1.0, 0.1


def _contact(b):
    z = (b - GAP) / S
    return KC * S * np.logaddexp(0.0, z), KC / (1.0 + np.exp(-z))


class StiffeningSeries(ToySystem):
    """DOFs (a, b): spring k1 between a and b, spring k2 plus a smoothed stiff contact at b."""

    dof_names = ("a", "b")

    def internal_force(self, u):
        a, b = u
        c, _ = _contact(b)
        return np.array([K1 * (a - b), -K1 * (a - b) + K2 * b + c])

    def tangent(self, u):
        _, dc = _contact(u[1])
        return np.array([[K1, -K1], [-K1, K1 + K2 + dc]])


def _closed_form(a):
    b = brentq(lambda b: K1 * (a - b) - K2 * b - _contact(b)[0], -10.0, a + 10.0, xtol=1e-14)
    return K1 * (a - b), b


def _follower(system, max_iterations):
    opts = PathOptions(control="arc-length", until_probe="a", until_value=3.0, tol=1e-10,
                       max_iterations=max_iterations)
    f = PathFollower(system, opts, ["a"], None)
    f.psi = 1.0
    f.prev_step = None
    f.sigma = 1.0
    f.states = [PathState(0, np.zeros(2), 0.0, 0, {"a": 0.0}, 0)]
    return f


def test_the_target_is_reached_in_substeps_where_one_corrector_fails():
    system = StiffeningSeries()
    f = _follower(system, max_iterations=6)
    last = f.states[0]
    t = np.linalg.solve(system.tangent(np.zeros(2)), system.f_ref)
    # one corrector over the whole distance fails (the check that the toy is hard enough) ...
    assert f.control_to("a", 3.0, last.u, last.load_factor, t) is None
    # ... the sub-incremented control reaches it, on the closed form
    trial = f.attempt_target("a", 3.0, last, t)
    assert trial is not None
    lam, b = _closed_form(3.0)
    assert math.isclose(trial.u[0], 3.0, rel_tol=1e-12)
    assert math.isclose(trial.u[1], b, rel_tol=1e-8)
    assert math.isclose(trial.load_factor, lam, rel_tol=1e-8)


def test_a_target_beyond_reach_gives_none_not_a_wrong_state():
    system = StiffeningSeries()
    f = _follower(system, max_iterations=1)  # one iteration never converges a nonlinear step
    last = f.states[0]
    t = np.linalg.solve(system.tangent(np.zeros(2)), system.f_ref)
    assert f.attempt_target("a", 3.0, last, t) is None
