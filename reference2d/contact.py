"""Frictionless unilateral contact between the lips of a debond: node-to-segment penalty.

Slave nodes are the face-lip nodes; the master curve is the core lip, the polyline through the
crack-tip node, the core-lip nodes and the other tip node (a quadratic facet counts as two straight
segments). Each slave node s sees the segment x1 → x2 it projects onto; the gap is the signed
distance along the segment's deformed normal n = J (x2 − x1)/|x2 − x1|, J a +90° rotation, with the
polyline ordered so that n points out of the core:

    g = (x2 − x1) × (x_s − x1) / |x2 − x1|.

The contact energy of a node is Π = ½ k b w_s ⟨−g⟩² (k penalty in N/mm³, b the width, w_s the
slave node's tributary length), so its force ∂Π/∂X and tangent ∂²Π/∂X² are exact derivatives of
one scalar: the tangent is consistent and symmetric. Pressure p = k ⟨−g⟩ (MPa).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

J = np.array([[0.0, -1.0], [1.0, 0.0]])  # rotation by +90°
# X = (x_s, x_1, x_2) stacked (6,); d = x_s − x_1 and a = x_2 − x_1 as linear maps of X
_D = np.hstack([np.eye(2), -np.eye(2), np.zeros((2, 2))])
_A = np.hstack([np.zeros((2, 2)), -np.eye(2), np.eye(2)])


def gap_with_derivatives(xs, x1, x2):
    """Signed gap g of x_s from the line x1 → x2, its gradient (6,) and Hessian (6, 6) in X."""
    d = xs - x1
    a = x2 - x1
    L2 = a @ a
    L = np.sqrt(L2)
    n = J @ a / L
    g = n @ d
    g_d = n  # ∂g/∂d
    g_a = -J @ d / L - g * a / L2  # ∂g/∂a: ∂(a×d)/∂a = (d_z, −d_x) = −J d
    H_da = J / L - np.outer(n, a) / L2  # ∂n/∂a = ∂²g/∂d∂a
    H_aa = (np.outer(J @ d, a) / (L2 * L) - np.outer(a, g_a) / L2 - g * np.eye(2) / L2
            + 2.0 * g * np.outer(a, a) / (L2 * L2))
    grad = _D.T @ g_d + _A.T @ g_a
    hess = _D.T @ H_da @ _A + _A.T @ H_da.T @ _D + _A.T @ H_aa @ _A
    return g, grad, 0.5 * (hess + hess.T)


@dataclass
class ContactPair:
    """One debond's lips as node indices (local DOF blocks) plus reference data."""

    slave: np.ndarray  # (ns,) blocks of face-lip nodes
    master: np.ndarray  # (nm,) blocks of the core-lip polyline, tip to tip, normal out of core
    weight: np.ndarray  # (ns,) tributary length of each slave node (mm)
    window: np.ndarray  # (ns, 2) first and last master *segment* a slave may use
    penalty: float  # k (N/mm³)
    width: float  # b (mm)
    x_ref: np.ndarray  # (ns,) reference x of the slave nodes (for profiles)


@dataclass
class ContactState:
    """Result of one contact evaluation."""

    gap: np.ndarray  # (ns,) signed gaps (mm), negative = penetration
    pressure: np.ndarray  # (ns,) p = k ⟨−g⟩ (MPa)
    rows: list[np.ndarray]  # per active slave: the 3 DOF blocks (s, m1, m2)
    forces: list[np.ndarray]  # per active slave: (6,) ∂Π/∂X
    tangents: list[np.ndarray]  # per active slave: (6, 6) ∂²Π/∂X²
    out_of_window: int  # slaves whose nearest segment lay at the edge of their window


def evaluate(pair: ContactPair, x_cur: np.ndarray, want_tangent: bool = True) -> ContactState:
    """Gaps, pressures, forces and tangents at current node positions ``x_cur`` (blocks, 2)."""
    ns = len(pair.slave)
    gaps = np.zeros(ns)
    rows, forces, tangents = [], [], []
    out = 0
    xm = x_cur[pair.master]
    for i in range(ns):
        xs = x_cur[pair.slave[i]]
        lo, hi = pair.window[i]
        best = None
        for seg in range(lo, hi + 1):
            x1, x2 = xm[seg], xm[seg + 1]
            a = x2 - x1
            xi = (xs - x1) @ a / (a @ a)
            dist = np.linalg.norm(xs - (x1 + np.clip(xi, 0.0, 1.0) * a))
            if best is None or dist < best[0] - 1e-14:
                best = (dist, seg)
        seg = best[1]
        if (seg == lo and lo > 0) or (seg == hi and hi < len(pair.master) - 2):
            x1, x2 = xm[seg], xm[seg + 1]
            xi = (xs - x1) @ (x2 - x1) / ((x2 - x1) @ (x2 - x1))
            if xi < 0.0 or xi > 1.0:
                out += 1
        g, dg, d2g = gap_with_derivatives(xs, xm[seg], xm[seg + 1])
        gaps[i] = g
        if g < 0.0:
            kw = pair.penalty * pair.width * pair.weight[i]
            rows.append(np.array([pair.slave[i], pair.master[seg], pair.master[seg + 1]]))
            forces.append(kw * g * dg)
            if want_tangent:
                tangents.append(kw * (np.outer(dg, dg) + g * d2g))
    pressure = pair.penalty * np.maximum(-gaps, 0.0)
    return ContactState(gaps, pressure, rows, forces, tangents, out)


def slave_weights(x_ref: np.ndarray, x_left_tip: float, x_right_tip: float) -> np.ndarray:
    """Tributary lengths of face-lip nodes on quadratic facets (Simpson weights 1/6, 2/3, 1/6).

    The nodes, sorted by x, alternate mid-side / corner between the two tips (which are corners
    and carry no contact: they are bonded).
    """
    xs = np.concatenate([[x_left_tip], np.sort(x_ref), [x_right_tip]])
    w = np.zeros(len(xs))
    for e in range(0, len(xs) - 2, 2):
        h = xs[e + 2] - xs[e]
        w[e] += h / 6.0
        w[e + 1] += 2.0 * h / 3.0
        w[e + 2] += h / 6.0
    order = np.argsort(np.argsort(x_ref))
    return w[1:-1][order]
