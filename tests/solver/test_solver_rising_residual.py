"""The corrector abandons an iteration whose residual rose twice in a row above the first one.

Toys with closed-form iterates: a unit spring f = u solved with a scripted tangent c_k at the
k-th correction, so each correction multiplies the residual by (1 − 1/c_k) exactly (c = 0.4:
×1.5, c = 10/9: ×0.1, c = 1: the exact solve); and f = arctan u at λ = 0 from u = 3, where
Newton diverges (|u| grows every iteration for |u₀| above the root of 2u = (1 + u²) arctan u,
≈ 1.392) and the residual |arctan u| rises towards π/2 without ever growing 1e4-fold, so
without the rule only the non-finite iterate (u ≈ u² per step) stops it.
"""

import math

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, PathOptions, follow_path, solve_equilibrium
from sandwich.solver.newton import RISING

TOL = 1e-10
ON = NewtonSettings(tol=TOL, divergence_rises=2)  # off by default; the path follower's value


class ScriptedSpring(ToySystem):
    """f = u with the tangents ``script`` (then 1): residual factors 1 − 1/c per correction."""

    dof_names = ("u",)

    def __init__(self, script: list[float]) -> None:
        super().__init__()
        self.script, self.residuals = list(script), []

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.residuals.append(abs(float(u[0]) - 1.0))  # λ = 1, f_ref = 1
        return np.array(u, dtype=float)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[self.script.pop(0) if self.script else 1.0]])


class Arctan(ToySystem):
    dof_names = ("u",)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return np.arctan(u)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[1.0 / (1.0 + float(u[0]) ** 2)]])


def test_two_rises_above_the_first_residual_fail_at_the_second():
    # residuals 1, 1.5, 2.25: both rises above the first one
    system = ScriptedSpring([0.4, 0.4, 0.4, 0.4])
    res = solve_equilibrium(system, 1.0, u0=np.array([0.0]), settings=ON)
    assert not res.converged and "rose 2 times" in res.reason
    np.testing.assert_allclose(system.residuals, [1.0, 1.5, 2.25], rtol=1e-14)
    assert res.iterations == 2 and res.u[0] == 0.0  # the start state is handed back


def test_rises_below_the_first_residual_or_one_at_a_time_do_not_fail():
    # 1 → 0.1, then three rises (0.15, 0.225, 0.3375) all below the first, then the exact solve
    system = ScriptedSpring([10.0 / 9.0, 0.4, 0.4, 0.4])
    res = solve_equilibrium(system, 1.0, u0=np.array([0.0]), settings=ON)
    assert res.converged and abs(res.u[0] - 1.0) <= TOL
    np.testing.assert_allclose(system.residuals[:5], [1.0, 0.1, 0.15, 0.225, 0.3375], rtol=1e-12)
    # above the first one but never twice in a row: 1 → 1.5 → 0.15 → 0.225 → … → converged
    system = ScriptedSpring([0.4, 10.0 / 9.0, 0.4])
    res = solve_equilibrium(system, 1.0, u0=np.array([0.0]), settings=ON)
    assert res.converged and abs(res.u[0] - 1.0) <= TOL
    np.testing.assert_allclose(system.residuals[:4], [1.0, 1.5, 0.15, 0.225], rtol=1e-12)


@pytest.mark.parametrize("rises", [2, 3])
def test_diverging_newton_on_arctan_stops_after_the_rises(rises):
    settings = NewtonSettings(tol=TOL, max_iterations=25, divergence_rises=rises)
    res = solve_equilibrium(Arctan(), 0.0, u0=np.array([3.0]), settings=settings)
    assert not res.converged and f"rose {rises} times" in res.reason
    assert res.iterations == rises
    off = solve_equilibrium(Arctan(), 0.0, u0=np.array([3.0]),
                            settings=NewtonSettings(tol=TOL, max_iterations=25,
                                                    divergence_rises=0))
    assert not off.converged and "non-finite" in off.reason
    assert off.iterations > 2 * rises  # what the rule saves: iterations to the overflow


def test_converging_newton_on_arctan_is_untouched():
    # inside the basin (|u0| < 1.392) the iterates alternate in sign and shrink: no rise
    res = solve_equilibrium(Arctan(), 0.0, u0=np.array([1.3]), settings=ON)
    assert res.converged and abs(res.u[0]) <= TOL
    assert math.isfinite(res.residual_norm)


class HuntingSpring(ToySystem):
    """f = u + u³ whose first two corrections of every corrector use 0.4 × the tangent.

    Each such correction multiplies the (small) residual by ≈ 1 − 1/0.4 = −1.5, so every
    attempt's residual rises twice above its first one, then converges under the exact tangent:
    what an iteration hunting for its contact set does at any increment (the 2D model's first
    step of a cantilever with a closed root debond). ``fresh`` is set before each corrector.
    """

    dof_names = ("u",)

    def __init__(self) -> None:
        super().__init__()
        self.bad, self.attempts = 0, []

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return u + u**3

    def tangent(self, u: np.ndarray) -> np.ndarray:
        k = 1.0 + 3.0 * float(u[0]) ** 2
        self.bad -= 1
        return np.array([[0.4 * k if self.bad >= 0 else k]])


def test_a_step_cut_by_the_rising_test_is_retried_without_it_and_the_path_drops_it():
    from sandwich.solver.path import attempts

    system = HuntingSpring()
    original = attempts.newton_correct

    def fresh(sys_, u, lam, constraint, settings, *args, **kwargs):
        sys_.bad = 2
        res = original(sys_, u, lam, constraint, settings, *args, **kwargs)
        sys_.attempts.append((settings.divergence_rises, res.converged, res.reason, res.rises))
        return res

    attempts.newton_correct = fresh
    try:
        result = follow_path(system, PathOptions(control="load", until_load_factor=2.0, tol=TOL),
                             ["u"])
    finally:
        attempts.newton_correct = original
    assert result.reached_target, result.message
    u = np.array([s.probes["u"] for s in result.states[1:]])
    lam = np.array([s.load_factor for s in result.states[1:]])
    np.testing.assert_allclose(u + u**3, lam, rtol=0, atol=10 * TOL * lam.max())  # closed form
    # the first attempt: stopped by the test; its retry (without it) rose as much and converged,
    # so no later corrector ran with it and no later step was cut
    first, retry, *later = system.attempts
    assert first[:2] == (2, False) and first[2].startswith(RISING)
    assert retry[:2] == (0, True) and retry[3] >= 2
    assert all(a[0] == 0 and a[1] for a in later) and later
    assert result.states[1].cuts == 1 and all(s.cuts == 0 for s in result.states[2:])
