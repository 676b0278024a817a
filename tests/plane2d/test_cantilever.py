"""Homogeneous cantilevers: linear limit vs beam theory, large deflection vs the elastica."""

import pytest
from r2d_elastica import elastica_tip
from r2d_helpers import cantilever

from sandwich.solver.path import PathOptions, follow_path, solve_linear

pytestmark = pytest.mark.dolfinx

E, NU, B = 1000.0, 0.3, 1.0
G = E / (2 * (1 + NU))


def _beam_theory(P, L, h):
    I = B * h**3 / 12
    eb = P * L**3 / (3 * E * I)
    return eb, eb + P * L / (5 / 6 * G * B * h)  # Euler–Bernoulli, Timoshenko (κ = 5/6)


def test_slender_cantilever_linear_limit_matches_euler_bernoulli():
    L, h, P = 100.0, 2.0, 1e-3
    s = cantilever(L, h, nx=50, nz=2, E=E, nu=NU, width=B, load=1.0)
    w = -s.probe_vector("w_tip") @ solve_linear(s, P)
    eb, timo = _beam_theory(P, L, h)
    print(f"L/h = 50: w = {w:.6g}, EB {eb:.6g}, Timoshenko {timo:.6g}")
    assert w == pytest.approx(timo, rel=2e-3)
    assert w == pytest.approx(eb, rel=2e-3)


def test_stocky_cantilever_shows_the_shear_correction():
    L, h, P = 20.0, 2.0, 1e-3
    s = cantilever(L, h, nx=40, nz=8, E=E, nu=NU, width=B, load=1.0)
    w = -s.probe_vector("w_tip") @ solve_linear(s, P)
    eb, timo = _beam_theory(P, L, h)
    print(f"L/h = 10: w = {w:.6g}, EB {eb:.6g}, Timoshenko {timo:.6g}")
    # shear adds 0.78 % to Euler–Bernoulli here; the 2D solution sees most of it (its clamped
    # section cannot warp, which stiffens it slightly against Timoshenko's)
    assert w > eb * 1.004
    assert w == pytest.approx(timo, rel=4e-3)


@pytest.mark.parametrize("alpha", [1.0, 3.0, 5.0])
def test_large_deflection_matches_the_elastica(alpha):
    L, h = 100.0, 2.0
    EI = E * B * h**3 / 12
    s = cantilever(L, h, nx=50, nz=2, E=E, nu=NU, width=B, load=1.0)
    P = alpha * EI / L**2
    res = follow_path(s, PathOptions(control="load", until_load_factor=P, tol=1e-8,
                                     max_steps=100), ["w_tip", "u_tip"])
    assert res.reached_target, res.message
    last = res.states[-1]
    dv, dh, _ = elastica_tip(alpha)
    w, u = -last.probes["w_tip"] / L, -last.probes["u_tip"] / L
    print(f"α = {alpha}: 2D w/L = {w:.5f} u/L = {u:.5f}; elastica {dv:.5f} {dh:.5f}, "
          f"{len(res.states) - 1} steps")
    assert w == pytest.approx(dv, rel=1e-3)
    assert u == pytest.approx(dh, rel=2e-3)
