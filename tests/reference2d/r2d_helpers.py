"""Shared builders for the 2D reference tests: homogeneous strips with hand-placed supports."""

from __future__ import annotations

import numpy as np

from reference2d.constitutive import LayerBand, PlaneStressStiffness, internal_work
from reference2d.loads import edge_facets, edge_load_vector
from reference2d.mesh import build_discretisation
from reference2d.model import probe_vector
from reference2d.system import Reference2DSystem
from sandwich.scene import Material
from r2d_structured import layered_mesh

TOL = 1e-7


def isotropic(E, nu):
    return Material("iso", "isotropic", E, E, E / (2 * (1 + nu)), nu)


def cantilever(length, height, nx, nz, E=1000.0, nu=0.3, width=1.0, load=1.0):
    """Homogeneous cantilever clamped (u = w = 0) on x = 0, uniform shear traction on x = L
    carrying ``load`` N downwards; probe ``w_tip`` at the tip mid-height."""
    mesh = layered_mesh(length, [("core", height, nz)], nx)
    disc = build_discretisation(mesh.points, mesh.cells)
    band = LayerBand("core", -height / 2, height / 2, isotropic(E, nu))
    stiff = PlaneStressStiffness(disc.mesh, [band])
    V = disc.V
    n_local = (V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts) * 2
    X = V.tabulate_dof_coordinates()
    root = np.where(np.abs(X[:, 0]) < TOL)[0]
    bc = np.concatenate([2 * root, 2 * root + 1])
    facets = edge_facets(disc.mesh, lambda x: np.abs(x[0] - length) < TOL)
    f = edge_load_vector(V, facets, (0.0, -load / (height * width)), width, n_local)
    probes = {"w_tip": probe_vector(V, length, band, n_local),
              "u_tip": np.roll(probe_vector(V, length, band, n_local), -1)}
    system = Reference2DSystem(V, lambda u, v: internal_work(u, v, stiff, width), f, bc, [], probes)
    return system
