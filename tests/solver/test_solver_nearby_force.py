"""The corrector asks a system's ``internal_force_nearby`` only after a converged increment.

Toy: a linear spring f = k u solved with the tangent 2k, so Newton converges linearly (ratio ½)
from u = 0 and many corrections pass the increment test (relative size ≤ √tol) before the
residual test; closed form u = λ / k. Each force evaluation records whether it came through
``internal_force_nearby`` and the size of the correction that led to it.
"""

import math

import numpy as np
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, solve_equilibrium

TOL = 1e-10


class SlowSpring(ToySystem):
    dof_names = ("u",)

    def __init__(self, nearby: bool, k: float = 3.0) -> None:
        super().__init__()
        self.k, self.calls, self.last_u = k, [], None
        if nearby:
            self.internal_force_nearby = lambda u: self._force(u, True)

    def _force(self, u: np.ndarray, nearby: bool) -> np.ndarray:
        step = None if self.last_u is None else float(abs(u[0] - self.last_u))
        self.calls.append((nearby, step, float(u[0])))
        self.last_u = float(u[0])
        return self.k * u

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self._force(u, False)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[2.0 * self.k]])


def test_nearby_is_asked_only_after_a_converged_increment_and_changes_nothing():
    settings = NewtonSettings(tol=TOL, max_iterations=60)
    plain = SlowSpring(nearby=False)
    res_plain = solve_equilibrium(plain, 1.0, settings=settings)
    system = SlowSpring(nearby=True)
    res = solve_equilibrium(system, 1.0, settings=settings)
    assert res.converged and res_plain.converged
    assert abs(res.u[0] - 1.0 / system.k) <= 1e-9 / system.k  # the closed form
    # the same iterates: the nearby force is the force
    assert [c[2] for c in system.calls] == [c[2] for c in plain.calls]
    assert res.iterations == res_plain.iterations
    used = [c for c in system.calls if c[0]]
    assert len(used) > 10  # the premise: many corrections after the increment converged
    assert not system.calls[0][0]  # never for the predictor
    # a nearby evaluation at u_k+1 follows an iterate u_k whose correction u_k − u_k−1 passed
    # the increment test: within √tol of the scale max(|Δu|, |u|) with the load weight ψ λ = 1
    for before, call in zip(system.calls[1:], system.calls[2:], strict=False):
        if call[0]:
            _, step, u = before
            assert step <= math.sqrt(TOL) * math.sqrt(u * u + 1.0)
    # and the first correction that passed the test is followed by nearby evaluations only
    first = next(i for i, c in enumerate(system.calls) if c[0])
    assert all(c[0] for c in system.calls[first:])
