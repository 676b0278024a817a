"""The ``face_membrane="averaged"`` option (not the paper's element; see docs/comparisons.md).

References: central finite differences of the force and of the energy (consistency of the
tangent), the closed-form element mean of ½ w,x² (definition of the assumed strain), and the
paper's element (identical linear stiffness: the option changes only the ½ w,x² term).
"""

import numpy as np
import pytest
from beam_scenes import KEVLAR, assert_layer_derivatives  # noqa: I001

from sandwich.beam.constitutive import face_stiffness
from sandwich.beam.dofs import DOF_TABLE
from sandwich.beam.element import layer_energy, layer_response
from sandwich.beam.layer_operators import build_layer_operators
from sandwich.beam.quadrature import EXACT_ORDER

C = face_stiffness(KEVLAR)


def _op(average):
    return build_layer_operators("top", 0.5, 0.0, C, gauss=EXACT_ORDER["top"],
                                 membrane_average=average)


def test_averaged_face_tangent_and_force_match_finite_differences():
    rng = np.random.default_rng(7)
    op = _op(True)
    lengths = np.array([4.0, 9.0, 2.5])
    u = rng.normal(size=(3, 40)) * 0.5
    f, K = assert_layer_derivatives(op, u, lengths)
    # and it differs from the paper's element at this state (the option does something)
    f_paper, _ = layer_response(_op(False), u, lengths, 60.0, tangent=False)
    assert np.max(np.abs(f - f_paper)) > 1e-3 * np.max(np.abs(f))


def test_averaged_strain_is_the_element_mean_of_half_w_x_squared():
    # w = a x² + b x³ on an element of length l, u = 0: ε̄_x = (1/l) ∫ ½ w,x² dx (closed form).
    l, a, b = 3.0, 0.02, -0.004
    names = [d.name for d in DOF_TABLE]
    u = np.zeros((1, 40))
    for node, x in ((0, 0.0), (1, l)):
        u[0, 20 * node + names.index("w_t")] = a * x**2 + b * x**3
        u[0, 20 * node + names.index("w_t,x")] = 2 * a * x + 3 * b * x**2
    xs = np.linspace(0, l, 200001)
    e = 0.5 * (2 * a * xs + 3 * b * xs**2) ** 2  # ε_x = ½ w,x² (u = 0), the same at every z
    # γ = w,x is the same in both elements, so the energies differ only in the ε_x part:
    # ½ E b h l (mean(e)² − mean(e²)) (averaged minus pointwise, closed form up to sampling).
    volume = l * 0.5 * 60.0
    expected = 0.5 * C[0, 0] * volume * (np.mean(e) ** 2 - np.mean(e**2))
    U = layer_energy(_op(True), u, np.array([l]), 60.0)[0]
    U_paper = layer_energy(_op(False), u, np.array([l]), 60.0)[0]
    assert expected < 0
    assert U - U_paper == pytest.approx(expected, rel=1e-4)


def test_averaged_face_has_the_paper_linear_stiffness():
    op_a, op_p = _op(True), _op(False)
    lengths = np.array([2.0, 5.0])
    u0 = np.zeros((2, 40))
    _, Ka = layer_response(op_a, u0, lengths, 60.0)
    _, Kp = layer_response(op_p, u0, lengths, 60.0)
    assert np.max(np.abs(Ka - Kp)) < 1e-12 * np.max(np.abs(Kp))
