"""Frictionless unilateral contact between the lips of a debond: small-sliding node-to-surface.

Slave nodes are the face-lip nodes; each is paired with the coincident core-lip node (its anchor,
x_0). The master surface near the anchor is the tangent line of the deformed core lip there, with
its direction taken from the chord of the anchor's two neighbours on the core lip, x_1 → x_2
(the crack-tip nodes close the chain; at an open mouth, where the debond reaches the beam
end, the last chord is one-sided: the anchor and its single neighbour). The gap is the signed
distance of the slave from that line along its normal n = J (x_2 − x_1)/|x_2 − x_1|, J a +90°
rotation, the chain being ordered so that n points out of the core:

    g = n · (x_s − x_0) = (x_2 − x_1) × (x_s − x_0) / |x_2 − x_1|.

This is the "small-sliding" node-to-surface formulation (the slave stays near its anchor; the
tangential slip (x_s − x_0) · t is reported so that this can be checked). Unlike node-to-segment
with a polyline, g is a smooth function of the nodal positions: at the start every slave sits
exactly on a master node, where the normal of a polyline jumps and Newton cycles.

The contact energy of a node is Π = ½ k b w_s ⟨−g⟩² (k penalty in N/mm³, b the width, w_s the
slave's tributary length), so its force ∂Π/∂X and tangent ∂²Π/∂X² are exact derivatives of one
scalar: the tangent is consistent and symmetric. Pressure p = k ⟨−g⟩ (MPa).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

J = np.array([[0.0, -1.0], [1.0, 0.0]])  # rotation by +90°
# X = (x_s, x_0, x_1, x_2) stacked (8,); d = x_s − x_0 and a = x_2 − x_1 as linear maps of X
_Z = np.zeros((2, 2))
_I = np.eye(2)
_D = np.hstack([_I, -_I, _Z, _Z])
_A = np.hstack([_Z, _Z, -_I, _I])


def gap_with_derivatives(xs, x0, x1, x2):
    """Signed gap g of x_s from the line through x0 along x1 → x2; gradient (8,), Hessian (8, 8)."""
    d = xs - x0
    a = x2 - x1
    L2 = a @ a
    L = np.sqrt(L2)
    n = J @ a / L
    g = n @ d
    g_d = n  # ∂g/∂d
    g_a = -J @ d / L - g * a / L2  # ∂g/∂a, using ∂(a × d)/∂a = (d_z, −d_x) = −J d
    H_da = J / L - np.outer(n, a) / L2  # ∂n/∂a = ∂²g/∂d∂a
    H_aa = (np.outer(J @ d, a) / (L2 * L) - np.outer(a, g_a) / L2 - g * np.eye(2) / L2
            + 2.0 * g * np.outer(a, a) / (L2 * L2))
    grad = _D.T @ g_d + _A.T @ g_a
    hess = _D.T @ H_da @ _A + _A.T @ H_da.T @ _D + _A.T @ H_aa @ _A
    return g, grad, 0.5 * (hess + hess.T)


@dataclass
class ContactPair:
    """One debond's lips as local DOF blocks plus reference data."""

    slave: np.ndarray  # (ns,) face-lip nodes
    anchor: np.ndarray  # (ns,) the coincident core-lip node of each slave
    chord: np.ndarray  # (ns, 2) core-lip neighbours (x_1, x_2) of each anchor, n out of the core
    weight: np.ndarray  # (ns,) tributary length of each slave node (mm)
    penalty: float  # k (N/mm³)
    width: float  # b (mm)
    x_ref: np.ndarray  # (ns,) reference x of the slave nodes (for profiles)

    def blocks(self, i: int) -> np.ndarray:
        """The four DOF blocks (s, 0, 1, 2) slave i's gap depends on."""
        return np.array([self.slave[i], self.anchor[i], self.chord[i, 0], self.chord[i, 1]])


@dataclass
class ContactState:
    """Result of one contact evaluation."""

    gap: np.ndarray  # (ns,) signed gaps (mm), negative = penetration
    slip: np.ndarray  # (ns,) tangential offset of the slave from its anchor (mm)
    pressure: np.ndarray  # (ns,) p = k ⟨−g⟩ (MPa)
    rows: list[np.ndarray]  # per active slave: its 4 DOF blocks
    forces: list[np.ndarray]  # per active slave: (8,) ∂Π/∂X
    tangents: list[np.ndarray]  # per active slave: (8, 8) ∂²Π/∂X²


def evaluate(pair: ContactPair, x_ref: np.ndarray, u: np.ndarray,
             want_tangent: bool = True) -> ContactState:
    """Gaps, pressures, forces and tangents at reference positions + displacements (blocks, 2).

    The slave–anchor offset x_s − x_0 is formed as (X_s − X_0) + (u_s − u_0): the positions are
    ~10² mm while the gap is ~10⁻⁵ mm, and X + u first would lose the gap to round-off (which
    the stiff penalty turns into a residual floor far above Newton's tolerance).
    """
    ns = len(pair.slave)
    gaps = np.zeros(ns)
    slips = np.zeros(ns)
    rows, forces, tangents = [], [], []
    for i in range(ns):
        blocks = pair.blocks(i)
        d = (x_ref[blocks[0]] - x_ref[blocks[1]]) + (u[blocks[0]] - u[blocks[1]])
        x1, x2 = x_ref[blocks[2:]] + u[blocks[2:]]
        g, dg, d2g = gap_with_derivatives(d, np.zeros(2), x1, x2)
        t = (x2 - x1) / np.linalg.norm(x2 - x1)
        gaps[i] = g
        slips[i] = d @ t
        if g < 0.0:
            kw = pair.penalty * pair.width * pair.weight[i]
            rows.append(blocks)
            forces.append(kw * g * dg)
            if want_tangent:
                tangents.append(kw * (np.outer(dg, dg) + g * d2g))
    pressure = pair.penalty * np.maximum(-gaps, 0.0)
    return ContactState(gaps, slips, pressure, rows, forces, tangents)


def slave_weights(x_ref: np.ndarray, x_left_tip: float | None,
                  x_right_tip: float | None) -> np.ndarray:
    """Tributary lengths of face-lip nodes on quadratic facets (Simpson weights 1/6, 2/3, 1/6).

    The nodes, sorted by x, alternate mid-side / corner along the lip. A crack tip (a corner
    shared by both lips, bonded, no contact) closes the chain at either end; ``None`` means the
    debond reaches the beam end there (open mouth): the outermost lip node is then itself a
    corner, a slave with the single-facet weight h/6.
    """
    inner = np.sort(np.asarray(x_ref, dtype=float))
    xs = np.concatenate([[] if x_left_tip is None else [x_left_tip], inner,
                         [] if x_right_tip is None else [x_right_tip]])
    if len(xs) % 2 == 0 or len(xs) < 3:
        raise ValueError("face-lip nodes must alternate corner / mid-side / corner along the lip")
    w = np.zeros(len(xs))
    for e in range(0, len(xs) - 2, 2):
        h = xs[e + 2] - xs[e]
        w[e] += h / 6.0
        w[e + 1] += 2.0 * h / 3.0
        w[e + 2] += h / 6.0
    lo = 0 if x_left_tip is None else 1
    w_sorted = w[lo: lo + len(inner)]
    order = np.argsort(np.argsort(x_ref))
    return w_sorted[order]
