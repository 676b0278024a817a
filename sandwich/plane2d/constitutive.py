"""Green–Lagrange kinematics and the orthotropic plane-stress St Venant–Kirchhoff law (eqs. 26-27).

Coordinates are (x, z); the mesh's second coordinate is z. One kinematic quantity per line.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem

from sandwich.scene import Material


@dataclass
class LayerBand:
    """A layer as the 2D model sees it: the band z_lo <= z <= z_hi (mm) and its material."""

    name: str
    z_lo: float
    z_hi: float
    material: Material


def deformation_gradient(u):
    """F = I + ∇u."""
    return ufl.Identity(2) + ufl.grad(u)


def green_lagrange(u):
    """E = (FᵀF − I)/2, eq. (26a): E_xx = ε_x, E_zz = ε_z, 2 E_xz = γ.

    Evaluated as (H + Hᵀ + HᵀH)/2 with H = ∇u, the same tensor without forming FᵀF ≈ I and
    subtracting I: that cancellation costs ~1e-16 absolute strain, i.e. relative errors of 1e-12
    at the 1e-4 strains of a sandwich face, and set a residual floor of ~1e-8 × the load on the
    compliant cantilever scenes (fig7), right at Newton's tolerance.
    """
    H = ufl.grad(u)
    return 0.5 * (H + H.T + H.T * H)


class PlaneStressStiffness:
    """Cell-wise (DG0) plane-stress stiffnesses Q_x, Q_z, Q, G_zx of eq. (27), one layer per cell.

    A cell belongs to the layer containing its centroid's z.
    """

    def __init__(self, mesh, bands: list[LayerBand]):
        Q0 = fem.FunctionSpace(mesh, ("DG", 0))
        self.Qx, self.Qz, self.Q, self.G = (fem.Function(Q0) for _ in range(4))
        n = mesh.topology.index_map(2).size_local + mesh.topology.index_map(2).num_ghosts
        z_mid = cell_centroids(mesh, n)[:, 1]
        self.layer_index = np.full(n, -1, dtype=np.int32)
        for k, band in enumerate(bands):
            inside = (z_mid > band.z_lo) & (z_mid < band.z_hi)
            self.layer_index[inside] = k
        if np.any(self.layer_index < 0):
            raise ValueError("a cell lies outside every layer band (mesh and scene disagree)")
        for f, attr in ((self.Qx, "Qx"), (self.Qz, "Qz"), (self.Q, "Q"), (self.G, "Gzx")):
            vals = np.array([getattr(b.material, attr) for b in bands])
            f.x.array[:n] = vals[self.layer_index]

    def pk2(self, E):
        """Second Piola–Kirchhoff stress S = C : E, eq. (26b)."""
        S_xx = self.Qx * E[0, 0] + self.Q * E[1, 1]  # σ_x = Q_x ε_x + Q ε_z
        S_zz = self.Qz * E[1, 1] + self.Q * E[0, 0]  # σ_z = Q_z ε_z + Q ε_x
        S_xz = self.G * 2.0 * E[0, 1]  # τ = G_zx γ
        return ufl.as_matrix([[S_xx, S_xz], [S_xz, S_zz]])


def cell_centroids(mesh, n_cells: int) -> np.ndarray:
    """Mean of the geometry nodes of each of the first ``n_cells`` cells."""
    x = mesh.geometry.x
    dm = mesh.geometry.dofmap
    return np.array([x[dm.links(c), :2].mean(axis=0) for c in range(n_cells)])


def internal_work(u, v, stiffness: PlaneStressStiffness, width: float):
    """B ∫ (F S) : ∇v dx — the internal virtual work (first Piola–Kirchhoff P = F S)."""
    S = stiffness.pk2(green_lagrange(u))
    P = S + ufl.grad(u) * S  # = F S, without the rounding of I + ∇u
    return width * ufl.inner(P, ufl.grad(v)) * ufl.dx
