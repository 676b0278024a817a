"""One-dimensional shape functions of the element (eqs. 11-12, READING-NOTES corrections).

Along x the reference coordinate is η = 2(x − x_i)/l − 1; through a layer of thickness h it is
ξ = 2(z − z_bottom)/h − 1 (eq. 11b prints η; it is ξ). Both run over [−1, 1].

The slope functions are returned for a reference length of 2, i.e. they multiply the derivative
with respect to η (or ξ):

    Hbar(η; l) = (l/2) Hbar_ref(η),   Hbar_ref_i = (η³ − η² − η + 1)/4,

so that a physical slope DOF u,x enters as (l/2) u,x (see :mod:`sandwich.beam.element`). Derivatives
with respect to x and z follow from the chain rule N,x = (2/l) N,η and N,z = (2/h) N,ξ — eq. (14)
prints the reciprocal factors; READING-NOTES fixes them.
"""

from __future__ import annotations

import numpy as np

X_KINDS = ("L", "H", "Hbar")
Z_KINDS = ("L_t", "L_b", "1", "H_t", "H_b", "Hbar_t", "Hbar_b")


def _as_array(s: np.ndarray | float) -> np.ndarray:
    return np.asarray(s, dtype=float)


def x_shape(kind: str, node: int, eta: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Shape function of node ``node`` (0 = i, 1 = i+1) of kind ``kind`` along x, eq. (11a).

    Parameters
    ----------
    kind
        ``"L"`` (linear Lagrange), ``"H"`` (Hermite value) or ``"Hbar"`` (Hermite slope, for a
        reference length 2).
    node
        0 for node i, 1 for node i+1.
    eta
        Reference coordinate(s) in [−1, 1].

    Returns
    -------
    value, d_deta
        The function and its derivative with respect to η, shaped like ``eta``.
    """
    η = _as_array(eta)
    if node not in (0, 1):
        raise ValueError(f"node must be 0 or 1, got {node!r}")
    if kind == "L":  # L_i = (1 − η)/2, L_{i+1} = (1 + η)/2
        sign = -1.0 if node == 0 else 1.0
        return 0.5 * (1.0 + sign * η), np.full_like(η, 0.5 * sign)
    if kind == "H":
        if node == 0:  # H_i = (η³ − 3η + 2)/4
            return (η**3 - 3 * η + 2) / 4, (3 * η**2 - 3) / 4
        return (-(η**3) + 3 * η + 2) / 4, (-3 * η**2 + 3) / 4  # H_{i+1}
    if kind == "Hbar":
        if node == 0:  # Hbar_i = (l/8)(η³ − η² − η + 1), here with l = 2
            return (η**3 - η**2 - η + 1) / 4, (3 * η**2 - 2 * η - 1) / 4
        return (η**3 + η**2 - η - 1) / 4, (3 * η**2 + 2 * η - 1) / 4  # Hbar_{i+1}
    raise ValueError(f"unknown x shape kind {kind!r}; expected one of {X_KINDS}")


def z_shape(kind: str, xi: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Shape function of kind ``kind`` through a layer's thickness, eq. (11b).

    Parameters
    ----------
    kind
        ``"L_t"``, ``"L_b"`` (linear, faces' u), ``"1"`` (constant, faces' w), ``"H_t"``,
        ``"H_b"`` (Hermite value at the top/bottom) or ``"Hbar_t"``, ``"Hbar_b"`` (Hermite slope,
        reference thickness 2).
    xi
        Reference coordinate(s) in [−1, 1]; ξ = −1 is the layer's bottom, ξ = 1 its top.

    Returns
    -------
    value, d_dxi
        The function and its derivative with respect to ξ, shaped like ``xi``.
    """
    ξ = _as_array(xi)
    if kind == "L_t":  # L_t = (1 + ξ)/2
        return 0.5 * (1 + ξ), np.full_like(ξ, 0.5)
    if kind == "L_b":  # L_b = (1 − ξ)/2
        return 0.5 * (1 - ξ), np.full_like(ξ, -0.5)
    if kind == "1":
        return np.ones_like(ξ), np.zeros_like(ξ)
    # The Hermite set through the thickness is the x set with bottom = node i, top = node i+1.
    hermite = {"H_b": ("H", 0), "Hbar_b": ("Hbar", 0), "H_t": ("H", 1), "Hbar_t": ("Hbar", 1)}
    if kind in hermite:
        return x_shape(*hermite[kind], ξ)
    raise ValueError(f"unknown z shape kind {kind!r}; expected one of {Z_KINDS}")


def slope_scale_x(kind: str) -> bool:
    """Whether a DOF of this x kind is a slope (its reference value is (l/2) times it)."""
    return kind == "Hbar"


def slope_scale_z(kind: str) -> bool:
    """Whether a DOF of this z kind is a slope (its reference value is (h/2) times it)."""
    return kind.startswith("Hbar")
