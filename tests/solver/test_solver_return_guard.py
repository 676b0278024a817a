"""The path follower stops where its path returns onto states it passed (``_Follower._returned``).

A regular equilibrium curve does not come back to a point it passed, so a state on an earlier
step's chord means the path is retracing its own branch (docs/solver.md, "A path that returns
onto itself"). Geometry checked on synthetic states (reference: the distance from a point to a
segment, worked by hand below), in the norm ‖(u, ψλ)‖.
"""

import math

import numpy as np
from solver_toys import VonMisesTruss

from sandwich.solver import PathOptions
from sandwich.solver.path import RETURN_FRACTION, RETURN_SKIP, PathState, _Follower


def _follower_on(points: list[tuple[float, float]]) -> _Follower:
    """A follower whose path is the (u, λ) points given (1 DOF, ψ = 1)."""
    truss = VonMisesTruss(h=0.2)
    f = _Follower(truss, PathOptions(control="arc-length", until_probe="w", until_value=1.0),
                  ["w"], None)
    f.psi = 1.0
    f.states = [PathState(k, np.array([u]), lam, 1, {"w": u}, 0)
                for k, (u, lam) in enumerate(points)]
    return f


def _state(step: int, u: float, lam: float) -> PathState:
    return PathState(step, np.array([u]), lam, 1, {"w": u}, 0)


def test_a_state_on_a_passed_chord_stops_the_path_and_one_beside_it_does_not():
    out = [(float(s), float(s)) for s in range(11)]  # u = λ = 0 … 10: chords of length √2
    f = _follower_on(out)
    back = _state(11, 5.5, 5.5)  # on chord 6 (5 → 6): the branch retraced
    why = f._returned(back)
    assert "returned onto the states it passed in step 6" in why, why
    # 0.5 above the line u = λ: distance 0.5/√2 = 0.25 of the chord's length √2 > 0.1
    assert f._returned(_state(11, 5.5, 6.0)) == ""
    # just inside the fraction: distance 0.09 × √2 from the chord, off its middle
    d = 0.09 * math.sqrt(2.0)
    n = np.array([1.0, -1.0]) / math.sqrt(2.0)  # unit normal of the line u = λ
    u, lam = np.array([5.5, 5.5]) + d * n
    assert RETURN_FRACTION > 0.09 and f._returned(_state(11, u, lam)) != ""


def test_the_last_chords_are_not_compared():
    """A state on one of the last RETURN_SKIP chords is the path's own neighbourhood."""
    out = [(float(s), float(s)) for s in range(11)]
    f = _follower_on(out)
    u = 10.0 - RETURN_SKIP + 0.5  # on the chord ending RETURN_SKIP - 1 states before the last
    assert f._returned(_state(11, u, u)) == ""
    u = 10.0 - RETURN_SKIP - 0.5  # on the chord before them: compared
    assert f._returned(_state(11, u, u)) != ""


def test_a_path_that_passes_near_in_load_but_far_in_displacement_goes_on():
    """The same λ and probe as an earlier state but another shape (a snapped branch): 2 DOFs,
    the second (the shape) far from the first branch's; never a return."""
    truss = VonMisesTruss(h=0.2, spring=1.0)
    f = _Follower(truss, PathOptions(control="arc-length", until_probe="w1", until_value=1.0),
                  ["w1", "w2"], None)
    f.psi = 1.0
    f.states = [PathState(k, np.array([0.1 * k, 0.0]), 0.1 * k, 1, {}, 0) for k in range(11)]
    assert f._returned(PathState(11, np.array([0.55, 2.0]), 0.55, 1, {}, 0)) == ""
    assert f._returned(PathState(11, np.array([0.55, 0.0]), 0.55, 1, {}, 0)) != ""
