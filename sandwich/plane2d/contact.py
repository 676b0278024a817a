"""Frictionless unilateral contact between the lips of a debond: finite-sliding node-to-surface.

Slave nodes are the face-lip nodes; the master is the chain of core-lip nodes (the crack-tip
nodes close it; at an open mouth, where the debond reaches the beam end, it ends at the lip's
last node), ordered so that the normal n = J t, J a +90° rotation, points out of the core.

**Tangent line at a master node.** The master surface at chain node a is the line through x_a
along the chord of its two neighbours, x_{a−1} → x_{a+1} (one-sided at the chain's ends). The
signed distance of a slave x_s from it is

    g_a = n · (x_s − x_a) = (x_{a+1} − x_{a−1}) × (x_s − x_a) / |x_{a+1} − x_{a−1}|.

**Following the sliding.** At every evaluation each slave is projected afresh: its segment
(a, b = a + 1) of the deformed chain is the one next to its nearest master node that holds its
projection, at the parameter ξ = (x_s − x_a)·(x_b − x_a)/|x_b − x_a|² ∈ [0, 1]. Its gap blends
the tangent lines of the segment's two nodes,

    g = (1 − φ(ξ)) g_a + φ(ξ) g_b,   φ(ξ) = 3ξ² − 2ξ³  (clamped to 0 / 1 outside [0, 1]),

a C¹ function of the positions of the five nodes (s, a − 1, a, b, b + 1): φ and φ' are 0 at ξ = 0
and 1, φ' = 0 at ξ = 1, so where a slave passes a master node onto the next segment the gap and
its gradient are those of that node's tangent line from both sides. This is a smoothed
node-to-segment formulation: on a straight lip g is the exact distance; on a lip of curvature κ
with master nodes Δ apart it is within κΔ²/8 of it (to leading order: the tangent lines' distance
from the arc at mid-segment). A polyline's normal jumps at every master
node, and at the start every corner slave sits exactly on one (Newton cycles there); the
quadratic edges of the lips are only C⁰ at their corners for the same reason. In the reference
state every slave lies on its coincident master node (ξ = 0), where g is that node's tangent-line
gap. The sliding reported is the material distance of the master point the slave faces from the
slave's own reference position, along the chain.

The contact energy of a node is Π = ½ k b w_s ⟨−g⟩² (k penalty in N/mm³, b the width, w_s the
slave's tributary length), so its force ∂Π/∂X and tangent ∂²Π/∂X² are exact derivatives of one
scalar: the tangent is consistent and symmetric (up to the jump of ∂²g where ξ crosses 0 or 1).
Pressure p = k ⟨−g⟩ (MPa).

**The matrix pattern.** Each slave has a window of master chain nodes, [lo, hi], whose couplings
the system's sparse matrix holds (:attr:`ContactPair.window`, initially :data:`WINDOW` nodes on
either side of the coincident node). A slave in contact whose five nodes leave its window is
reported (:attr:`ContactState.outside`); the system then widens the windows crowded at that
moment and rebuilds its matrix (:meth:`ContactPair.widen`). Only slaves that penetrate less than
:attr:`ContactPair.widen_depth` count: the wild iterates of a failing corrector (slaves millimetres
deep, several millimetres from where they were) would otherwise widen the windows for nothing.
Entries of a deeper slave's block outside the pattern are left out of that iterate's tangent
(its force is exact): a state that converges has its slaves shallow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

J = np.array([[0.0, -1.0], [1.0, 0.0]])  # rotation by +90°
# X = (x_s, x_0, x_1, x_2) stacked (8,); d = x_s − x_0 (JUMP_MAP) and a = x_2 − x_1 (CHORD_MAP)
# as linear maps of X
_Z = np.zeros((2, 2))
_I = np.eye(2)
JUMP_MAP = np.hstack([_I, -_I, _Z, _Z])
CHORD_MAP = np.hstack([_Z, _Z, -_I, _I])

#: Master chain nodes on either side of a slave's coincident node that the matrix pattern holds
#: from the start (a chain node every half element: four quadratic edges each way).
WINDOW = 8

# the five nodes of a slave's gap, (s, p, a, b, q) = (slave, a − 1, a, b = a + 1, b + 1), as
# DOF positions 0..9; where the tangent lines' (x_s, x_0, x_1, x_2) of gaps_with_derivatives sit
_NODE_DOFS = np.arange(10).reshape(5, 2)
_AT_A = _NODE_DOFS[[0, 2, 1, 3]].ravel()  # g_a: x_0 = a, chord p → b
_AT_B = _NODE_DOFS[[0, 3, 2, 4]].ravel()  # g_b: x_0 = b, chord a → q
_XI = _NODE_DOFS[[0, 2, 3]].ravel()  # ξ: (x_s, x_a, x_b)
# ξ as a function of d = x_s − x_a and e = x_b − x_a: (d, e) = _M (x_s, x_a, x_b)
_M = np.block([[_I, -_I, _Z], [_Z, -_I, _I]])


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
    grad = JUMP_MAP.T @ g_d + CHORD_MAP.T @ g_a
    hess = (JUMP_MAP.T @ H_da @ CHORD_MAP + CHORD_MAP.T @ H_da.T @ JUMP_MAP
            + CHORD_MAP.T @ H_aa @ CHORD_MAP)
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
    cross = np.einsum("ia,nij,jb->nab", JUMP_MAP, H_da, CHORD_MAP)
    hess = cross + cross.transpose(0, 2, 1) + np.einsum("ia,nij,jb->nab", CHORD_MAP, H_aa,
                                                        CHORD_MAP)
    return g, grad, 0.5 * (hess + hess.transpose(0, 2, 1))


def segment_parameter(d: np.ndarray, e: np.ndarray):
    """ξ = d·e/|e|² of slaves on segments (d = x_s − x_a, e = x_b − x_a, both (n, 2)).

    Returns ξ (n,), its gradient (n, 6) and Hessian (n, 6, 6) with respect to (x_s, x_a, x_b).
    """
    L2 = np.einsum("ni,ni->n", e, e)
    xi = np.einsum("ni,ni->n", d, e) / L2
    xi_d = e / L2[:, None]
    r = d - xi[:, None] * 2.0 * e  # ∂ξ/∂e = (d − 2ξ e)/|e|²
    xi_e = r / L2[:, None]
    H_de = np.eye(2)[None] / L2[:, None, None] - 2.0 * np.einsum("ni,nj->nij", e, e) / (
        L2 * L2)[:, None, None]
    er = np.einsum("ni,nj->nij", e, r)
    H_ee = (-2.0 * (er + er.transpose(0, 2, 1)) / (L2 * L2)[:, None, None]
            - (2.0 * xi / L2)[:, None, None] * np.eye(2)[None])
    H = np.zeros((len(xi), 4, 4))
    H[:, :2, 2:] = H_de
    H[:, 2:, :2] = H_de
    H[:, 2:, 2:] = H_ee
    grad = np.concatenate([xi_d, xi_e], axis=1) @ _M
    return xi, grad, np.einsum("ia,nij,jb->nab", _M, H, _M)


def blend(xi: np.ndarray):
    """φ(ξ) = 3ξ² − 2ξ³ on [0, 1], 0 below, 1 above; with φ' and φ''."""
    t = np.clip(xi, 0.0, 1.0)
    inside = (xi > 0.0) & (xi < 1.0)
    return (t * t * (3.0 - 2.0 * t), np.where(inside, 6.0 * t * (1.0 - t), 0.0),
            np.where(inside, 6.0 - 12.0 * t, 0.0))


def blended_gaps(d_a, chord_a, d_b, chord_b, d, e, want_hessian: bool = True):
    """Gaps g = (1 − φ(ξ)) g_a + φ(ξ) g_b of slaves on segments (a, b), with derivatives.

    All arguments are (n, 2): ``d_a`` = x_s − x_a and ``chord_a`` = x_b − x_p (the tangent line
    at a), ``d_b`` = x_s − x_b and ``chord_b`` = x_q − x_a (at b), ``d`` = x_s − x_a and
    ``e`` = x_b − x_a (the segment). Returns g (n,), ξ (n,), the gradient (n, 10) and the Hessian
    (n, 10, 10) (None unless asked for) with respect to the positions of (s, p, a, b, q).
    """
    n = len(d)
    g_a, G_a, H_a = gaps_with_derivatives(d_a, chord_a)
    g_b, G_b, H_b = gaps_with_derivatives(d_b, chord_b)
    xi, X1, X2 = segment_parameter(d, e)
    phi, dphi, d2phi = blend(xi)
    delta = g_b - g_a
    g = g_a + phi * delta
    grad_a, grad_b, grad_xi = (np.zeros((n, 10)) for _ in range(3))
    grad_a[:, _AT_A] = G_a
    grad_b[:, _AT_B] = G_b
    grad_xi[:, _XI] = X1
    grad_delta = grad_b - grad_a
    grad = grad_a + phi[:, None] * grad_delta + (dphi * delta)[:, None] * grad_xi
    if not want_hessian:
        return g, xi, grad, None
    hess_a, hess_b, hess_xi = (np.zeros((n, 10, 10)) for _ in range(3))
    hess_a[:, _AT_A[:, None], _AT_A[None, :]] = H_a
    hess_b[:, _AT_B[:, None], _AT_B[None, :]] = H_b
    hess_xi[:, _XI[:, None], _XI[None, :]] = X2
    cross = np.einsum("ni,nj->nij", grad_delta, grad_xi)
    hess = (hess_a + phi[:, None, None] * (hess_b - hess_a)
            + dphi[:, None, None] * (cross + cross.transpose(0, 2, 1))
            + (d2phi * delta)[:, None, None] * np.einsum("ni,nj->nij", grad_xi, grad_xi)
            + (dphi * delta)[:, None, None] * hess_xi)
    return g, xi, grad, hess


@dataclass
class ContactPair:
    """One debond's lips: node indices (into the arrays handed to :func:`evaluate`) and weights.

    :func:`sandwich.plane2d.model.contact_pairs` gives input-mesh node indices (the same on every
    MPI rank); the system renumbers them into its list of contact nodes.
    """

    slave: np.ndarray  # (ns,) face-lip nodes
    master: np.ndarray  # (m,) the core-lip chain, ordered so that n points out of the core
    anchor: np.ndarray  # (ns,) chain position of each slave's coincident core-lip node
    weight: np.ndarray  # (ns,) tributary length of each slave node (mm)
    penalty: float  # k (N/mm³)
    width: float  # b (mm)
    x_ref: np.ndarray  # (ns,) reference x of the slave nodes (for profiles)
    window: np.ndarray | None = None  # (ns, 2) chain positions [lo, hi] the matrix holds
    widen_depth: float = np.inf  # deeper slaves never widen their windows (mm)
    # the slaves a cohesive law holds, one entry per growing tip
    # (:class:`sandwich.plane2d.cohesive.CohesiveLips`, indices into ``slave``)
    cohesive: tuple = ()

    def __post_init__(self):
        """The initial windows: :data:`WINDOW` chain nodes either side of the anchor."""
        if len(self.master) < 2:
            raise ValueError("a debond's core lip needs at least two nodes")
        if self.window is None:
            last = len(self.master) - 1
            self.window = np.column_stack([np.clip(self.anchor - WINDOW, 0, last),
                                           np.clip(self.anchor + WINDOW, 0, last)])

    @property
    def nodes(self) -> np.ndarray:
        """Every node the pair's gaps may depend on (slaves, then the master chain)."""
        return np.concatenate([self.slave, self.master])

    def window_nodes(self, i: int) -> np.ndarray:
        """Slave i and the master nodes of its window (the couplings the matrix holds for it)."""
        lo, hi = self.window[i]
        return np.concatenate([[self.slave[i]], self.master[lo: hi + 1]])

    def widen(self, state: ContactState) -> None:
        """Widen the windows of this pair's slaves in contact at or near their edges (``state``).

        Its ``outside`` slaves left their windows; the slaves in contact whose spans come within
        ``WINDOW // 2`` nodes of an edge of theirs are widened with them (slaves near the one
        that left slide alike). A window is widened on the side it is crowded to hold the span
        and :data:`WINDOW` nodes beyond, so that sliding on does not widen it at every step.
        """
        last = len(self.master) - 1
        act = state.active
        lo, hi = self.window[act, 0], self.window[act, 1]
        p, q = state.spans[act, 0], state.spans[act, 1]
        low, high = p - lo < WINDOW // 2, hi - q < WINDOW // 2
        self.window[act[low], 0] = np.clip(p[low] - WINDOW, 0, last)
        self.window[act[high], 1] = np.clip(q[high] + WINDOW, 0, last)

    def renumbered(self, index: dict[int, int]) -> ContactPair:
        """The same pair with every node n replaced by ``index[n]`` (the windows shared)."""
        def m(a):
            return np.vectorize(lambda k: index[int(k)], otypes=[np.int64])(a)
        return ContactPair(m(self.slave), m(self.master), self.anchor, self.weight,
                           self.penalty, self.width, self.x_ref, self.window, self.widen_depth,
                           self.cohesive)


@dataclass
class ContactState:
    """Result of one contact evaluation (arrays over the slaves, or the active ones, in order)."""

    gap: np.ndarray  # (ns,) signed gaps (mm), negative = penetration
    slip: np.ndarray  # (ns,) sliding: the master point faced, from the slave's own (mm)
    pressure: np.ndarray  # (ns,) p = k ⟨−g⟩ (MPa)
    segment: np.ndarray  # (ns,) chain position a of each slave's segment (a, a + 1)
    xi: np.ndarray  # (ns,) its parameter ξ on the segment
    active: np.ndarray  # (na,) indices of the slaves with g <= 0
    rows: np.ndarray  # (na, 5) their nodes (s, a − 1, a, a + 1, a + 2)
    forces: np.ndarray  # (na, 10) ∂Π/∂X
    tangents: np.ndarray | None  # (na, 10, 10) ∂²Π/∂X² (None unless asked for)
    spans: np.ndarray  # (ns, 2) the chain positions (a − 1, a + 2) of each slave's five nodes
    outside: np.ndarray  # (no,) active slaves, not deeper than widen_depth, out of their window

    def nodal_forces(self, n_nodes: int) -> np.ndarray:
        """The forces summed per node, (n_nodes, 2)."""
        f = np.zeros((n_nodes, 2))
        np.add.at(f, self.rows.ravel(), self.forces.reshape(-1, 2))
        return f


def evaluate(pair: ContactPair, x_ref: np.ndarray, u: np.ndarray,
             want_tangent: bool = True) -> ContactState:
    """Gaps, pressures, forces and tangents at reference positions + displacements (nodes, 2).

    Vectorised over the slaves of the pair. Each slave's segment is found afresh (module
    docstring). Every offset x_i − x_j is formed as (X_i − X_j) + (u_i − u_j): the positions are
    ~10² mm while the gap is ~10⁻⁵ mm, and X + u first would lose the gap to round-off (which the
    stiff penalty turns into a residual floor far above Newton's tolerance).
    """
    s, m = pair.slave, pair.master
    last = len(m) - 1

    def offset(i, j):
        return (x_ref[i] - x_ref[j]) + (u[i] - u[j])

    nearest = cKDTree(x_ref[m] + u[m]).query(x_ref[s] + u[s])[1]
    a = np.minimum(nearest, last - 1)
    e = offset(m[a + 1], m[a])
    ahead = np.einsum("ni,ni->n", offset(s, m[a]), e) / np.einsum("ni,ni->n", e, e)
    a = np.where((ahead < 0.0) & (a == nearest) & (a > 0), a - 1, a)  # the segment behind
    b = a + 1
    p, q = np.maximum(a - 1, 0), np.minimum(b + 1, last)
    d = offset(s, m[a])
    g, xi, grad, hess = blended_gaps(d, offset(m[b], m[p]), offset(s, m[b]), offset(m[q], m[a]),
                                     d, offset(m[b], m[a]), want_hessian=want_tangent)
    # g = 0 counts as active (force 0, tangent k b w ∇g ∇gᵀ, a valid choice at the kink of
    # ⟨−g⟩²): lips that touch in the reference state start supported instead of free
    active = np.flatnonzero(g <= 0.0)
    kw = pair.penalty * pair.width * pair.weight[active]
    ga, grad_a = g[active], grad[active]
    forces = (kw * ga)[:, None] * grad_a
    tangents = None
    if want_tangent:
        tangents = kw[:, None, None] * (np.einsum("na,nb->nab", grad_a, grad_a)
                                        + ga[:, None, None] * hess[active])
    t = x_ref[m[-1]] - x_ref[m[0]]
    t = t / np.linalg.norm(t)
    faced = x_ref[m[a]] + np.clip(xi, 0.0, 1.0)[:, None] * (x_ref[m[b]] - x_ref[m[a]])
    slip = (faced - x_ref[s]) @ t
    pressure = pair.penalty * np.maximum(-g, 0.0)
    rows = np.column_stack([s, m[p], m[a], m[b], m[q]])[active]
    lo, hi = pair.window[active, 0], pair.window[active, 1]
    out = ((p[active] < lo) | (q[active] > hi)) & (g[active] >= -pair.widen_depth)
    outside = active[out]
    return ContactState(g, slip, pressure, a, xi, active, rows, forces, tangents,
                        np.column_stack([p, q]), outside)


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
