"""Shape functions (eqs. 11-13): interpolation properties and derivatives.

References: the defining properties of Lagrange and Hermite interpolation (values and slopes at
the ends), and central finite differences of the functions themselves.
"""

import numpy as np
import pytest

from sandwich.beam.dofs import DOF_NAMES, DOF_TABLE, NODE_DOFS, dof, layer_element_dofs
from sandwich.beam.layer_operators import build_layer_operators
from sandwich.beam.shape_functions import x_shape, z_shape

ETA = np.linspace(-1, 1, 21)


def test_dof_table_is_the_papers_order():
    # eq. (8), as transcribed in READING-NOTES
    expected = ("u_tt u_tb w_t w_t,x u_ct u_ct,x u_ct,z u_cb u_cb,x u_cb,z w_ct w_ct,x w_ct,z "
                "w_cb w_cb,x w_cb,z u_bt u_bb w_b w_b,x").split()
    assert list(DOF_NAMES) == expected
    assert NODE_DOFS == 20 and dof("w_b,x") == 19
    with pytest.raises(ValueError):
        dof("w_q")
    assert len(layer_element_dofs("core")) == 24 and len(layer_element_dofs("top")) == 8


def test_lagrange_partition_of_unity_and_nodal_values():
    L0, _ = x_shape("L", 0, ETA)
    L1, _ = x_shape("L", 1, ETA)
    assert np.allclose(L0 + L1, 1)
    assert x_shape("L", 0, -1.0)[0] == 1 and x_shape("L", 0, 1.0)[0] == 0


def test_hermite_nodal_values_and_slopes():
    # H_i: value 1 at η=-1, 0 at η=1, zero slopes; Hbar_i: zero values, slope 1 (in η) at η=-1.
    for node, end, other in ((0, -1.0, 1.0), (1, 1.0, -1.0)):
        v, d = x_shape("H", node, np.array([end, other]))
        assert np.allclose(v, [1, 0]) and np.allclose(d, [0, 0])
        v, d = x_shape("Hbar", node, np.array([end, other]))
        assert np.allclose(v, [0, 0]) and np.allclose(d, [1, 0])
    H0, _ = x_shape("H", 0, ETA)
    H1, _ = x_shape("H", 1, ETA)
    assert np.allclose(H0 + H1, 1)  # the value functions reproduce constants


def test_hermite_reproduces_cubics():
    # p(η) = a + bη + cη² + dη³ is interpolated exactly from its end values and slopes.
    a, b, c, d = 0.3, -1.2, 0.7, 2.1
    p = lambda s: a + b * s + c * s**2 + d * s**3  # noqa: E731
    dp = lambda s: b + 2 * c * s + 3 * d * s**2  # noqa: E731
    interp = (p(-1) * x_shape("H", 0, ETA)[0] + dp(-1) * x_shape("Hbar", 0, ETA)[0]
              + p(1) * x_shape("H", 1, ETA)[0] + dp(1) * x_shape("Hbar", 1, ETA)[0])
    assert np.allclose(interp, p(ETA), atol=1e-14)


@pytest.mark.parametrize("kind", ["L_t", "L_b", "1", "H_t", "H_b", "Hbar_t", "Hbar_b"])
def test_z_derivatives_match_finite_differences(kind):
    h = 1e-6
    _, d = z_shape(kind, ETA[1:-1])
    fd = (z_shape(kind, ETA[1:-1] + h)[0] - z_shape(kind, ETA[1:-1] - h)[0]) / (2 * h)
    assert np.allclose(d, fd, atol=1e-8)


@pytest.mark.parametrize("kind,node", [(k, n) for k in ("L", "H", "Hbar") for n in (0, 1)])
def test_x_derivatives_match_finite_differences(kind, node):
    h = 1e-6
    _, d = x_shape(kind, node, ETA[1:-1])
    fd = (x_shape(kind, node, ETA[1:-1] + h)[0] - x_shape(kind, node, ETA[1:-1] - h)[0]) / (2 * h)
    assert np.allclose(d, fd, atol=1e-8)


def test_core_rows_interpolate_boundary_values_and_physical_slopes():
    # The core's u at (η, ξ) from DOFs set to a known smooth field's nodal data reproduces a field
    # that is cubic in x and z with no twist: u = f(x) g(z) with f, g cubic would need u,xz, so
    # use u = f(x) + g(z), which the no-twist Hermite product represents exactly.
    h, l = 25.0, 8.0
    op = build_layer_operators("core", h, -h / 2, np.eye(3), eta=np.repeat(ETA, 3),
                               xi=np.tile([-1.0, 0.3, 1.0], ETA.size))
    f = lambda x: 0.1 + 0.02 * x - 0.003 * x**2 + 1e-4 * x**3  # noqa: E731
    df = lambda x: 0.02 - 0.006 * x + 3e-4 * x**2  # noqa: E731
    g = lambda z: 0.05 * z + 1e-3 * z**2 - 2e-5 * z**3  # noqa: E731
    dg = lambda z: 0.05 + 2e-3 * z - 6e-5 * z**2  # noqa: E731
    values = np.zeros(40)
    for node, x in ((0, 0.0), (1, l)):
        for side, z in (("t", h / 2), ("b", -h / 2)):
            values[node * 20 + dof(f"u_c{side}")] = f(x) + g(z)
            values[node * 20 + dof(f"u_c{side},x")] = df(x)
            values[node * 20 + dof(f"u_c{side},z")] = dg(z)
    ref = values.copy()
    ref[[i for i in range(40) if DOF_TABLE[i % 20].x_kind == "Hbar"]] *= l / 2
    x = (op.eta + 1) * l / 2
    z = op.xi * h / 2
    u = op.N @ ref[op.dofs]
    assert np.allclose(u, f(x) + g(z), atol=1e-12)
    u_z = (2 / h) * (op.N_xi @ ref[op.dofs])
    assert np.allclose(u_z, dg(z), atol=1e-12)
    u_x = (2 / l) * (op.N_eta @ ref[op.dofs])
    assert np.allclose(u_x, df(x), atol=1e-12)
