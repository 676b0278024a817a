"""Newton's backtracking line search (``NewtonSettings.backtracks``) on a start plain Newton
cannot leave.

Toy: two uncoupled DOFs with the energy ½ x² + (y atan y − ½ ln(1 + y²)), i.e. f_int = (x, atan y),
the load on x and the probe x prescribed to 0.5 (displacement control). Closed form: x = 0.5,
λ = 0.5, y = 0. Newton on atan y diverges from |y| > 1.39 (each correction overshoots to a larger
|y| of the other sign), so from y = 3 the plain corrector never converges; halving the
corrections that do not lower ‖R‖ reaches the closed form, after which full steps converge
quadratically.
"""

import math

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, newton_correct
from sandwich.solver.controls import LoadConstraint, ProbeConstraint


class AtanSpring(ToySystem):
    dof_names = ("x", "y")
    load_dof = 0

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        return np.array([u[0], math.atan(u[1])])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[1.0, 0.0], [0.0, 1.0 / (1.0 + u[1] ** 2)]])


def _solve(backtracks: int, y0: float = 3.0):
    system = AtanSpring()
    c = system.probe_vector("x")
    res = newton_correct(system, np.array([0.0, y0]), 0.0,
                         ProbeConstraint(c, 0.5, lambda a, b: float(a @ b)),
                         NewtonSettings(tol=1e-12, max_iterations=40, backtracks=backtracks))
    return system, res


def test_plain_newton_cannot_leave_the_far_start():
    _, res = _solve(backtracks=0)
    assert not res.converged


@pytest.mark.parametrize("y0", [3.0, -10.0, 50.0])
def test_backtracking_reaches_the_closed_form(y0):
    _, res = _solve(backtracks=12, y0=y0)
    assert res.converged, res.reason
    assert res.u[0] == pytest.approx(0.5, abs=1e-12)
    assert res.load_factor == pytest.approx(0.5, abs=1e-12)
    assert abs(res.u[1]) < 1e-8


def test_backtracking_leaves_a_start_plain_newton_handles_unchanged():
    """From y = 0.5 every full correction lowers ‖R‖: the same iterates as plain Newton."""
    s0, plain = _solve(backtracks=0, y0=0.5)
    s1, damped = _solve(backtracks=12, y0=0.5)
    assert plain.converged and damped.converged
    assert plain.iterations == damped.iterations
    np.testing.assert_array_equal(plain.u, damped.u)
    assert s1.evaluations == s0.evaluations  # the line search's force is reused, not redone


class NoisySpring(ToySystem):
    """f = k u plus a force error of amplitude δ that changes from call to call (round-off)."""

    dof_names = ("u",)

    def __init__(self, delta: float, k: float = 3.0) -> None:
        super().__init__()
        self.delta, self.k = delta, k

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        return self.k * u + self.delta * math.sin(1.1 * self.evaluations)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[self.k]])


def test_a_residual_within_the_tolerance_is_not_line_searched():
    """Closed form u = λ P / k within δ / k. After the first correction ‖R‖ is at the noise δ,
    below tol · λ P, but the increment test needs one more (tiny) correction; whether it
    lowers ‖R‖ is up to the noise (with this noise it does not: searched, the corrector would
    fail with "no decrease"), so it is taken in full."""
    system = NoisySpring(delta=1e-9)
    res = newton_correct(system, np.array([0.0]), 1.0, LoadConstraint(1.0),
                         NewtonSettings(tol=1e-8, max_iterations=10, backtracks=12))
    assert res.converged, res.reason
    assert res.u[0] == pytest.approx(1.0 / 3.0, abs=2e-9)


class AtanSpringForceOnly(AtanSpring):
    """The same system with ``internal_force_only`` (the same force, counted apart)."""

    def __init__(self) -> None:
        super().__init__()
        self.only = 0
        self.full_points: list[float] = []

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.full_points.append(float(u[1]))
        return super().internal_force(u)

    def internal_force_only(self, u: np.ndarray) -> np.ndarray:
        self.only += 1
        return np.array([u[0], math.atan(u[1])])


def test_halved_trials_ask_for_the_force_only_with_the_same_iterates():
    """The full step's trial through internal_force, the halved ones through
    internal_force_only: the same iterates and answer as without it (closed form above)."""
    plain, ref = _solve(backtracks=12)
    system = AtanSpringForceOnly()
    c = system.probe_vector("x")
    res = newton_correct(system, np.array([0.0, 3.0]), 0.0,
                         ProbeConstraint(c, 0.5, lambda a, b: float(a @ b)),
                         NewtonSettings(tol=1e-12, max_iterations=40, backtracks=12))
    assert res.converged and res.iterations == ref.iterations
    np.testing.assert_array_equal(res.u, ref.u)
    assert system.only > 0  # there were halvings (from y = 3 the full steps overshoot)
    assert system.evaluations + system.only == plain.evaluations  # one force per trial
