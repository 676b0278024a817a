"""The path follower stops where its path retraces its own branch (``ReturnGuard.retracing``).

A regular equilibrium curve does not come back to a point it passed: RETURN_STATES states in a
row on the chords of steps the path had travelled away from mean it is retracing its branch
(docs/solver.md, "A path that returns onto itself"). Geometry checked on synthetic paths
(reference: point-to-segment distances worked by hand below), in the norm ‖(u, ψλ)‖, ψ = 1.
"""

import math

import numpy as np

from sandwich.solver.path import RETURN_FRACTION, RETURN_STATES, PathState, ReturnGuard


def _dot(a, b):
    return float(a @ b)


def _state(step, u, lam):
    return PathState(step, np.atleast_1d(np.array(u, dtype=float)), lam, 1, {}, 0)


def _path(points):
    """A path so far, ``points``: (u, λ), u a float or a tuple of dofs; and its return guard."""
    return [_state(k, u, lam) for k, (u, lam) in enumerate(points)], ReturnGuard(_dot, 1.0)


def _walk(path, points):
    """Append each (u, λ) as the next state and ask the guard; the reasons, one per state."""
    states, guard = path
    out = []
    for u, lam in points:
        states.append(_state(len(states), u, lam))
        out.append(guard.retracing(states))
    return out


OUT = [(float(s), float(s)) for s in range(11)]  # u = λ = 0 … 10: chords of length √2


def test_three_states_in_a_row_on_the_path_followed_stop_it():
    path = _path(OUT)
    back = [(9.5, 9.5), (8.5, 8.5), (7.5, 7.5), (6.5, 6.5)]
    reasons = _walk(path, back)
    # the first one back lies on the last step, which it has not travelled away from by its
    # length (0.71 of √2): not counted; the next three lie on step 9, 8, 7's chords
    assert RETURN_STATES == 3 and reasons[:3] == ["", "", ""]
    assert "is retracing its own branch" in reasons[3] and "steps 12-14" in reasons[3]


def test_a_single_near_pass_does_not_stop_the_path():
    """One state on an old chord, the next ones 0.25 of a chord's length beside it."""
    path = _path(OUT)
    beside = 0.5  # λ above u by 0.5: distance 0.5/√2 = 0.25 × √2
    reasons = _walk(path, [(9.5, 9.5), (8.5, 8.5 + beside), (7.5, 7.5 + beside), (6.5, 6.5)])
    assert reasons == ["", "", "", ""]


def test_the_fraction_of_the_chord_decides():
    """Within 0.09 of the chord's length: on it; 0.11: beside it."""
    n = np.array([1.0, -1.0]) / math.sqrt(2.0)  # unit normal of the line u = λ
    for offset, stops in ((0.09, True), (0.11, False)):
        path = _path(OUT)
        pts = [tuple(np.array([x, x]) + offset * math.sqrt(2.0) * n)
               for x in (9.5, 8.5, 7.5, 6.5)]
        reasons = _walk(path, pts)
        assert (reasons[-1] != "") is stops, (offset, reasons)
    assert 0.09 < RETURN_FRACTION < 0.11


def test_short_steps_after_a_long_one_are_not_a_return():
    """After a long step, a stall in tiny steps lies on that step's chord without having left
    it: those steps are not compared until the path has travelled their length away."""
    path = _path([(0.0, 0.0), (10.0, 10.0)])  # one long step
    reasons = _walk(path, [(10.0 + 1e-3 * i, 10.0 - 2e-3 * i) for i in range(1, 8)])
    assert reasons == [""] * 7


def test_the_same_load_and_probe_with_another_shape_is_not_a_return():
    """2 DOFs: a snapped branch at the λ and w1 of earlier states, its second DOF elsewhere."""
    path = _path([((0.1 * k, 0.0), 0.1 * k) for k in range(11)])
    assert _walk(path, [((0.55 - 0.1 * i, 2.0), 0.55 - 0.1 * i) for i in range(4)]) == [""] * 4
    path = _path([((0.1 * k, 0.0), 0.1 * k) for k in range(11)])
    assert _walk(path, [((0.95 - 0.1 * i, 0.0), 0.95 - 0.1 * i) for i in range(4)])[-1] != ""
