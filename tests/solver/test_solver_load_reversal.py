"""A path that comes back through zero load: followed through by default, stopped on request.

Toy: one DOF with f(w) = k w (w − 1)(w − 2) under λ P (P = 1): from w = 0 the load rises to a
maximum at w = 1 − 1/√3, falls through λ = 0 at w = 1 (closed form), is negative up to w = 2
and rises again (a snap-through). ``stop_at_load_reversal`` (the beam's ``auto`` reruns) stops
at the first state past w = 1 with λ < 0; by default the path snaps through to its target, and
the message's λ < 0 warning (a sign slip in the target) is not given for a path that carried
positive load before.
"""

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import PathOptions, follow_path


class SnapThrough(ToySystem):
    """``f(w) = k w (w − 1)(w − 2)``."""

    dof_names = ("w",)

    def __init__(self, k: float = 3.0) -> None:
        super().__init__()
        self.k = k

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        w = u[0]
        return np.array([self.k * w * (w - 1.0) * (w - 2.0)])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        w = u[0]
        return np.array([[self.k * (3.0 * w * w - 6.0 * w + 2.0)]])


def _options(**kw):
    return PathOptions(control="arc-length", until_probe="w", until_value=2.6, tol=1e-10,
                       max_steps=400, **kw)


def test_by_default_the_path_snaps_through_zero_load_to_its_target():
    toy = SnapThrough()
    r = follow_path(toy, _options(), ["w"])
    assert r.reached_target, r.message
    lam = [s.load_factor for s in r.states]
    assert min(lam) < 0 < max(lam)  # it did pass through negative load
    w_end = 2.6
    assert lam[-1] == pytest.approx(toy.k * w_end * (w_end - 1) * (w_end - 2), rel=1e-6)
    assert "every load's force is reversed" not in r.message


def test_stop_at_load_reversal_stops_at_the_first_negative_load():
    toy = SnapThrough()
    r = follow_path(toy, _options(stop_at_load_reversal=True), ["w"])
    assert not r.reached_target
    assert "came back through zero load" in r.message, r.message
    assert "every load's force is reversed" not in r.message
    lam = [s.load_factor for s in r.states]
    assert lam[-1] < 0 and all(x >= 0 for x in lam[:-1])
    w = [s.probes["w"] for s in r.states]
    assert w[-2] <= 1.0 < w[-1]  # the crossing λ = 0 lies at w = 1 (closed form)
