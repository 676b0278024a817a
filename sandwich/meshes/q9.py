"""The 9-node quadrilateral (gmsh type 10) geometry: shape functions, Jacobians, areas."""

from __future__ import annotations

import numpy as np

# reference coordinates of the nodes in gmsh order: corners, edge mid-nodes, centre
NODES = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0], [0, 0]],
                 dtype=float)
GAUSS_1D = (np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)]), np.array([5.0, 8.0, 5.0]) / 9.0)


def _lagrange(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1D quadratic Lagrange functions at nodes -1, 0, 1 and their derivatives, (3, n)."""
    n = np.array([0.5 * t * (t - 1), 1 - t**2, 0.5 * t * (t + 1)])
    d = np.array([t - 0.5, -2 * t, t + 0.5])
    return n, d


def shape_gradients(xi: np.ndarray) -> np.ndarray:
    """D N_a / d(xi, eta) at reference points ``xi`` (q, 2): array (q, 9, 2)."""
    nx, dx = _lagrange(xi[:, 0])
    ny, dy = _lagrange(xi[:, 1])
    ix = (NODES[:, 0] + 1).astype(int)
    iy = (NODES[:, 1] + 1).astype(int)
    g = np.empty((len(xi), 9, 2))
    g[:, :, 0] = (dx[ix] * ny[iy]).T
    g[:, :, 1] = (nx[ix] * dy[iy]).T
    return g


def gauss_points() -> tuple[np.ndarray, np.ndarray]:
    """3 x 3 Gauss points (9, 2) and weights (9,) on [-1, 1]^2."""
    t, w = GAUSS_1D
    xi = np.array([[a, b] for b in t for a in t])
    return xi, np.array([wa * wb for wb in w for wa in w])


def jacobian_determinants(points: np.ndarray, cells: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Jacobian determinant of every cell at reference points ``xi``: array (n_cells, q)."""
    g = shape_gradients(xi)  # (q, 9, 2)
    J = np.einsum("cai,qaj->cqij", points[cells], g)  # (c, q, 2 coords, 2 ref)
    return J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]


def cell_areas(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Area of every cell by 3 x 3 Gauss quadrature (exact for these straight-sided cells)."""
    xi, w = gauss_points()
    return jacobian_determinants(points, cells, xi) @ w
