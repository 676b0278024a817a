"""Debond contact: a closed debond transmits the bonded normal response, an open one nothing;
Newton converges quadratically with contact active."""

import numpy as np
import pytest
from r2d_helpers import pressed_strip

from sandwich.plane2d.newton import newton

pytestmark = pytest.mark.dolfinx

PRESSURE = 2.0  # MPa on a strip of E = 100 MPa: 2 % strain, well into the nonlinear range


def _solve(system, lam_final, steps=4):
    u = np.zeros(system.size)
    logs = []
    for lam in np.linspace(lam_final / steps, lam_final, steps):
        res = newton(system, u, lam, tol=1e-10, max_iterations=25)
        assert res.converged, res.residuals
        logs.append(res.residuals)
        u = res.u
    system.commit(u, lam_final)
    return u, logs


def test_closed_debond_gives_the_bonded_normal_response():
    bonded, _ = pressed_strip(False, PRESSURE)
    cut, pairs = pressed_strip(True, PRESSURE)
    assert len(pairs) == 1 and len(pairs[0].slave) == 19
    ub, _ = _solve(bonded, 1.0)
    uc, _ = _solve(cut, 1.0)
    wb = bonded.probe_vector("w_top_mid") @ ub
    wc = cut.probe_vector("w_top_mid") @ uc
    state = cut.last_contact[0]
    print(f"bonded w = {wb:.6g}, debonded w = {wc:.6g}, p = {state.pressure.min():.5g}.."
          f"{state.pressure.max():.5g}, max penetration {-state.gap.min():.3g}")
    assert np.all(state.pressure > 0)  # every lip node in contact
    # pressure transmitted as in the bonded strip (the applied dead load, to 0.3 %)
    assert state.pressure == pytest.approx(PRESSURE, rel=3e-3)
    # penetration within 1e-3 × face thickness, and the deflection is the bonded one up to it
    assert -state.gap.min() <= 1e-3 * 0.5
    assert wc == pytest.approx(wb, abs=2 * -state.gap.min() + 1e-9 * abs(wb))


def test_opening_debond_carries_no_pressure():
    cut, _ = pressed_strip(True, -PRESSURE)  # suction on the top edge lifts the face lip
    _solve(cut, 1.0)
    state = cut.last_contact[0]
    print(f"gaps {state.gap.min():.4g}..{state.gap.max():.4g}")
    assert np.all(state.pressure == 0.0)
    assert state.gap.max() > 1e-3  # it did open
    assert np.all(state.gap >= 0.0)


def test_newton_converges_quadratically_with_contact_active():
    cut, _ = pressed_strip(True, PRESSURE)
    _, logs = _solve(cut, 1.0, steps=2)
    r = np.array(logs[-1])
    print("residual norms of the last step:", " ".join(f"{x:.3e}" for x in r))
    assert len(cut.last_contact[0].rows) == 19
    # quadratic: log r_{k+1} ≈ 2 log r_k (relative to the load), over the iterations above
    # the round-off floor
    rel = r / r[0]
    big = [i for i in range(1, len(rel) - 1) if rel[i] < 1e-2 and rel[i + 1] > 1e-13]
    assert big, rel
    for i in big:
        assert np.log(rel[i + 1]) / np.log(rel[i]) > 1.8


# Open mouth: a debond reaching the beam end (x = 0 here) has no crack tip there; the end lip
# node is a slave with the one-sided Simpson weight h/6 and a one-sided master chord. Reference:
# the same strip bonded (a closed crack transmits the normal load unchanged, as in the tests
# above) and the applied pressure (uniform, so every lip node must carry it).
MOUTH = (0.0, 6.0)


def test_open_mouth_weights_integrate_the_lip_length():
    _, pairs = pressed_strip(True, PRESSURE, span=MOUTH)
    (pair,) = pairs
    assert len(pair.slave) == 12  # x = 0 (mouth corner) … 5.5; x = 6 is the tip
    assert pair.weight.sum() == pytest.approx(6.0 - 1.0 / 6.0)  # tip's h/6 is bonded
    i0 = int(np.argmin(pair.x_ref))
    assert pair.x_ref[i0] == 0.0 and pair.weight[i0] == pytest.approx(1.0 / 6.0)


def test_closed_open_mouth_debond_gives_the_bonded_normal_response():
    bonded, _ = pressed_strip(False, PRESSURE)
    cut, _ = pressed_strip(True, PRESSURE, span=MOUTH)
    ub, _ = _solve(bonded, 1.0)
    uc, _ = _solve(cut, 1.0)
    state = cut.last_contact[0]
    print(f"p = {state.pressure.min():.5g}..{state.pressure.max():.5g}, "
          f"penetration {-state.gap.min():.3g}")
    assert np.all(state.pressure > 0)  # the mouth node included
    assert state.pressure == pytest.approx(PRESSURE, rel=3e-3)
    assert -state.gap.min() <= 1e-3 * 0.5
    def top_edge_w(system, u):  # w along the loaded edge, by x (the two meshes number apart)
        X = system.x_ref
        top = np.where(np.abs(X[:, 1] - 2.5) < 1e-7)[0]
        top = top[np.argsort(X[top, 0])]
        return X[top, 0], u[2 * top + 1]

    xb, wb = top_edge_w(bonded, ub)
    xc, wc = top_edge_w(cut, uc)
    assert np.array_equal(xb, xc)
    assert np.max(np.abs(wc - wb)) <= 2 * -state.gap.min() + 1e-9 * np.max(np.abs(wb))


def test_opening_open_mouth_debond_carries_no_pressure():
    cut, _ = pressed_strip(True, -PRESSURE, span=MOUTH)
    _solve(cut, 1.0)
    state = cut.last_contact[0]
    print(f"gaps {state.gap.min():.4g}..{state.gap.max():.4g}")
    assert np.all(state.pressure == 0.0)
    assert np.all(state.gap >= 0.0) and state.gap.max() > 1e-3


def test_windows_slid_out_of_are_widened_and_the_matrix_rebuilt_without_changing_the_answer():
    # reference: the same strip with the default windows (no widening needed)
    wide, _ = pressed_strip(True, PRESSURE)
    narrow, _ = pressed_strip(True, PRESSURE, empty_windows=True)
    uw, logs_w = _solve(wide, 1.0, steps=2)
    un, logs_n = _solve(narrow, 1.0, steps=2)
    assert wide.counters["pattern_growths"] == 0
    assert narrow.counters["pattern_growths"] >= 1
    assert [len(r) for r in logs_n] == [len(r) for r in logs_w]
    assert np.allclose(un, uw, rtol=1e-9, atol=1e-12 * np.abs(uw).max())
