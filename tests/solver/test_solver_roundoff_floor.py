"""Newton accepts a residual at the system's round-off floor once the increment has converged.

Toy: a linear spring ``f = k u`` whose force carries a deterministic error of amplitude δ that
no iterate can remove (as round-off does in a stiff model). Closed form: ``u = λ P / k`` within
δ / k. With a tolerance below δ / (λ P) the plain tests never pass; a system that declares
``residual_roundoff(u) = δ`` converges, and the state is the closed form within δ / k.
"""

import math

import numpy as np
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, solve_equilibrium


class NoisySpring(ToySystem):
    dof_names = ("u",)

    def __init__(self, delta: float, declare: bool, k: float = 3.0) -> None:
        super().__init__()
        self.delta, self.k, self.calls = delta, k, 0
        if declare:
            self.residual_roundoff = lambda u: self.delta

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.calls += 1  # an error that changes from call to call, bounded by δ
        return self.k * u + self.delta * math.sin(1.7 * self.calls)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[self.k]])


SETTINGS = NewtonSettings(tol=1e-12, max_iterations=15)  # tol · λ P = 1e-12 ≪ δ = 1e-8


def test_without_a_declared_floor_newton_stalls():
    res = solve_equilibrium(NoisySpring(1e-8, declare=False), 1.0, settings=SETTINGS)
    assert not res.converged and "no convergence" in res.reason


def test_a_declared_floor_is_accepted_and_the_state_is_right():
    system = NoisySpring(1e-8, declare=True)
    res = solve_equilibrium(system, 1.0, settings=SETTINGS)
    assert res.converged and res.reason == "converged to the round-off floor"
    assert res.residual_norm <= 1e-8
    assert abs(res.u[0] - 1.0 / system.k) <= 2e-8 / system.k


def test_an_exact_system_converges_ordinarily():
    """Ordinary convergence is still reported as such when the tolerance can be met."""
    res = solve_equilibrium(NoisySpring(0.0, declare=True), 1.0, settings=NewtonSettings())
    assert res.converged and res.reason == "converged"


class SlowSpring(ToySystem):
    """f = k u with a tangent 2k: Newton converges linearly (ratio ½), so many corrections
    pass the increment test before the residual one; the floor evaluations are counted."""

    dof_names = ("u",)

    def __init__(self, k: float = 3.0) -> None:
        super().__init__()
        self.k, self.floors = k, 0

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.k * u

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[2.0 * self.k]])

    def residual_roundoff(self, u: np.ndarray) -> float:
        self.floors += 1
        return 1e-300


def test_the_floor_is_evaluated_once_per_corrector():
    """Linear convergence from u = 0: tol 1e-10 passes the increment test (√tol) after ~17
    corrections and the residual test after ~33; the floor, asked for at each of the ~16 in
    between before, is evaluated once, and the answer is the closed form λ / k."""
    system = SlowSpring()
    res = solve_equilibrium(system, 1.0, settings=NewtonSettings(tol=1e-10, max_iterations=60))
    assert res.converged and res.reason == "converged"
    assert abs(res.u[0] - 1.0 / system.k) <= 1e-9 / system.k
    assert res.iterations > 20  # the premise: many corrections after the increment test passed
    assert system.floors == 1
