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


def gaps_with_derivatives(d: np.ndarray, a: np.ndarray):
    """Batched :func:`gap_with_derivatives` for n slaves at once.

    ``d`` (n, 2) is x_s − x_0, ``a`` (n, 2) the chord x_2 − x_1. Returns g (n,), the gradient
    (n, 8) and the Hessian (n, 8, 8) with respect to X = (x_s, x_0, x_1, x_2), the same
    expressions as the single-slave function (which the finite-difference test checks).
    """
    L2 = np.einsum("ni,ni->n", a, a)
    L = np.sqrt(L2)
    Ja = a @ J.T
    Jd = d @ J.T
    n = Ja / L[:, None]
    g = np.einsum("ni,ni->n", n, d)
    g_a = -Jd / L[:, None] - (g / L2)[:, None] * a
    H_da = J[None] / L[:, None, None] - np.einsum("ni,nj->nij", n, a) / L2[:, None, None]
    H_aa = (np.einsum("ni,nj->nij", Jd, a) / (L2 * L)[:, None, None]
            - np.einsum("ni,nj->nij", a, g_a) / L2[:, None, None]
            - (g / L2)[:, None, None] * np.eye(2)[None]
            + (2.0 * g / (L2 * L2))[:, None, None] * np.einsum("ni,nj->nij", a, a))
    grad = np.concatenate([n, -n, -g_a, g_a], axis=1)
    cross = np.einsum("ia,nij,jb->nab", _D, H_da, _A)
    hess = cross + cross.transpose(0, 2, 1) + np.einsum("ia,nij,jb->nab", _A, H_aa, _A)
    return g, grad, 0.5 * (hess + hess.transpose(0, 2, 1))


@dataclass
class ContactPair:
    """One debond's lips: node indices (into the arrays handed to :func:`evaluate`) and weights.

    :func:`sandwich.plane2d.model.contact_pairs` gives input-mesh node indices (the same on every
    MPI
    rank); the system renumbers them into its list of contact nodes.
    """

    slave: np.ndarray  # (ns,) face-lip nodes
    anchor: np.ndarray  # (ns,) the coincident core-lip node of each slave
    chord: np.ndarray  # (ns, 2) core-lip neighbours (x_1, x_2) of each anchor, n out of the core
    weight: np.ndarray  # (ns,) tributary length of each slave node (mm)
    penalty: float  # k (N/mm³)
    width: float  # b (mm)
    x_ref: np.ndarray  # (ns,) reference x of the slave nodes (for profiles)

    @property
    def all_blocks(self) -> np.ndarray:
        """(ns, 4): the nodes (s, 0, 1, 2) each slave's gap depends on."""
        return np.column_stack([self.slave, self.anchor, self.chord[:, 0], self.chord[:, 1]])

    def blocks(self, i: int) -> np.ndarray:
        """The four nodes (s, 0, 1, 2) slave i's gap depends on."""
        return self.all_blocks[i]

    def renumbered(self, index: dict[int, int]) -> ContactPair:
        """The same pair with every node n replaced by ``index[n]``."""
        def m(a):
            return np.vectorize(lambda k: index[int(k)], otypes=[np.int64])(a)
        return ContactPair(m(self.slave), m(self.anchor), m(self.chord), self.weight,
                           self.penalty, self.width, self.x_ref)


@dataclass
class ContactState:
    """Result of one contact evaluation (arrays over the active slaves, in slave order)."""

    gap: np.ndarray  # (ns,) signed gaps (mm), negative = penetration
    slip: np.ndarray  # (ns,) tangential offset of the slave from its anchor (mm)
    pressure: np.ndarray  # (ns,) p = k ⟨−g⟩ (MPa)
    active: np.ndarray  # (na,) indices of the slaves with g <= 0
    rows: np.ndarray  # (na, 4) their nodes (s, 0, 1, 2)
    forces: np.ndarray  # (na, 8) ∂Π/∂X
    tangents: np.ndarray | None  # (na, 8, 8) ∂²Π/∂X² (None unless asked for)

    def nodal_forces(self, n_nodes: int) -> np.ndarray:
        """The forces summed per node, (n_nodes, 2)."""
        f = np.zeros((n_nodes, 2))
        np.add.at(f, self.rows.ravel(), self.forces.reshape(-1, 2))
        return f


def evaluate(pair: ContactPair, x_ref: np.ndarray, u: np.ndarray,
             want_tangent: bool = True) -> ContactState:
    """Gaps, pressures, forces and tangents at reference positions + displacements (nodes, 2).

    Vectorised over the slaves of the pair. The slave–anchor offset x_s − x_0 is formed as
    (X_s − X_0) + (u_s − u_0): the positions are ~10² mm while the gap is ~10⁻⁵ mm, and X + u
    first would lose the gap to round-off (which the stiff penalty turns into a residual floor
    far above Newton's tolerance).
    """
    s, a0 = pair.slave, pair.anchor
    c1, c2 = pair.chord[:, 0], pair.chord[:, 1]
    d = (x_ref[s] - x_ref[a0]) + (u[s] - u[a0])
    chord = (x_ref[c2] + u[c2]) - (x_ref[c1] + u[c1])
    L = np.sqrt(np.einsum("ni,ni->n", chord, chord))
    slips = np.einsum("ni,ni->n", d, chord) / L
    gaps = np.einsum("ni,ni->n", (chord @ J.T) / L[:, None], d)  # as in gaps_with_derivatives
    # g = 0 counts as active (force 0, tangent k b w ∇g ∇gᵀ, a valid choice at the kink of
    # ⟨−g⟩²): lips that touch in the reference state start supported instead of free
    active = np.flatnonzero(gaps <= 0.0)
    g, dg, d2g = gaps_with_derivatives(d[active], chord[active])
    kw = pair.penalty * pair.width * pair.weight[active]
    forces = (kw * g)[:, None] * dg
    tangents = None
    if want_tangent:
        tangents = kw[:, None, None] * (np.einsum("na,nb->nab", dg, dg) + g[:, None, None] * d2g)
    pressure = pair.penalty * np.maximum(-gaps, 0.0)
    return ContactState(gaps, slips, pressure, active, pair.all_blocks[active], forces, tangents)


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
