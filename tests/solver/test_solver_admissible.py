"""Inadmissible states: the path must stop where the model's law loses its meaning.

Regression of the fig4 2D reference (bonded sandwich, three-point bending, arc-length to
w_top_mid = −15 mm): the St. Venant–Kirchhoff core under the patch load reached its material
limit point (core crushing, λ_max = 1930.7), the arc-length path followed the crushing branch
correctly past it, then through det F = 0 into states with inverted core elements, where λ
changed sign and ran away to −2741 after 400 steps. Toy with the same feature: a St.
Venant–Kirchhoff bar crushed by a dead load (:class:`solver_toys.SvkBar`, closed form).
"""

import math

import numpy as np
import pytest
from solver_toys import SvkBar

from sandwich.solver import PathOptions, follow_path

TOL = 1e-8


def _run(system, **kw):
    opts = PathOptions(control="arc-length", until_probe="w", until_value=1.5 * system.length,
                       max_steps=300, tol=TOL, **kw)
    return follow_path(system, opts, ["w"])


def test_unguarded_svk_bar_reproduces_the_sign_runaway():
    """Without ``admissible`` the law's own equations lead through s = 0 to λ < 0."""
    system = SvkBar(guard=False)
    result = _run(system)
    lam = np.array([s.load_factor for s in result.states])
    w = np.array([s.probes["w"] for s in result.states])
    assert result.reached_target, result.message
    assert lam[-1] < 0.0 and np.any(system.stretch(w) < 0.0)


def test_path_stops_at_the_admissible_boundary_without_sign_change():
    system = SvkBar()
    result = _run(system, max_increment=0.02)  # steps fine enough to resolve the maximum
    assert not result.reached_target
    assert "inadmissible state: bar inverted" in result.message
    assert "admissible domain" in result.message
    lam = np.array([s.load_factor for s in result.states])
    w = np.array([s.probes["w"] for s in result.states])
    s = system.stretch(w)
    assert np.all(s > 0.0)  # no state with the bar turned inside out
    assert np.all(lam >= 0.0)  # λ never changes sign
    assert np.all(np.diff(w) > 0.0)  # w keeps moving forward through the limit point
    # every state on the closed form (Newton residual bound)
    np.testing.assert_allclose(lam, system.force(w) / system.p_ref, rtol=0,
                               atol=TOL * lam.max())
    # it went up to the boundary (s → 0, λ → 0), not stopped early
    assert s[-1] < 0.02 and lam[-1] < 0.05 * lam.max()
    # exactly one load maximum, at the material limit s = 1/√3 (closed form). It is located
    # within its step (sandwich.solver.extrema): λ(w) of this bar is a cubic, which the cubic
    # Hermite interpolant of the step reproduces, so the located top is the closed form's to
    # round-off, where the extreme state is off by up to the Taylor bound ½ sup|f''| h²
    lam_max = system.ea / (3.0 * math.sqrt(3.0)) / system.p_ref
    assert [lp.kind for lp in result.limit_points] == ["max"]
    lp = result.limit_points[0]
    i = lp.step
    assert lp.located_at is not None and 0.0 < lp.located_at < 1.0
    assert w[i - 1] < lp.probes["w"] < w[i]
    assert lp.load_factor == pytest.approx(lam_max, rel=1e-12)
    assert system.stretch(lp.probes["w"]) == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-9)
    top = int(np.argmax(lam))  # the extreme state: within the Taylor bound, below
    h = max(w[top] - w[top - 1], w[top + 1] - w[top])
    bound = 0.5 * (3.0 * system.ea / system.length**2) * h * h  # sup|f''| = 3 EA s / L² ≤ 3 EA/L²
    assert lam_max - bound <= lam[top] <= lam_max
    assert bound < 0.02 * lam_max
