"""Contact-limited corrections: the corrector shortens a correction to the system's limit.

Toy: a spring k u pressed by λ P against a penalty wall at u = g₀ (plain penalty ε ⟨u − g₀⟩),
whose tangent has no wall stiffness while the point is off the wall — the blind spot of the
beam's open contact pairs (``BeamModel.correction_limit``). Its ``correction_limit`` keeps the
linearised penetration of a correction from an open state at most δ. The equilibrium under
λ P > k g₀ is u* = (λ P + ε g₀)/(k + ε), in closed form.
"""

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, PathOptions, follow_path, solve_equilibrium
from sandwich.solver.newton import LIMITED_CORRECTIONS, MIN_CORRECTION_FRACTION, NewtonResult
from sandwich.solver.path import attempts

TOL = 1e-10


class SpringOnWall(ToySystem):
    """f(u) = k u + ε ⟨u − g₀⟩; ``correction_limit`` keeps an open point within δ of the wall."""

    dof_names = ("u",)

    def __init__(self, k=1.0, eps=1e4, g0=1.0, delta=1e-3, fixed_limit=None):
        super().__init__()
        self.k, self.eps, self.g0, self.delta = k, eps, g0, delta
        self.fixed_limit = fixed_limit  # a scripted limit (tests of the corrector's rules)
        self.iterates, self.limit_calls = [], 0

    def internal_force(self, u):
        self.iterates.append(float(u[0]))
        return np.array([self.k * u[0] + self.eps * max(u[0] - self.g0, 0.0)])

    def tangent(self, u):
        return np.array([[self.k + (self.eps if u[0] > self.g0 else 0.0)]])

    def correction_limit(self, u, du):
        self.limit_calls += 1
        if self.fixed_limit is not None:
            return self.fixed_limit
        u0, d = float(u[0]), float(du[0])
        if u0 <= self.g0 and u0 + d > self.g0 + self.delta:  # open now, deep after
            return (self.g0 + self.delta - u0) / d
        return 1.0

    def equilibrium(self, lam):
        return (lam * self.p_ref + self.eps * self.g0) / (self.k + self.eps)


def _solve(system, lam, limit):
    settings = NewtonSettings(tol=TOL, max_iterations=30, limit_corrections=limit)
    return solve_equilibrium(system, lam, np.zeros(1), settings)


def test_limited_corrections_reach_the_same_equilibrium():
    """From the open state, the plain correction lands 4 past the wall (u = 5); the limited
    one stops δ past it, where the next tangent has the wall: both converge to u*."""
    free, limited = SpringOnWall(), SpringOnWall()
    a, b = _solve(free, 5.0, False), _solve(limited, 5.0, True)
    assert a.converged and b.converged
    u_star = free.equilibrium(5.0)
    assert a.u[0] == pytest.approx(u_star, rel=1e-9)
    assert b.u[0] == pytest.approx(u_star, rel=1e-9)
    assert free.iterates[1] == pytest.approx(5.0)  # the blind correction
    assert limited.iterates[1] == pytest.approx(1.0 + 1e-3)  # stopped at the allowed depth
    assert free.limit_calls == 0  # asked only when the settings say so


def test_the_limit_is_floored():
    """A limit below MIN_CORRECTION_FRACTION is raised to it (the corrector keeps moving)."""
    s = SpringOnWall(fixed_limit=0.0)
    settings = NewtonSettings(tol=TOL, max_iterations=1, limit_corrections=True)
    solve_equilibrium(s, 0.5, np.zeros(1), settings)
    assert s.iterates[1] == pytest.approx(MIN_CORRECTION_FRACTION * 0.5, rel=1e-12)


def test_only_the_first_corrections_are_limited_and_never_count_as_small():
    """Corrections halved by the limit (0.5 at every iterate) for the corrector's first
    LIMITED_CORRECTIONS, then plain Newton's — exact on this linear stretch. Started within
    1e-12 of the equilibrium, the first halved correction already leaves a residual and an
    increment within the tolerances; the corrector must not stop on a shortened correction:
    it converges after the first plain one, at u* to round-off."""
    s = SpringOnWall(fixed_limit=0.5)
    u_star = 0.5  # off the wall: u* = λ P / k
    settings = NewtonSettings(tol=TOL, max_iterations=30, limit_corrections=True)
    r = solve_equilibrium(s, u_star, np.array([u_star * (1 - 1e-12)]), settings)
    assert r.converged
    assert r.iterations == LIMITED_CORRECTIONS + 1
    assert r.u[0] == pytest.approx(u_star, rel=1e-15)
    steps = np.abs(u_star - np.array(s.iterates[:LIMITED_CORRECTIONS + 1]))
    assert np.allclose(steps[1:] / steps[:-1], 0.5, rtol=1e-3)  # halved while limited


def test_a_failed_corrector_turns_limits_on_for_the_rest_of_the_path(monkeypatch):
    """The path follower asks for limited corrections once one of its correctors has failed,
    for every corrector after it; a path whose correctors all converge never asks."""

    def run(*fail_calls):
        seen = []
        real = attempts.newton_correct

        def spy(system, u, lam, constraint, settings, *args):
            seen.append(settings.limit_corrections)
            if len(seen) in fail_calls:
                return NewtonResult(False, np.array(u, dtype=float), lam, 1, 1.0, "scripted")
            return real(system, u, lam, constraint, settings, *args)

        monkeypatch.setattr(attempts, "newton_correct", spy)
        opts = PathOptions(control="load", until_load_factor=3.0, initial_increment=0.5,
                           max_increment=0.5, tol=TOL)
        result = follow_path(SpringOnWall(), opts, ["u"])
        assert result.reached_target
        return seen

    assert not any(run())  # no failure: never asked
    seen = run(3)
    assert seen[:3] == [False, False, False]
    assert len(seen) > 4 and all(seen[3:])


def test_a_step_whose_limited_attempt_failed_is_retried_without_the_limit(monkeypatch):
    """Within one step, a failed limited attempt sends the step's further attempts back to
    plain corrections (as the rising test's retries); the next step is limited again."""
    seen = []
    real = attempts.newton_correct

    def spy(system, u, lam, constraint, settings, *args):
        seen.append(settings.limit_corrections)
        if len(seen) in (3, 4):  # step 3 fails plain, then its limited retry fails too
            return NewtonResult(False, np.array(u, dtype=float), lam, 1, 1.0, "scripted")
        return real(system, u, lam, constraint, settings, *args)

    monkeypatch.setattr(attempts, "newton_correct", spy)
    opts = PathOptions(control="load", until_load_factor=3.0, initial_increment=0.5,
                       max_increment=0.5, tol=TOL)
    assert follow_path(SpringOnWall(), opts, ["u"]).reached_target
    assert seen[:6] == [False, False, False, True, False, True]
