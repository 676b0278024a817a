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

Law. Penalty ε (N/mm³) on a node's tributary area A = b · (half the adjacent element lengths),
regularised over a gap width s (mm) by a shifted "softplus" (:func:`pressure_law`):

    p(g) = ε s [sp(−g/s − c) − sp(−c)]  for g < 0,   p = 0 for g ≥ 0   (pressure, MPa),
    sp(x) = ln(1 + eˣ),   dp/dg = −ε / (1 + e^(g/s + c)),   c = SHIFT = 25.

Far inside (−g ≫ c s) this is the plain penalty ε (−g − c s), offset by c s; near g = 0 the
stiffness −dp/dg rises smoothly over a few s around g = −c s. At g = 0, p = 0 exactly (the
unloaded and rigidly moved states carry no contact force) and dp/dg jumps by ε e⁻²⁵ (≈ 3e-7
N/mm³), far below any structural stiffness. s = 0 is the plain penalty ε ⟨−g⟩. Force
f = −p A ∂g/∂u and consistent tangent K = −A p'(g) ∂g ∂gᵀ − p A ∂²g (the second term is the
rotation of the normal); the energy A ∫_g^0 p(t) dt has a closed form (dilogarithm).

Why regularise. With the plain penalty the tangent jumps by ε A (≈ 1e7 N/mm for an 8 mm element)
when a pair opens. Where the face next to an opening pair buckles away from the core (debonds at
a clamp, fig. 7 C3/C4) the structure without that pair is unstable (a negative tangent
eigenvalue, measured −12 N/mm at 40 elements), so the opening is a limit point with a corner:
Newton jumps between the two tangents and the arc-length method cannot turn. A polynomial band
(p quadratic over |g| < δ) does not help: the stiffness falls from ε A to the structure's ~10 N/mm
only within 1e-6 δ of the band's edge, a corner again. The exponential tail of the softplus
spreads that fall over ~14 s, the path turns smoothly, and the arc-length method passes it with
steps down to ~s (:mod:`beam_element.solve` lowers the step floor accordingly).

What it costs: the penetration at a pressure p is at most c s + p/ε, so with the default
s = 0.002 × bound (1e-6 mm for 0.5 mm faces; offset c s = 2.5e-5 mm) the bound 1e-3 × face
thickness holds wherever p ≤ ε × (bound − c s) (10.6 MPa for the paper's materials). The offset
is what limits s: near a debond tip the face must bend from g = 0 (tied) to g ≈ −c s, which
disturbs the pressure there (squeeze test, 10 mm from the tip: +0.56 % at s = 1e-5 mm,
+0.15 % at 2.5e-6 mm, within 0.1 % at 1e-6 mm; plain penalty 2e-3 %).
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


SHIFT = 25.0  # c: the softplus is centred at g = −c s, so dp/dg jumps by only ε e⁻²⁵ at g = 0


def pressure_law(
    gap: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Contact pressure p(g) (MPa) and its derivative dp/dg (N/mm³) of the shifted softplus.

    ``penalty`` is ε (N/mm³), ``smoothing`` the width s (mm) of the regularisation (see the
    module docstring); s = 0 is the plain penalty ε ⟨−g⟩.
    """
    if not (np.isfinite(penalty) and penalty > 0):
        raise ValueError(f"contact penalty must be positive, got {penalty!r}")
    if not (np.isfinite(smoothing) and smoothing >= 0):
        raise ValueError(f"contact smoothing must be >= 0 mm, got {smoothing!r}")
    g = np.asarray(gap, dtype=float)
    if smoothing == 0:
        return penalty * np.maximum(-g, 0.0), np.where(g < 0, -penalty, 0.0)
    closed = g < 0
    x = -np.minimum(g, 0.0) / smoothing - SHIFT
    p = penalty * smoothing * (_softplus(x) - _softplus(-SHIFT))
    dp = -penalty * 0.5 * (1.0 + np.tanh(0.5 * x))  # −ε / (1 + e⁻ˣ)
    return np.where(closed, p, 0.0), np.where(closed, dp, 0.0)


def _softplus(x: np.ndarray | float) -> np.ndarray:
    """ln(1 + eˣ) without overflow."""
    return np.maximum(x, 0.0) + np.log1p(np.exp(-np.abs(x)))


def _softplus_integral(x: np.ndarray | float) -> np.ndarray:
    """∫_−∞^x ln(1 + eᵗ) dt = −Li₂(−eˣ), with Li₂(z) = ``scipy.special.spence(1 − z)``."""
    from scipy.special import spence

    return -spence(1.0 + np.exp(x))


def contact_energy(gap: np.ndarray, penalty: float, smoothing: float = 0.0) -> np.ndarray:
    """Energy per unit area ∫_g^0 p(t) dt (N/mm) of :func:`pressure_law` (closed form)."""
    g = np.minimum(np.asarray(gap, dtype=float), 0.0)
    if smoothing == 0:
        return 0.5 * penalty * g**2
    s, c = smoothing, SHIFT
    return penalty * (s**2 * (_softplus_integral(-g / s - c) - _softplus_integral(-c))
                      + s * _softplus(-c) * g)


def in_contact(gap: np.ndarray, smoothing: float) -> np.ndarray:
    """Pairs reported as in contact.

    Penetration beyond (c − 5) s (stiffness above 0.7 % of ε), or g < 0 for the plain penalty.
    """
    g = np.asarray(gap)
    return g < -(SHIFT - 5.0) * smoothing if smoothing > 0 else g < 0.0


def penalty_response(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics]:
    """Contact forces (m, 6), tangents (m, 6, 6), pressures (m,) MPa and the kinematics.

    ``smoothing`` is the regularisation width s (mm) of :func:`pressure_law`.
    """
    k = pair_kinematics(pairs, u_full)
    p, dp = pressure_law(k.gap, penalty, smoothing)  # eq. (41): contact pressure, MPa
    A = pairs.area
    f = -(p * A)[:, None] * k.grad
    K = (-dp * A)[:, None, None] * k.grad[:, :, None] * k.grad[:, None, :]
    K -= (p * A)[:, None, None] * k.hess
    return f, K, p, k
