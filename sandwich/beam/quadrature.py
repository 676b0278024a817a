"""Gauss-Legendre rules along x and through each layer, and the orders that are exact.

With St Venant-Kirchhoff materials and polynomial shape functions the strain energy is a
polynomial on the reference element, so a tensor Gauss rule of high enough order integrates it —
hence the internal force and the tangent — exactly. Degrees of the energy density:

- core: u, w cubic in η and in ξ; ε_z = w,z + (u,z² + w,z²)/2 has degree 6 in η and ε_x degree 6
  in ξ, so the energy has degree 12 in each: 7 points in η and ξ;
- faces: w Hermite-cubic in η, u linear in η and ξ; ε_x = u,x + (u,x² + w,x²)/2 has degree 4 in η
  and 2 in ξ, so the energy has degree 8 and 4: 5 points in η, 3 in ξ.
"""

from __future__ import annotations

import numpy as np

EXACT_ORDER: dict[str, tuple[int, int]] = {"top": (5, 3), "core": (7, 7), "bottom": (5, 3)}


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights of the n-point Gauss-Legendre rule on [−1, 1]."""
    if not isinstance(n, int | np.integer) or n < 1:
        raise ValueError(f"Gauss order must be a positive integer, got {n!r}")
    return np.polynomial.legendre.leggauss(int(n))


def tensor_rule(n_x: int, n_z: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tensor-product rule: η, ξ and weight of each of the n_x·n_z points (η varies slowest)."""
    eta, w_eta = gauss_legendre(n_x)
    xi, w_xi = gauss_legendre(n_z)
    return (np.repeat(eta, n_z), np.tile(xi, n_x), np.outer(w_eta, w_xi).ravel())
