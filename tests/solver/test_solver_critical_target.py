"""A hard step across a critical point and the stopping target is cut, not finished from before.

``PathFollower.converge_step`` refuses, up to ``CRITICAL_TARGET_CUTS`` times, a converged trial
whose tangent's inertia differs from the last state's, which passed the ``until`` target and
needed more than ``desired_iterations``: the target is then reached by ordinary steps past the
critical point instead of by the target's control from before it. Toy: the von Mises truss
behind a spring (its load maximum changes the inertia 0 → 1, tests/solver/solver_toys.py);
the trial's iteration count is set by the test. The beam's case (fig. 7 c1 at 120 elements):
tests/beam/test_step_independence.py.
"""

import numpy as np
import pytest
from solver_toys import VonMisesTruss

from sandwich.solver import PathOptions
from sandwich.solver.path import (
    CRITICAL_TARGET_CUTS,
    PathFollower,
    PathState,
    StepSize,
    Trial,
)

TOL = 1e-10


def _follower(target_fraction: float, past: bool = True, desired: int = 5):
    """A follower at a state before the truss's maximum, a trial past it (or, ``past`` False,
    still before it), and until = w2 at ``target_fraction`` of the way between them."""
    truss = VonMisesTruss(spring=2000.0)
    (w_max, _), (w_min, _) = truss.limit_points()

    def state(w1):
        lam = float(truss.bar_force(w1)) / truss.p_ref
        return np.array([w1, w1 + lam * truss.p_ref / truss.ks]), lam

    u0, lam0 = state(0.5 * w_max)
    u1, lam1 = state(0.5 * (w_max + w_min) if past else 0.8 * w_max)
    target = u0[1] + target_fraction * (u1[1] - u0[1])
    opts = PathOptions(control="arc-length", until_probe="w2", until_value=target, tol=TOL,
                       desired_iterations=desired)
    f = PathFollower(truss, opts, ["w1", "w2"], None)
    f.psi, f.prev_step, f.sigma = 1.0, None, 1.0
    f.recent, f.peak = [], 0.0
    f.divergence_rises = 0
    fac0 = truss.factorize(truss.tangent(u0))
    last = PathState(0, u0, lam0, 0, f.probes(u0), fac0.negative_pivots)
    f.states = [last]
    fac1 = truss.factorize(truss.tangent(u1))
    return f, last, u1, lam1, fac1


def _converge(monkeypatch, f, last, u1, lam1, fac1, iterations):
    """``_converge_step`` with every attempt converging to the same trial; the sizes tried."""
    tried = []

    def attempt(self, h, last_, t, rises=0, limit=None):
        tried.append(h)
        return Trial(u1, lam1, iterations, fac1), "converged"

    monkeypatch.setattr(PathFollower, "attempt", attempt)
    size = StepSize(1.0, 1e-6, 10.0, f.opt.desired_iterations)
    out = f.converge_step(size, last, np.zeros(2), 1)
    return out, tried


def test_the_toy_step_crosses_the_maximum_and_the_target():
    f, last, u1, lam1, fac1 = _follower(0.5)
    assert (last.negative_pivots, fac1.negative_pivots) == (0, 1)
    assert f.crossings(last, Trial(u1, lam1, 9, fac1))


def test_a_hard_step_across_the_maximum_and_the_target_is_cut(monkeypatch):
    f, last, u1, lam1, fac1 = _follower(0.5)
    (trial, h, direct, cuts), tried = _converge(monkeypatch, f, last, u1, lam1, fac1, 9)
    # refused CRITICAL_TARGET_CUTS times, each retry at half the size, then accepted
    assert tried == [0.5 ** k for k in range(CRITICAL_TARGET_CUTS + 1)]
    assert cuts == CRITICAL_TARGET_CUTS >= 1 and h == tried[-1]


@pytest.mark.parametrize("case", ["easy", "before the maximum", "target not crossed"])
def test_other_steps_are_accepted_at_once(monkeypatch, case):
    f, last, u1, lam1, fac1 = _follower(
        1.5 if case == "target not crossed" else 0.5, past=case != "before the maximum")
    iterations = 5 if case == "easy" else 9  # desired_iterations = 5
    (trial, h, direct, cuts), tried = _converge(monkeypatch, f, last, u1, lam1, fac1,
                                                iterations)
    assert tried == [1.0] and cuts == 0


def test_unknown_inertia_leaves_the_step_alone(monkeypatch):
    f, last, u1, lam1, fac1 = _follower(0.5)
    last = PathState(0, last.u, last.load_factor, 0, last.probes, None)
    f.states = [last]
    (_, _, _, cuts), tried = _converge(monkeypatch, f, last, u1, lam1, fac1, 9)
    assert tried == [1.0] and cuts == 0
