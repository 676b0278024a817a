"""Probe rescue: where the arc collapses, one step under control of the until probe.

``PathOptions.probe_rescue`` (default on, arc-length with an ``until_probe``): a failed step cut
below ``RESCUE_FRACTION`` of the largest increment so far is retried once as a step of the
probe, as long as its largest recent change, towards the target. Needed by the beam on fig. 6
(240 elements): at the debonded face's buckling the arc shrank to 1e-4 and turned back down the
loading branch through λ = 0. Toy: a linear spring ``f = k w`` (closed form ``λ = k w``) whose
states in a band of w are declared inadmissible, so that no arc can land beyond it unless one
step jumps it; the probe step does.
"""

import numpy as np
from solver_toys import ToySystem

from sandwich.solver import PathOptions, follow_path


class GappedSpring(ToySystem):
    """``f(w) = k w``; states with ``lo < w < hi`` are inadmissible."""

    dof_names = ("w",)

    def __init__(self, lo: float, hi: float, k: float = 2.0) -> None:
        super().__init__()
        self.lo, self.hi, self.k = lo, hi, k

    def internal_force(self, u):
        return self.k * u

    def tangent(self, u):
        return np.array([[self.k]])

    def admissible(self, u):
        return "gap" if self.lo < u[0] < self.hi else ""


def _run(rescue: bool):
    system = GappedSpring(lo=0.50, hi=0.56)
    opts = PathOptions(control="arc-length", until_probe="w", until_value=1.0, tol=1e-10,
                       initial_increment=0.15, max_increment=0.15, probe_rescue=rescue)
    return system, follow_path(system, opts, ["w"])


def test_the_rescue_steps_over_a_band_no_arc_can_cross():
    system, result = _run(rescue=True)
    w = np.array([s.probes["w"] for s in result.states])
    lam = np.array([s.load_factor for s in result.states])
    assert result.reached_target, result.message
    assert "under control of w" in result.message
    assert abs(w[-1] - 1.0) <= 1e-6
    assert not np.any((w > 0.50) & (w < 0.56))  # no refused state was kept
    assert np.all(np.diff(w) > 0)  # forward only
    np.testing.assert_allclose(lam, system.k * w, rtol=1e-9)  # every state on the closed form


def test_without_the_rescue_the_same_path_stops_and_says_why():
    _, result = _run(rescue=False)
    w = np.array([s.probes["w"] for s in result.states])
    assert not result.reached_target
    assert "min_increment" in result.message
    assert w[-1] <= 0.50
