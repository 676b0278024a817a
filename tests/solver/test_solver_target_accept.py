"""A crossed stopping target that cannot be hit within ``target_tol``.

``PathOptions.target_accept`` (default 1e-3, relative): when the step that crosses the target
cannot be shortened onto it (every shortened corrector fails), the closest converged state is
accepted as reaching the target if it misses by at most ``target_accept``, and the message says
by how much; otherwise the run stops, keeps its states and says why. Toy: a linear spring
``f = k w`` (closed form ``w = λ P / k``) whose states in a band around the target are declared
inadmissible, so that regula falsi's shortened steps near the target are all refused.
"""

import numpy as np
from solver_toys import ToySystem

from sandwich.solver import PathOptions, follow_path


class BlindSpring(ToySystem):
    """``f(w) = k w``; states with ``|w − target| < band`` are inadmissible."""

    dof_names = ("w",)

    def __init__(self, target: float, band: float, k: float = 2.0) -> None:
        super().__init__()
        self.target, self.band, self.k = target, band, k

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.k * u

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[self.k]])

    def admissible(self, u: np.ndarray) -> str:
        return "blind spot" if abs(u[0] - self.target) < self.band else ""


def _run(system: BlindSpring, increment: float):
    # load control with a fixed increment: λ = increment · n, w = λ / k; the step that crosses
    # w = target overshoots it by a known amount
    opts = PathOptions(control="load", until_probe="w", until_value=system.target,
                       initial_increment=increment, max_increment=increment, tol=1e-10)
    return follow_path(system, opts, ["w"])


def test_target_missed_within_target_accept_is_accepted_and_said():
    system = BlindSpring(target=0.5, band=2e-4)
    # λ steps of 0.2502: w = 0.1251, 0.2502, 0.3753, 0.5004 — crosses 0.5 by 8e-4 relative
    result = _run(system, 0.2502)
    w = np.array([s.probes["w"] for s in result.states])
    lam = np.array([s.load_factor for s in result.states])
    assert result.reached_target, result.message
    assert "not within target_tol" in result.message
    miss = abs(w[-1] - 0.5) / 0.5
    assert 1e-6 < miss <= 1e-3  # hit within target_accept, not within target_tol
    assert f"{miss:.1e}" in result.message  # the message says by how much
    assert np.all(np.abs(w - 0.5) >= 2e-4)  # no refused (blind) state was kept
    np.testing.assert_allclose(w, lam / system.k, rtol=1e-9)  # every state on the closed form


def test_target_missed_beyond_target_accept_stops_and_keeps_the_states():
    system = BlindSpring(target=0.5, band=2e-3)  # nothing within 4e-3 relative is admissible
    result = _run(system, 0.26)  # w = 0.13, 0.26, 0.39, 0.52: crosses by 4 %
    w = np.array([s.probes["w"] for s in result.states])
    assert not result.reached_target
    assert "could not be hit" in result.message
    assert len(result.states) >= 4  # state 0 and the three steps before the crossing at least
    assert np.all(np.abs(w - 0.5) >= 2e-3)
    np.testing.assert_allclose(w[:4], [0.0, 0.13, 0.26, 0.39], rtol=1e-9)


def test_default_target_accept_is_small():
    """The fallback must not turn a clear miss into "reached": 0.1 % at most by default."""
    assert PathOptions().target_accept <= 1e-3
