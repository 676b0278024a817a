"""Frictionless unilateral contact on debonded stretches (eqs. 41-42), by a penalty.

Pairing. Nodes strictly inside a debond are untied; at each of them the face's inner surface
(master) is paired with the core boundary point of the *same material coordinate x* (slave).
This node-to-node pairing assumes small relative sliding; the sliding s = t·Δ is returned so a
user can check it (a sliding of a fraction of an element means the pairing is no longer apt).

Gap (eq. 42). The slave boundary's deformed tangent is t ∝ (1 + u_c,x, w_c,x), its outward normal
n = s_n (−w_c,x, 1 + u_c,x)/ℓ with ℓ = |(1 + u_c,x, w_c,x)| and s_n = +1 on the core's top,
−1 on its bottom, i.e. n = s_n(−sin β, cos β) with β the slope angle of eq. (42). With the
displacement jump Δ = (u_face − u_core, w_face − w_core) (face and core surfaces coincide in the
reference state),

    g = n · Δ = s_n (−w_c,x Δu + (1 + u_c,x) Δw) / ℓ,

which is eq. (41)'s w̄_face − w̄_core. g < 0 is penetration.

Law. Penalty ε (N/mm³) on a node's tributary area A = b · (half the adjacent element lengths):
contact pressure p = ε ⟨−g⟩ (MPa), energy ½ ε A ⟨−g⟩², force f = −p A ∂g/∂u and consistent
tangent K = ε A H(−g) ∂g ∂gᵀ − p A ∂²g (the second term is the rotation of the normal).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from beam_element.dofs import CONTACT_DOFS, global_dof

# Local order of a contact pair's six DOFs.
PAIR_ROLES = ("u_face", "w_face", "u_core", "w_core", "u_core,x", "w_core,x")
NORMAL_SIGN = {"top": 1.0, "bottom": -1.0}

# d(Δu, Δw, a = 1 + u_c,x, c = w_c,x) / d(pair DOFs): the chain from gap variables to DOFs.
_D = np.array([
    [1.0, 0.0, -1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, -1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
])


@dataclass(frozen=True)
class ContactPairs:
    """Node-to-node contact pairs of one interface."""

    interface: str
    nodes: np.ndarray  # (m,)
    area: np.ndarray  # (m,) tributary area b · l_trib (mm²)
    dofs: np.ndarray  # (m, 6) full DOF indices in PAIR_ROLES order

    @property
    def size(self) -> int:
        """Number of pairs."""
        return int(self.nodes.size)


def contact_pairs(interface: str, nodes: np.ndarray, x: np.ndarray, width: float) -> ContactPairs:
    """Pairs at ``nodes`` (indices into the node coordinates ``x``) of a debonded interface."""
    if interface not in CONTACT_DOFS:
        raise ValueError(f"interface must be 'top' or 'bottom', got {interface!r}")
    nodes = np.asarray(nodes, dtype=int)
    left = np.where(nodes > 0, x[nodes] - x[np.maximum(nodes - 1, 0)], 0.0)
    right = np.where(nodes < x.size - 1, x[np.minimum(nodes + 1, x.size - 1)] - x[nodes], 0.0)
    names = CONTACT_DOFS[interface]
    dofs = np.stack([global_dof(nodes, names[r]) for r in PAIR_ROLES], axis=-1).reshape(-1, 6)
    return ContactPairs(interface, nodes, width * 0.5 * (left + right), dofs)


@dataclass(frozen=True)
class PairKinematics:
    """Gap g, its gradient and Hessian on the pair DOFs, and the tangential sliding."""

    gap: np.ndarray  # (m,) mm, negative = penetration
    grad: np.ndarray  # (m, 6)
    hess: np.ndarray  # (m, 6, 6)
    sliding: np.ndarray  # (m,) mm


def pair_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> PairKinematics:
    """Gap along the slave's deformed normal, eq. (42), with first and second derivatives."""
    v = u_full[pairs.dofs]  # (m, 6)
    Δu, Δw = v[:, 0] - v[:, 2], v[:, 1] - v[:, 3]
    a, c = 1.0 + v[:, 4], v[:, 5]  # slave tangent (1 + u_c,x, w_c,x)
    ℓ = np.sqrt(a**2 + c**2)
    s_n = NORMAL_SIGN[pairs.interface]
    q = -c * Δu + a * Δw  # ℓ n·Δ / s_n
    gap = s_n * q / ℓ  # eq. (42): w̄_face − w̄_core
    sliding = (a * Δu + c * Δw) / ℓ
    m = v.shape[0]
    # Derivatives in the variables (Δu, Δw, a, c).
    dq = np.stack([-c, a, Δw, -Δu], axis=-1)
    dℓ = np.stack([np.zeros(m), np.zeros(m), a / ℓ, c / ℓ], axis=-1)
    d2q = np.zeros((m, 4, 4))
    d2q[:, 0, 3] = d2q[:, 3, 0] = -1.0
    d2q[:, 1, 2] = d2q[:, 2, 1] = 1.0
    d2ℓ = np.zeros((m, 4, 4))
    d2ℓ[:, 2, 2], d2ℓ[:, 3, 3] = c**2 / ℓ**3, a**2 / ℓ**3
    d2ℓ[:, 2, 3] = d2ℓ[:, 3, 2] = -a * c / ℓ**3
    ℓ1, q1 = ℓ[:, None], q[:, None]
    dg = s_n * (dq / ℓ1 - q1 * dℓ / ℓ1**2)
    cross = dq[:, :, None] * dℓ[:, None, :]
    d2g = s_n * (
        d2q / ℓ1[:, :, None]
        - (cross + cross.transpose(0, 2, 1)) / (ℓ1**2)[:, :, None]
        - (q1 / ℓ1**2)[:, :, None] * d2ℓ
        + (2 * q1 / ℓ1**3)[:, :, None] * dℓ[:, :, None] * dℓ[:, None, :]
    )
    return PairKinematics(gap, dg @ _D, np.einsum("ia,mij,jb->mab", _D, d2g, _D), sliding)


def penalty_response(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics]:
    """Contact forces (m, 6), tangents (m, 6, 6), pressures (m,) MPa and the kinematics."""
    if not (np.isfinite(penalty) and penalty > 0):
        raise ValueError(f"contact penalty must be positive, got {penalty!r}")
    k = pair_kinematics(pairs, u_full)
    active = k.gap < 0.0
    p = penalty * np.where(active, -k.gap, 0.0)  # eq. (41): contact pressure, MPa
    A = pairs.area
    f = -(p * A)[:, None] * k.grad
    K = (penalty * A * active)[:, None, None] * k.grad[:, :, None] * k.grad[:, None, :]
    K -= (p * A)[:, None, None] * k.hess
    return f, K, p, k
