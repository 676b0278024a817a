"""Contact-set settling: a corrector whose contact set still changes goes past max_iterations.

Toy: a string of n nodes (springs c between neighbours) lying on a unilateral penalty
foundation (ε u where u ≤ 0: at zero gap a node counts as shut, as the 2D model's lips do),
under its own weight q per node and pulled up at node 0 by λ P. From u = 0 every node is shut;
Newton opens the lifted stretch about one node per iteration, so it needs more iterations than
nodes lifted. Reference: the exact solution found by trying every lifted prefix (the one whose
displacements agree with its own contact set: lifted u > 0, shut u ≤ 0).
"""

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import NewtonSettings, solve_equilibrium
from sandwich.solver.newton import SETTLED_ITERATIONS, SETTLING_PER_PAIR


class StringOnFoundation(ToySystem):
    """f(u) = K u + ε u [u ≤ 0]; f_ref = P e₀ − q 1 (the pull and the weight)."""

    def __init__(self, n=60, c=1.0, eps=1e3, pull=35.0, q=1.0):
        super().__init__()
        self.dof_names = tuple(f"u{i}" for i in range(n))
        K = np.zeros((n, n))
        for i in range(n - 1):  # springs between neighbours
            K[np.ix_([i, i + 1], [i, i + 1])] += c * np.array([[1.0, -1.0], [-1.0, 1.0]])
        self.K, self.eps = K, eps
        self._f = -q * np.ones(n)
        self._f[0] += pull
        self._shut = np.ones(n, dtype=bool)

    @property
    def f_ref(self):
        return self._f

    def internal_force(self, u):
        self._shut = u <= 0.0
        return self.K @ u + self.eps * np.where(self._shut, u, 0.0)

    def tangent(self, u):
        return self.K + np.diag(self.eps * (u <= 0.0))

    def exact(self, lam):
        """The displacement whose contact set is its own (tried over every lifted prefix)."""
        n = self.size
        for k in range(n + 1):
            shut = np.arange(n) >= k
            u = np.linalg.solve(self.K + np.diag(self.eps * shut), lam * self._f)
            if np.all(u[:k] > 0) and np.all(u[k:] <= 0):
                return u, k
        raise AssertionError("no consistent contact set")


class StringWithSet(StringOnFoundation):
    """The same, telling the corrector its contact set."""

    def contact_set(self):
        return self._shut.copy()


def _solve(system, max_iterations=25, tol=1e-10):
    settings = NewtonSettings(tol=tol, max_iterations=max_iterations)
    return solve_equilibrium(system, 1.0, np.zeros(system.size), settings)


def test_a_corrector_whose_set_still_changes_goes_on_to_the_exact_solution():
    blind, told = StringOnFoundation(), StringWithSet()
    u_exact, lifted = told.exact(1.0)
    a, b = _solve(blind), _solve(told)
    print(f"{lifted} nodes lifted; without the set: {a.reason!r}; with it: {b.iterations} its")
    assert lifted >= 30  # more nodes to open than the iteration limit (one per iteration)
    assert not a.converged and "no convergence in 25 iterations" in a.reason
    assert b.converged and b.iterations > 25
    assert b.u == pytest.approx(u_exact, rel=1e-8, abs=1e-12)


def test_a_settled_set_keeps_the_ordinary_limit_and_the_extension_is_bounded():
    """An unreachable tolerance: the corrector stops at max_iterations once its set settled
    (here long before), and never beyond max_iterations + SETTLING_PER_PAIR × pairs."""
    told = StringWithSet()
    settled = _solve(told, max_iterations=60, tol=1e-300)
    assert not settled.converged and settled.iterations == 60
    assert "more while its contact set settled" not in settled.reason
    short = StringWithSet(n=40)
    r = _solve(short, max_iterations=5, tol=1e-300)
    assert not r.converged
    assert 5 < r.iterations <= 5 + SETTLING_PER_PAIR * short.size
    assert "more while its contact set settled" in r.reason
    # it stopped because the set settled (SETTLED_ITERATIONS without a change), not the budget
    assert r.iterations < 5 + SETTLING_PER_PAIR * short.size
    assert SETTLED_ITERATIONS >= 1


class ChatteringSet(StringWithSet):
    """The same string, but its reported set flips between two (a chattering pair)."""

    def __init__(self):
        super().__init__()
        self.calls = 0

    def contact_set(self):
        self.calls += 1
        flags = np.zeros(self.size, dtype=bool)
        flags[self.calls % 2] = True
        return flags


def test_a_set_that_only_cycles_is_chattering_and_keeps_the_ordinary_limit():
    """Sets met before do not extend the corrector (fig. 9 d10's failing attempts: counting every
    change made its 2D run 12 × slower on the same path)."""
    r = _solve(ChatteringSet(), max_iterations=25, tol=1e-300)
    assert not r.converged and r.iterations == 25
