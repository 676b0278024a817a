"""The path goes on on a finer system a ``refine`` hook hands over (sandwich.solver.path.switching).

References are closed forms: a cubic spring whose finer model has one more (hierarchical) DOF,
an enrichment ``z`` coupled to ``w`` (``z = α w / k_z`` at equilibrium, so its ``w``-stiffness is
``k − α²/k_z``), and the pitchfork toy (λ_c = k1 k2 / P).
"""

import numpy as np
import pytest
from solver_toys import Pitchfork, ToySystem

from sandwich.solver import PathOptions, follow_path
from sandwich.solver.controls import LoadConstraint, ProbeConstraint
from sandwich.solver.limits import find_limit_points
from sandwich.solver.newton import NewtonSettings, newton_correct
from sandwich.solver.path import Refinement

TOL = 1e-10


class Cubic(ToySystem):
    """``f(w) = k w + c w³`` under ``λ P`` (1 DOF ``w``)."""

    dof_names = ("w",)

    def __init__(self, k: float = 2.0, c: float = 0.5) -> None:
        super().__init__()
        self.k, self.c = k, c

    def internal_force(self, u):
        return np.array([self.k * u[0] + self.c * u[0] ** 3])

    def tangent(self, u):
        return np.array([[self.k + 3 * self.c * u[0] ** 2]])


class EnrichedCubic(Cubic):
    """The cubic with an enrichment ``z``: ``Π = … + ½ k_z z² − α w z`` (2 DOFs ``w, z``)."""

    dof_names = ("w", "z")

    def __init__(self, k=2.0, c=0.5, kz=4.0, alpha=1.0) -> None:
        super().__init__(k, c)
        self.kz, self.alpha = kz, alpha

    def internal_force(self, u):
        w, z = u
        return np.array([self.k * w + self.c * w**3 - self.alpha * z,
                         self.kz * z - self.alpha * w])

    def tangent(self, u):
        w, _ = u
        return np.array([[self.k + 3 * self.c * w * w, -self.alpha], [-self.alpha, self.kz]])

    def load_of(self, w):
        """λ on the finer model's path at ``w`` (P = 1)."""
        return (self.k - self.alpha**2 / self.kz) * w + self.c * w**3


def _pad(v):
    return np.concatenate([v, [0.0]]) if v.size == 1 else v


def _switch_once(fine, when, hold_probe=False):
    """A hook handing over ``fine`` at the first state ``when(state)`` says, re-converged there."""
    calls = []

    def hook(state, system):
        calls.append(state.step)
        if system is fine or not when(state):
            return None
        c = fine.probe_vector("w")
        constraint = (ProbeConstraint(c, state.probes["w"]) if hold_probe
                      else LoadConstraint(state.load_factor))
        res = newton_correct(fine, _pad(state.u), state.load_factor, constraint,
                             NewtonSettings(tol=TOL))
        assert res.converged
        return Refinement(fine, _pad, res.u, res.load_factor, res.iterations, res.factorization)

    return hook, calls


def test_the_path_goes_on_on_the_finer_system_and_ends_on_its_closed_form():
    coarse, fine = Cubic(), EnrichedCubic()
    hook, _ = _switch_once(fine, lambda s: s.load_factor >= 1.0)
    seen = []
    res = follow_path(coarse, PathOptions(control="load", until_load_factor=3.0,
                                          initial_increment=0.4, max_increment=0.4, tol=TOL),
                      ["w"], seen.append, refine=hook)
    assert res.reached_target
    switched = next(i for i, s in enumerate(res.states) if s.u.size == 2 and s.load_factor >= 1.0)
    for s in res.states[switched:]:  # on the finer model's closed-form path
        assert s.load_factor == pytest.approx(fine.load_of(s.probes["w"]), rel=1e-8)
        assert s.u[1] == pytest.approx(fine.alpha * s.u[0] / fine.kz, rel=1e-8)
    for s in res.states[1:switched]:  # carried over: the coarse path, enrichment zero
        assert s.u.size == 2 and s.u[1] == 0.0
        assert s.load_factor == pytest.approx(coarse.k * s.u[0] + coarse.c * s.u[0] ** 3,
                                              rel=1e-8)
    # one state per step, the replaced one streamed again with its step number
    assert [s.step for s in res.states] == list(range(len(res.states)))
    assert [s.step for s in seen].count(switched) == 2
    assert seen[-1] is res.states[-1]
    # the finer model is softer: same load, larger deflection at the switch
    first = seen[[s.step for s in seen].index(switched)]  # as the coarse path reached it
    assert res.states[switched].probes["w"] > first.probes["w"]


def test_a_switch_is_no_limit_point():
    """Under displacement control the softer model's load drops at the switch: not a maximum."""
    coarse, fine = Cubic(), EnrichedCubic(alpha=1.8)
    hook, _ = _switch_once(fine, lambda s: s.probes["w"] >= 0.5, hold_probe=True)
    res = follow_path(coarse, PathOptions(control="displacement", until_probe="w",
                                          until_value=1.5, initial_increment=0.1,
                                          max_increment=0.1, tol=TOL), ["w"], refine=hook)
    assert res.reached_target
    lam = [s.load_factor for s in res.states]
    assert any(b < a for a, b in zip(lam[:-1], lam[1:], strict=True))  # the drop is there
    assert find_limit_points(res.states)  # read as one step it would be a maximum
    assert res.limit_points == []
    assert res.states[-1].load_factor == pytest.approx(fine.load_of(1.5), rel=1e-8)


class SofterPitchfork(Pitchfork):
    """The pitchfork with a lower critical load (same fundamental path ``x = λ P / k1``)."""


def test_a_rewinding_switch_locates_the_critical_point_on_the_finer_system():
    coarse, fine = Pitchfork(k1=2.0, k2=1.0), SofterPitchfork(k1=2.0, k2=0.9)
    before = {}

    def hook(state, system):
        last, before["state"] = before.get("state"), state
        if system is fine or state.crossing is None or last is None:
            return None
        res = newton_correct(fine, last.u.copy(), last.load_factor,
                             LoadConstraint(last.load_factor), NewtonSettings(tol=TOL))
        assert res.converged
        return Refinement(fine, lambda v: v.copy(), res.u, res.load_factor, res.iterations,
                          res.factorization, rewind=1)

    res = follow_path(coarse, PathOptions(control="load", until_load_factor=3.0,
                                          initial_increment=0.35, max_increment=0.35,
                                          tol=TOL),
                      ["x", "y"], refine=hook)
    assert res.reached_target
    bif = [lp for lp in res.limit_points if lp.kind == "bifurcation"]
    assert len(bif) == 1
    # on the finer model's critical load (1.8, after the state before the crossing at 1.75),
    # not the coarse one's (2.0)
    assert abs(bif[0].load_factor - fine.critical_load_factor) < 0.05
    assert [s.step for s in res.states] == list(range(len(res.states)))
