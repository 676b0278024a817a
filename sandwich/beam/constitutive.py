"""Linear elastic laws of the layers in Voigt form (eqs. 3-4).

Stresses are second Piola-Kirchhoff, strains Green-Lagrange, ordered (ε_x, ε_z, γ):

- faces (first-order beams): σ_x = E_x ε_x, τ = G_zx γ; no σ_z (the face energy of eq. 6 has no
  ε_z term), so the ε_z row and column are zero;
- core (orthotropic plane stress): σ_x = Q_x ε_x + Q ε_z, σ_z = Q_z ε_z + Q ε_x, τ = G_zx γ with
  Q_x, Q_z, Q of eq. (4).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class ElasticMaterial(Protocol):
    """What the laws need from a material (``sandwich.scene.Material`` satisfies it)."""

    Ex: float
    Ez: float
    Gzx: float
    nu_zx: float


def _check_positive(**values: float) -> None:
    for key, v in values.items():
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"material property {key} must be a positive finite number, got {v!r}")


def face_stiffness(material: ElasticMaterial) -> np.ndarray:
    """Voigt stiffness (MPa) of a face sheet, eq. (3): diag(E_x, 0, G_zx)."""
    _check_positive(Ex=material.Ex, Gzx=material.Gzx)
    return np.diag([material.Ex, 0.0, material.Gzx])


def core_stiffness(material: ElasticMaterial) -> np.ndarray:
    """Voigt stiffness (MPa) of the orthotropic plane-stress core, eqs. (3-4)."""
    _check_positive(Ex=material.Ex, Ez=material.Ez, Gzx=material.Gzx)
    D = 1.0 - (material.Ex / material.Ez) * material.nu_zx**2  # eq. (4) denominator
    if not D > 0:
        raise ValueError(
            f"core Poisson ratio nu_zx = {material.nu_zx} makes the plane-stress law indefinite "
            f"(1 - (Ex/Ez) nu_zx^2 = {D:.3g} <= 0)"
        )
    Qx = material.Ex / D  # eq. (4)
    Qz = material.Ez / D
    Q = material.Ex * material.nu_zx / D
    return np.array([[Qx, Q, 0.0], [Q, Qz, 0.0], [0.0, 0.0, material.Gzx]])
