"""Manufactured solution for the nonlinear (Green strain, St Venant–Kirchhoff) operator."""

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from petsc4py import PETSc
from r2d_helpers import isotropic
from r2d_structured import layered_mesh

from sandwich.plane2d.constitutive import (
    LayerBand,
    PlaneStressStiffness,
    deformation_gradient,
    green_lagrange,
    internal_work,
)
from sandwich.plane2d.mesh import build_discretisation
from sandwich.plane2d.newton import newton
from sandwich.plane2d.system import Reference2DSystem

pytestmark = pytest.mark.dolfinx

L, H, WIDTH = 2.0, 1.0, 1.0
AMP = 0.08  # large enough that the quadratic strain terms matter (|∇u| up to ~0.3)


def _u_exact(x):
    s = ufl.sin(np.pi * x[0] / L) * ufl.sin(np.pi * (x[1] + H / 2) / H)
    return ufl.as_vector([AMP * s * (1 + x[0]), AMP * s * ufl.cos(x[0])])


def _errors(n):
    mesh = layered_mesh(L, [("core", H, n)], 2 * n)
    disc = build_discretisation(mesh.points, mesh.cells)
    V = disc.V
    band = LayerBand("core", -H / 2, H / 2, isotropic(100.0, 0.3))
    stiff = PlaneStressStiffness(disc.mesh, [band])
    x = ufl.SpatialCoordinate(disc.mesh)
    ue = _u_exact(x)
    P = deformation_gradient(ue) * stiff.pk2(green_lagrange(ue))  # first Piola–Kirchhoff
    body = -ufl.div(P)
    v = ufl.TestFunction(V)
    dx = ufl.dx(metadata={"quadrature_degree": 8})
    b = fem_petsc.assemble_vector(fem.form(WIDTH * ufl.inner(body, v) * dx))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    X = V.tabulate_dof_coordinates()
    edge = np.where((np.abs(X[:, 0]) < 1e-9) | (np.abs(X[:, 0] - L) < 1e-9)
                    | (np.abs(np.abs(X[:, 1]) - H / 2) < 1e-9))[0]
    bc = np.concatenate([2 * edge, 2 * edge + 1])
    s = Reference2DSystem(V, lambda u, w: internal_work(u, w, stiff, WIDTH), b.array, bc, [], {})
    u = np.zeros(s.size)
    for lam in np.linspace(0.125, 1.0, 8):
        res = newton(s, u, lam, tol=1e-12)
        assert res.converged, res.residuals
        u = res.u
    s.u.x.array[:] = u
    e = s.u - ue
    l2 = np.sqrt(fem.assemble_scalar(fem.form(ufl.inner(e, e) * dx)))
    h1 = np.sqrt(fem.assemble_scalar(fem.form(ufl.inner(ufl.grad(e), ufl.grad(e)) * dx)))
    return H / n, l2, h1


def test_observed_rates_are_those_of_quadratic_elements():
    data = np.array([_errors(n) for n in (2, 4, 8, 16)])
    h, l2, h1 = data.T
    rate_l2 = np.polyfit(np.log(h[1:]), np.log(l2[1:]), 1)[0]
    rate_h1 = np.polyfit(np.log(h[1:]), np.log(h1[1:]), 1)[0]
    print(f"h = {h}, L2 = {l2}, H1 = {h1}, rates L2 {rate_l2:.3f}, H1 {rate_h1:.3f}")
    assert 2.8 < rate_l2 < 3.3
    assert 1.85 < rate_h1 < 2.3
