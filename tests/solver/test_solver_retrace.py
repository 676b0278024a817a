"""Retrace / branch-jump guard of the path follower (Crisfield's angle criterion on the converged
step, displacement part only as in Feng, Perić & Owen 1996; see docs/solver.md).

Closed-form system: the von Mises truss (1 DOF), λ(w) = f(w)/P. Its equilibrium curve is a graph
over w, so a path that goes forward along it has w strictly increasing; any decrease of w is a
retrace or a jump to another part of the curve. With a heavy load weight in the arc
(``arc_load_weight = 30``) and long steps the spherical arc around a state past the load maximum
also cuts the curve on its w < 0 part (λ < 0): unguarded, the corrector lands there (step 18,
w 0.263 → −0.045, 11 iterations; the predictor and corrector jump guards both pass it) and the
path runs down to λ ≈ −1100 at w ≈ −1.2, never reaching its target. Guarded, that step's
displacement increment is antiparallel to the previous one, it is refused and cut, and the path
passes the maximum and the minimum and reaches w = 3h with w increasing.
"""

import dataclasses

import numpy as np
from solver_toys import VonMisesTruss

from sandwich.solver import PathOptions, follow_path

TOL = 1e-8


def _options(min_step_cosine: float, h: float) -> PathOptions:
    return PathOptions(control="arc-length", until_probe="w", until_value=3 * h, tol=TOL,
                       initial_increment=0.4, max_increment=1.6, arc_load_weight=30.0,
                       max_steps=300, min_step_cosine=min_step_cosine)


def test_unguarded_long_arc_jumps_back_through_the_origin():
    # documents the defect the guard removes (the guard switched off with min_step_cosine = -1)
    truss = VonMisesTruss(h=0.2)
    result = follow_path(truss, _options(-1.0, truss.h), ["w"])
    w = np.array([s.probes["w"] for s in result.states])
    lam = np.array([s.load_factor for s in result.states])
    assert not result.reached_target
    assert np.any(np.diff(w) < 0) and lam.min() < -100.0


def test_guarded_arc_goes_forward_past_both_limit_points_to_the_target():
    truss = VonMisesTruss(h=0.2)
    result = follow_path(truss, _options(0.0, truss.h), ["w"])
    assert result.reached_target, result.message
    w = np.array([s.probes["w"] for s in result.states])
    lam = np.array([s.load_factor for s in result.states])
    assert np.all(np.diff(w) > 0)  # forward along the curve at every step
    assert w[-1] == 3 * truss.h or abs(w[-1] - 3 * truss.h) <= 1e-6 * 3 * truss.h
    # on the closed form (the residual test of a 1-load-DOF system)
    assert np.abs(lam - truss.bar_force(w) / truss.p_ref).max() <= TOL * np.abs(lam).max() * 1.01
    kinds = [lp.kind for lp in result.limit_points]
    assert kinds.count("max") == 1 and kinds.count("min") == 1
    assert sum(s.cuts for s in result.states) >= 1  # the jump was refused and the step cut


def test_guard_refuses_a_reversed_step_with_its_reason():
    # a step from the last state back towards the origin (Δu antiparallel to the previous Δu)
    # is refused by the guard, and the message names it
    from sandwich.solver.path import RETRACE, PathFollower

    truss = VonMisesTruss(h=0.2)
    f = PathFollower(truss, _options(0.0, truss.h), ["w"], None)
    f.prev_step = (np.array([0.01]), 0.5)
    assert f.turns_back(np.array([0.005]), np.array([0.005])) == ""
    why = f.turns_back(np.array([-0.005]), np.array([0.005]))
    assert why.startswith(RETRACE) and "180°" in why
    f.opt = dataclasses.replace(f.opt, control="arc-length")  # options are frozen
    f.sigma = 1.0
    f.turns_back(np.array([-0.005]), np.array([-0.005]))  # the predictor pointed back too
    assert f.sigma == -1.0
