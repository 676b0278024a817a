"""Limit points and bifurcations read off a computed equilibrium path.

- A *limit point* is a local extremum of λ along the path. The states show it where the
  increments Δλ before and after a state have opposite signs (zero increments are skipped);
  the path follower locates it within the step before or after that state from the load
  curve's slopes (:mod:`sandwich.solver.extrema`, a state's ``extremum``; in a step that
  jumped a snap — a probe rescue, or an arc step whose corrector moved far — by walking the
  branch it left to its end: :meth:`sandwich.solver.path.PathFollower.walk_branch_left`), and it
  is reported
  there: ``located_at`` the fraction of that step's probe change, ``between`` that step's two
  load factors. Without a located one it is reported at the extreme state (exact only to the
  step resolution: the two increments' loads are its ``between``). An extremum located inside
  a step whose states do not show it (both sides of the top on one step and no state beyond)
  is reported as well.
- A *bifurcation* is a change of the tangent's negative-pivot count between two successive states
  that is not explained by a limit point: a simple limit point changes the count by one between
  the state before and the state after it; any further change (or a change with no limit point
  next to it) is a bifurcation on that step (located within it, below).

Each point carries ``between``: the load factors of the two converged states that enclose it
along the path (its step's states; an extremum not located: the states either side of it),
so a user sees to what resolution the path sampled it. A bifurcation whose state
carries a ``crossing`` (located within its step by the path follower:
:meth:`sandwich.solver.path.PathFollower.locate_crossing`) is reported there instead: its load
factor and probes are the located point's, ``between`` the bracket it was located in (the
step's states, or equilibria solved inside the step), ``located_at`` its fraction of the step.
Without one (a change of the count shared with a limit point, a location that failed, states
from elsewhere) it is reported at the first state with the new count. A narrowed step whose
equilibria inside rise above both of its states (or fall below) had a load maximum (minimum)
there that the states did not sample: the point is then reported as that ``"max"``
(``"min"``), at the crossing.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from sandwich.results import LimitPoint

__all__ = ["find_limit_points"]


class _State(Protocol):
    step: int
    load_factor: float
    probes: dict[str, float]
    negative_pivots: int | None


def _located_extremum(states: Sequence[_State], steps: Sequence[int], kind: str,
                      extreme: float) -> int | None:
    """The state among ``steps`` whose step has a located extremum of ``kind`` (the top one).

    Only one at or beyond the extreme state's load ``extreme``: a top found by walking the
    branch a step left lies below the states after it where the path regained more (it is
    another, earlier extremum, reported in its own step).
    """
    sign = 1.0 if kind == "max" else -1.0
    found = [m for m in steps if 0 < m < len(states)
             and (e := getattr(states[m], "extremum", None)) is not None and e.kind == kind
             and sign * e.load_factor >= sign * extreme]
    if not found:
        return None
    return max(found, key=lambda m: sign * states[m].extremum.load_factor)


def _from_extremum(state: _State) -> LimitPoint:
    e = state.extremum
    return LimitPoint(e.kind, state.step, float(e.load_factor), dict(e.probes),
                      tuple(map(float, e.between)), float(e.fraction))


def _position(lp: LimitPoint) -> float:
    """Where a point lies along the path, in steps (a located one inside its step)."""
    return lp.step - 1 + lp.located_at if lp.located_at is not None else float(lp.step)


def find_limit_points(states: Sequence[_State]) -> list[LimitPoint]:
    """Return the limit points and bifurcations along ``states`` (ordered along the path).

    The order is by position along the path: a point located within step k lies at
    k − 1 + its fraction of the step, one reported at state k at k.
    """
    n = len(states)
    if n < 2:
        return []
    lam = np.array([s.load_factor for s in states], dtype=float)
    dlam = np.diff(lam)
    found: list[LimitPoint] = []
    limit_at: set[int] = set()
    taken: set[int] = set()  # states whose located extremum is reported
    nz = np.flatnonzero(dlam != 0.0)  # increment j goes from state j to state j + 1
    for j0, j1 in zip(nz[:-1], nz[1:], strict=True):
        if np.sign(dlam[j0]) != np.sign(dlam[j1]):
            k = int(j0) + 1  # the extreme state ends the first increment
            kind = "max" if dlam[j0] > 0 else "min"
            s = states[k]
            after = int(j1) + 1  # the state that ends the next non-zero increment
            limit_at.add(k)
            m = _located_extremum(states, (k, after), kind, float(lam[k]))
            if m is not None and m not in taken:  # located within the step before or after k
                taken.add(m)
                found.append(_from_extremum(states[m]))
                continue
            found.append(LimitPoint(kind, s.step, float(s.load_factor), dict(s.probes),
                                    (float(lam[int(j0)]), float(lam[after]))))
    for m in range(1, n):  # located inside a step whose states do not show it
        if m not in taken and getattr(states[m], "extremum", None) is not None:
            taken.add(m)
            limit_at.add(m)
            found.append(_from_extremum(states[m]))
    used: set[int] = set()
    for k in range(1, n):
        a, b = states[k - 1].negative_pivots, states[k].negative_pivots
        if a is None or b is None or a == b:
            continue
        change = abs(b - a)
        for m in (k - 1, k):  # a limit point at either end of this step explains one change
            if change and m in limit_at and m not in used:
                used.add(m)
                change -= 1
        if change:
            s = states[k]
            c = getattr(s, "crossing", None)
            if c is not None and change == abs(b - a):  # located, no limit point shares it
                found.append(LimitPoint(c.kind, s.step, float(c.load_factor), dict(c.probes),
                                        tuple(map(float, c.between)), float(c.fraction)))
            else:
                found.append(LimitPoint("bifurcation", s.step, float(s.load_factor),
                                        dict(s.probes), (float(lam[k - 1]), float(lam[k]))))
    found.sort(key=_position)
    return found
