"""One Newton correction (``sandwich.solver.newton.newton_step``): the linearised answer.

References: the closed-form derivatives of the von Mises truss (``solver_toys``): Newton's iterate
w₁ = w₀ − (f(w₀) − λP) / f'(w₀) under load control; with the spring-linked second DOF held by a
probe, the iterate's probe is the target exactly (the constraint is linear) and its load factor
follows from the 2×2 linear system written out by hand.
"""

import numpy as np
import pytest
from solver_toys import VonMisesTruss

from sandwich.solver.controls import LoadConstraint, ProbeConstraint
from sandwich.solver.newton import newton_step


def test_one_correction_under_load_control_is_newtons_iterate():
    truss = VonMisesTruss()
    w0, lam = 0.05, 20.0
    step = newton_step(truss, np.array([w0]), lam, LoadConstraint(lam))
    f0, k0 = float(truss.bar_force(w0)), float(truss.bar_stiffness(w0))
    w1 = w0 - (f0 - lam) / k0
    assert step.u[0] == pytest.approx(w1, rel=1e-12)
    assert step.load_factor == lam
    assert step.residual_before == pytest.approx(abs(f0 - lam), rel=1e-12)
    assert step.residual_after == pytest.approx(abs(float(truss.bar_force(w1)) - lam), rel=1e-12)
    # quadratic phase: the residual left is about f''/(2 f'²) times the square of the first
    r0 = f0 - lam
    second_order = abs(float(truss.bar_curvature(w0))) / (2 * k0**2) * r0**2
    assert step.residual_after == pytest.approx(second_order, rel=0.05)
    assert step.contraction == pytest.approx(step.residual_after / step.residual_before)


def test_one_correction_holds_a_probe_and_solves_for_the_load():
    ks = 500.0
    truss = VonMisesTruss(spring=ks)
    u0, lam0, target = np.array([0.02, 0.05]), 10.0, 0.06
    c = truss.probe_vector("w2")
    step = newton_step(truss, u0, lam0, ProbeConstraint(c, target))
    # by hand: K [δw1, δw2] = λ1 e2 − f(u0), δw2 = target − w2(0)
    f = truss.internal_force(u0)
    k = float(truss.bar_stiffness(u0[0]))
    d2 = target - u0[1]
    d1 = (-f[0] + ks * d2) / (k + ks)  # first row: (k + ks) δw1 − ks δw2 = −f1
    lam1 = f[1] - ks * d1 + ks * d2  # second row: −ks δw1 + ks δw2 = λ1 − f2
    assert step.u[1] == pytest.approx(target, rel=1e-13)
    assert step.u[0] == pytest.approx(u0[0] + d1, rel=1e-12)
    assert step.load_factor == pytest.approx(lam1, rel=1e-12)


def test_a_linear_system_is_settled_by_one_correction():
    class Grounded(VonMisesTruss):
        def internal_force(self, u):
            return super().internal_force(u) + np.array([100.0 * u[0], 0.0])

        def tangent(self, u):
            return super().tangent(u) + np.diag([100.0, 0.0])

    grounded = Grounded(ea=0.0, spring=200.0)  # bars without stiffness: two linear springs
    step = newton_step(grounded, np.zeros(2), 3.0, LoadConstraint(3.0))
    assert step.residual_before == pytest.approx(3.0)
    assert step.residual_after <= 1e-12 * step.residual_before
    # closed form: springs in series, 3 / 100 at w1 and 3 / 100 + 3 / 200 at w2
    assert step.u == pytest.approx([0.03, 0.045], rel=1e-12)


def test_a_singular_tangent_gives_no_correction():
    truss = VonMisesTruss(ea=0.0)  # no stiffness at all: K = 0
    assert newton_step(truss, np.array([0.0]), 1.0, LoadConstraint(1.0)) is None
