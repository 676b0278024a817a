"""Frictionless unilateral contact on debonded stretches (eqs. 41-42), by a penalty.

Pairing. Nodes strictly inside a debond are untied; at each of them the face's inner surface
point (master) meets the core's boundary curve (slave). Two searches (``contact_pairs(search=)``):

* ``"closest-point"`` (option of ``contact_search`` in :func:`sandwich.beam.model.build_model`,
  docs/contact_search.md): node-to-segment. The master
  point is projected on the deformed core boundary curve, the gap is measured along the slave's
  deformed normal at the projection, and the linearisation includes the motion of the
  projection point (below).
* ``"same-x"`` (the default of ``build_model`` and of :func:`contact_pairs`):
  node-to-node, the core boundary point of the *same material coordinate x*. It assumes small
  relative sliding; the sliding s = t·Δ is returned so a user can check it.

Closest point (node-to-segment; cf. Wriggers, Computational Contact Mechanics, ch. 4 and 8, the
2D node-to-segment element on a curved segment; written here via the implicit function ξ(q)).
On a core segment [x_a, x_b] of length l, ξ ∈ [0, 1], the deformed boundary is

    X(ξ) = (x_a + l ξ + Σ_k N_k(ξ) U_k,  z + Σ_k N_k(ξ) W_k),

N = (H_a, l H̄_a, H_b, l H̄_b) the element's cubic Hermite functions in x (``"H"``, ``"Hbar"`` of
:mod:`sandwich.beam.shape_functions` with η = 2ξ − 1), U = (u_c, u_c,x) and W = (w_c, w_c,x) at
the segment's two nodes. The master point is x_s = (x_i + u_face, z + w_face) (face and core
surfaces coincide in the reference state, so z cancels). With r(ξ) = x_s − X(ξ) and the tangent
X_ξ = (a, c) = (l + Σ N'_k U_k, Σ N'_k W_k), the projection solves

    φ(ξ, q) = r · X_ξ = 0          (Newton: ξ ← ξ − φ/φ_ξ, φ_ξ = −|X_ξ|² + r·X_ξξ),

vectorised over pairs and candidate segments (those within ``reach`` mm on each side of the node,
at least one per side; at most 30 iterations, stopping when every |Δξ| < 1e-12). A candidate
counts only if its Newton converged (|φ|/|X_ξ|² ≤ 1e-9) to a ξ in [0, 1]; the chosen one is the
nearest (smallest |r|) of those. The core boundary is C¹ across nodes (shared slope DOFs), so at a
node both neighbours give the same point, and between two distinct projections the nearest rule
switches at equal distance, where g = ±|r| agrees. If no candidate counts (sliding beyond the
searched reach) the pair is flagged ``outside`` and held at the nearer end of the searched
stretch at fixed ξ (ξ_q = 0): its gap n·r is the distance to the tangent line at that end, equal
to the projection's gap when the projection leaves through that end (r ∥ n there), so g stays
continuous and C¹ (g̃_ξ = 0 there) along any motion (docs/contact_search.md: the earlier
fallback, an extrapolated "least outside" segment, made the c3 cantilever's internal force jump).
The gap along the slave's deformed normal n = s_n (−c, a)/ℓ, ℓ = |X_ξ|, is

    g̃(ξ, q) = n · r = s_n (a r₂ − c r₁)/ℓ,      g(q) = g̃(ξ(q), q),

the same expression as the same-x gap with Δ → r and (1 + u_c,x, w_c,x) → X_ξ (g̃ is homogeneous
of degree 0 in X_ξ). Linearisation: q = (u_face, w_face, U, W) of the segment and y = (ξ, q).
(r₁, r₂, a, c) are linear in q at fixed ξ, so their Jacobian J = ∂(r₁, r₂, a, c)/∂y and their
second derivatives Z (non-zero only in the ξ row and column: ∂²r/∂ξ² = −X_ξξ,
∂²r/∂ξ∂q = −N', ∂²X_ξ/∂ξ² = X_ξξξ, ∂²X_ξ/∂ξ∂q = N'') are closed forms, and the chain rule gives
g̃_y = g̃_z J and g̃_yy = Jᵀ g̃_zz J + Σ_α g̃_α Z_α (z = (r₁, r₂, a, c), g̃_z, g̃_zz as for the same-x
gap). At the projection g̃_ξ = s_n r·n_ξ = 0, since n_ξ ∥ X_ξ ⊥ r; hence

    ∂g/∂q = g̃_q                                    (the normal's and ξ's variations drop),
    ∂²g/∂q² = g̃_qq + g̃_qξ ⊗ ξ_q + ξ_q ⊗ g̃_ξq + g̃_ξξ ξ_q ⊗ ξ_q,   ξ_q = −φ_q/φ_ξ

(implicit function theorem on φ = 0; the g̃_ξ ξ_qq term vanishes with g̃_ξ). The ξ_q terms are
the classical NTS terms of the moving contact point (with the curvature through X_ξξ and
g̃_ξξ); g̃_qq holds the rotation of the normal. The gap is C¹ in q across segment switches
(n and the nodal values are continuous there); its Hessian jumps with the curvature. Force and
tangent act on the pair's block (face node + core nodes of the searched segments), so the sparse
pattern is fixed; :func:`contact_pair_groups` groups an interface's pairs by search width (blocks
no wider than needed on graded meshes) and the projection is computed once for all its groups.
The sliding reported is the material distance x(ξ) − x_i of the projection.

Gap (eq. 42), same-x. The slave boundary's deformed tangent is t ∝ (1 + u_c,x, w_c,x), its
outward normal n = s_n (−w_c,x, 1 + u_c,x)/ℓ with ℓ = |(1 + u_c,x, w_c,x)| and s_n = +1 on the
core's top, −1 on its bottom, i.e. n = s_n(−sin β, cos β) with β the slope angle of eq. (42).
With the displacement jump Δ = (u_face − u_core, w_face − w_core) (face and core surfaces
coincide in the reference state),

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
steps down to ~s (:mod:`sandwich.beam.solve` lowers the step floor accordingly).

What it costs: the penetration at a pressure p is at most c s + p/ε, so with the default
s = 0.002 × bound (1e-6 mm for 0.5 mm faces; offset c s = 2.5e-5 mm) the bound 1e-3 × face
thickness holds wherever p ≤ ε × (bound − c s) (10.6 MPa for the paper's materials). The offset
is what limits s: near a debond tip the face must bend from g = 0 (tied) to g ≈ −c s, which
disturbs the pressure there (squeeze test, 10 mm from the tip: +0.56 % at s = 1e-5 mm,
+0.15 % at 2.5e-6 mm, within 0.1 % at 1e-6 mm; plain penalty 2e-3 %).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from sandwich.beam.dofs import CONTACT_DOFS, global_dof

SEARCHES = ("closest-point", "same-x")
# Local order of a same-x contact pair's six DOFs.
PAIR_ROLES = ("u_face", "w_face", "u_core", "w_core", "u_core,x", "w_core,x")
# Local order of the four DOFs of one core boundary node in a closest-point pair's block.
CORE_NODE_ROLES = ("u_core", "u_core,x", "w_core", "w_core,x")
NORMAL_SIGN = {"top": 1.0, "bottom": -1.0}
DEFAULT_REACH = 1.0  # mm: closest-point search covers at least this far on each side of a node
PROJECTION_TOL = 1e-12  # |Δξ| at which the projection Newton stops
PROJECTION_MAX_ITERATIONS = 30
PROJECTION_RESIDUAL_TOL = 1e-9  # a candidate counts if |φ| / |X_ξ|² (≈ its remaining |Δξ|) is below
IN_SEGMENT_TOL = 1e-10  # ξ ∈ [−tol, 1 + tol] counts as on the segment

# d(Δu, Δw, a = 1 + u_c,x, c = w_c,x) / d(pair DOFs): the chain from gap variables to DOFs.
_D = np.array([
    [1.0, 0.0, -1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, -1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
])


@dataclass(frozen=True)
class ContactPairs:
    """Contact pairs of one interface: one per untied face node (master).

    ``dofs`` are the node's own six same-x DOFs (PAIR_ROLES); the linear analysis
    (:func:`sandwich.beam.solve.linear_solution`) and the same-x search use them. A closest-point
    pair (``search == "closest-point"``) also carries the core boundary nodes ``core_nodes``
    (i − k … i + k, clamped to the mesh) whose segments it searches; its force and tangent live on
    ``block_dofs`` = (u_face, w_face, then CORE_NODE_ROLES of each core node).
    """

    interface: str
    nodes: np.ndarray  # (m,)
    area: np.ndarray  # (m,) tributary area b · l_trib (mm²)
    dofs: np.ndarray  # (m, 6) full DOF indices in PAIR_ROLES order
    search: str = "same-x"
    x: np.ndarray | None = None  # (n_nodes,) reference node coordinates (closest-point)
    core_nodes: np.ndarray | None = None  # (m, 2k + 1) (closest-point)
    segment_valid: np.ndarray | None = None  # (m, 2k): segment j joins core_nodes j and j + 1
    support_dofs: np.ndarray | None = None  # (m, 2 + 4 (2k + 1)) (closest-point)
    # contact_pair_groups: the interface's pairs in one group (widest k), whose projection is
    # computed once for all groups, and this group's rows in it
    parent: ContactPairs | None = None
    parent_rows: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Number of pairs."""
        return int(self.nodes.size)

    @property
    def block_dofs(self) -> np.ndarray:
        """Full DOF indices of the force and tangent blocks of :func:`penalty_response`."""
        return self.dofs if self.search == "same-x" else self.support_dofs


def contact_pairs(
    interface: str, nodes: np.ndarray, x: np.ndarray, width: float, *, search: str = "same-x",
    reach: float = DEFAULT_REACH,
) -> ContactPairs:
    """Pairs at ``nodes`` (indices into the node coordinates ``x``) of a debonded interface.

    ``search`` is ``"same-x"`` (the face node against the core point of the same x) or
    ``"closest-point"`` (the face node projected on the core boundary curve, searched over the
    segments within ``reach`` mm on each side of the node, at least one segment per side).
    """
    if interface not in CONTACT_DOFS:
        raise ValueError(f"interface must be 'top' or 'bottom', got {interface!r}")
    if search not in SEARCHES:
        raise ValueError(f"contact search must be one of {SEARCHES}, got {search!r}")
    x = np.asarray(x, dtype=float)
    nodes = np.asarray(nodes, dtype=int)
    left = np.where(nodes > 0, x[nodes] - x[np.maximum(nodes - 1, 0)], 0.0)
    right = np.where(nodes < x.size - 1, x[np.minimum(nodes + 1, x.size - 1)] - x[nodes], 0.0)
    names = CONTACT_DOFS[interface]
    dofs = np.stack([global_dof(nodes, names[r]) for r in PAIR_ROLES], axis=-1).reshape(-1, 6)
    area = width * 0.5 * (left + right)
    if search == "same-x":
        return ContactPairs(interface, nodes, area, dofs)
    if not (np.isfinite(reach) and reach >= 0):
        raise ValueError(f"contact reach must be >= 0 mm, got {reach!r}")
    # Each node searches the core nodes lo..hi: the segments covering `reach` mm on each side
    # (at least one segment per side, stopping at the mesh ends). A common width 2k + 1 keeps the
    # arrays rectangular; slots beyond a node's own range repeat its end node (no extra coupling
    # in the sparse pattern) and their segments are marked invalid.
    lo, hi = _search_range(nodes, x, reach)
    k = int(max(np.max(nodes - lo, initial=1), np.max(hi - nodes, initial=1)))
    raw = nodes[:, None] + np.arange(-k, k + 1)[None, :]
    core_nodes = np.clip(raw, lo[:, None], hi[:, None])
    valid = (raw[:, :-1] >= lo[:, None]) & (raw[:, 1:] <= hi[:, None])
    core = np.stack([global_dof(core_nodes, names[r]) for r in CORE_NODE_ROLES], axis=-1)
    support = np.concatenate([dofs[:, :2], core.reshape(nodes.size, -1)], axis=1)
    return ContactPairs(interface, nodes, area, dofs, search, x, core_nodes, valid, support)


def _search_range(nodes: np.ndarray, x: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """First and last core node each face node searches: ``reach`` mm each side, ≥ 1 segment."""
    tol = 1e-12 * (x[-1] - x[0])
    lo = np.searchsorted(x, x[nodes] - reach + tol, side="right") - 1
    lo = np.clip(np.minimum(lo, nodes - 1), 0, None)
    hi = np.searchsorted(x, x[nodes] + reach - tol, side="left")
    hi = np.clip(np.maximum(hi, nodes + 1), None, x.size - 1)
    return lo, hi


def contact_pair_groups(
    interface: str, nodes: np.ndarray, x: np.ndarray, width: float, *, search: str = "same-x",
    reach: float = DEFAULT_REACH,
) -> list[ContactPairs]:
    """:func:`contact_pairs` split so that each group's blocks are no wider than needed.

    A closest-point pair's block spans the core nodes within ``reach`` of its node, so on a
    graded mesh the width varies node to node; one rectangular group would give every pair the
    widest block. Nodes are grouped by their search half-width k rounded up to a power of two
    (at most a few groups, each block at most twice its needed width). Same-x: one group.
    """
    x = np.asarray(x, dtype=float)
    nodes = np.asarray(nodes, dtype=int)
    if search != "closest-point" or nodes.size == 0:
        return [contact_pairs(interface, nodes, x, width, search=search, reach=reach)]
    parent = contact_pairs(interface, nodes, x, width, search=search, reach=reach)  # checks
    lo, hi = _search_range(nodes, x, reach)  # the half-width each node needs, as contact_pairs
    k = np.maximum(np.maximum(nodes - lo, hi - nodes), 1)
    bins = 2 ** np.ceil(np.log2(k)).astype(int)
    groups = []
    for b in np.unique(bins):
        rows = np.flatnonzero(bins == b)
        g = contact_pairs(interface, nodes[rows], x, width, search=search, reach=reach)
        groups.append(dataclasses.replace(g, parent=parent, parent_rows=rows))
    return groups


@dataclass(frozen=True)
class PairKinematics:
    """Gap g, its gradient and Hessian on the pair's block DOFs, and the tangential sliding."""

    gap: np.ndarray  # (m,) mm, negative = penetration
    grad: np.ndarray  # (m, n) on ContactPairs.block_dofs
    hess: np.ndarray  # (m, n, n)
    sliding: np.ndarray  # (m,) mm
    xi: np.ndarray | None = None  # (m,) closest point's coordinate on its segment, [0, 1]
    segment: np.ndarray | None = None  # (m,) chosen segment (local index)
    outside: np.ndarray | None = None  # (m,) bool: no searched segment holds the projection


def _gap_derivatives(
    r1: np.ndarray, r2: np.ndarray, a: np.ndarray, c: np.ndarray, s_n: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap g = s_n (a r2 − c r1)/√(a² + c²) with gradient and Hessian in (r1, r2, a, c)."""
    ℓ = np.sqrt(a**2 + c**2)
    q = -c * r1 + a * r2  # ℓ n·r / s_n
    z = np.zeros_like(ℓ)
    dq = np.stack([-c, a, r2, -r1], axis=-1)
    dℓ = np.stack([z, z, a / ℓ, c / ℓ], axis=-1)
    d2q = np.zeros((*ℓ.shape, 4, 4))
    d2q[..., 0, 3] = d2q[..., 3, 0] = -1.0
    d2q[..., 1, 2] = d2q[..., 2, 1] = 1.0
    d2ℓ = np.zeros((*ℓ.shape, 4, 4))
    d2ℓ[..., 2, 2], d2ℓ[..., 3, 3] = c**2 / ℓ**3, a**2 / ℓ**3
    d2ℓ[..., 2, 3] = d2ℓ[..., 3, 2] = -a * c / ℓ**3
    ℓ1, q1 = ℓ[..., None], q[..., None]
    dg = s_n * (dq / ℓ1 - q1 * dℓ / ℓ1**2)
    cross = dq[..., :, None] * dℓ[..., None, :]
    d2g = s_n * (
        d2q / ℓ1[..., None]
        - (cross + np.swapaxes(cross, -1, -2)) / (ℓ1**2)[..., None]
        - (q1 / ℓ1**2)[..., None] * d2ℓ
        + (2 * q1 / ℓ1**3)[..., None] * dℓ[..., :, None] * dℓ[..., None, :]
    )
    return s_n * q / ℓ, dg, d2g


def pair_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> PairKinematics:
    """Gap along the slave's deformed normal, eq. (42), with first and second derivatives."""
    if pairs.search == "closest-point":
        # the model asks for the force, then the tangent, at the same u: reuse the projection
        v = u_full[pairs.support_dofs]
        cached = getattr(pairs, "_last", None)
        if cached is not None and np.array_equal(cached[0], v):
            return cached[1]
        k = _scatter(pairs, _own_compact(pairs, u_full))  # one projection for all groups
        object.__setattr__(pairs, "_last", (v, k))
        return k
    v = u_full[pairs.dofs]  # (m, 6)
    Δu, Δw = v[:, 0] - v[:, 2], v[:, 1] - v[:, 3]
    a, c = 1.0 + v[:, 4], v[:, 5]  # slave tangent (1 + u_c,x, w_c,x)
    gap, dg, d2g = _gap_derivatives(Δu, Δw, a, c, NORMAL_SIGN[pairs.interface])
    sliding = (a * Δu + c * Δw) / np.sqrt(a**2 + c**2)
    return PairKinematics(gap, dg @ _D, _D.T @ d2g @ _D, sliding)  # Dᵀ (d²g) D per pair


def hermite_basis(xi: np.ndarray, length: np.ndarray, orders: int = 4) -> np.ndarray:
    """Cubic Hermite functions on a segment, ξ ∈ [0, 1], and their ξ-derivatives 0 … orders − 1.

    Returns (orders, …, 4): derivative order × the functions multiplying (value at node a, slope
    at a, value at b, slope at b) with the slopes physical (d/dx), i.e. the slope functions carry
    the segment length. These are the element's ``"H"``/``"Hbar"`` x-functions of
    :mod:`sandwich.beam.shape_functions` with η = 2ξ − 1 (checked in the tests).
    """
    ξ = np.asarray(xi, dtype=float)
    l = np.broadcast_to(np.asarray(length, dtype=float), ξ.shape)
    ξ2 = ξ * ξ
    ξ3 = ξ2 * ξ
    out = np.empty((orders, *ξ.shape, 4))
    out[0, ..., 0] = 1 - 3 * ξ2 + 2 * ξ3
    out[0, ..., 1] = l * (ξ - 2 * ξ2 + ξ3)
    out[0, ..., 2] = 3 * ξ2 - 2 * ξ3
    out[0, ..., 3] = l * (ξ3 - ξ2)
    if orders > 1:
        out[1, ..., 0] = 6 * (ξ2 - ξ)
        out[1, ..., 1] = l * (1 - 4 * ξ + 3 * ξ2)
        out[1, ..., 2] = -out[1, ..., 0]
        out[1, ..., 3] = l * (3 * ξ2 - 2 * ξ)
    if orders > 2:
        out[2, ..., 0] = 12 * ξ - 6
        out[2, ..., 1] = l * (6 * ξ - 4)
        out[2, ..., 2] = -out[2, ..., 0]
        out[2, ..., 3] = l * (6 * ξ - 2)
    if orders > 3:
        out[3, ..., 0], out[3, ..., 2] = 12.0, -12.0
        out[3, ..., 1] = out[3, ..., 3] = 6 * l
    return out


def _segment_geometry(pairs: ContactPairs, u_full: np.ndarray):
    """Per pair and candidate segment: ends, length, nodal (U, W) and the master's point."""
    x = pairs.x
    v_face = u_full[pairs.dofs[:, :2]]  # (m, 2): u_face, w_face
    core = u_full[pairs.support_dofs[:, 2:]].reshape(pairs.size, -1, 4)  # (m, n_c, 4)
    xa, xb = x[pairs.core_nodes[:, :-1]], x[pairs.core_nodes[:, 1:]]
    length = np.where(pairs.segment_valid, xb - xa, 1.0)
    # U = (u_a, u_a,x, u_b, u_b,x), W = (w_a, w_a,x, w_b, w_b,x) per segment
    U = np.concatenate([core[:, :-1, 0:2], core[:, 1:, 0:2]], axis=-1)
    W = np.concatenate([core[:, :-1, 2:4], core[:, 1:, 2:4]], axis=-1)
    xs = x[pairs.nodes][:, None] + v_face[:, 0:1]  # master point, x (the z offsets cancel)
    return xa, length, U, W, xs, v_face[:, 1:2]


@dataclass(frozen=True)
class _Compact:
    """Closest-point kinematics on the chosen segment's 10 DOFs (u_f, w_f, U, W)."""

    gap: np.ndarray  # (m,)
    grad: np.ndarray  # (m, 10)
    hess: np.ndarray  # (m, 10, 10)
    cols: np.ndarray  # (m, 10) columns in the block of the pairs they were computed on
    sliding: np.ndarray
    xi: np.ndarray
    segment: np.ndarray
    outside: np.ndarray


def _cached_compact(pairs: ContactPairs, u_full: np.ndarray) -> _Compact:
    v = u_full[pairs.support_dofs]
    cached = getattr(pairs, "_last_compact", None)
    if cached is not None and np.array_equal(cached[0], v):
        return cached[1]
    c = _compact_kinematics(pairs, u_full)
    object.__setattr__(pairs, "_last_compact", (v, c))
    return c


def forget_kinematics(pairs: ContactPairs) -> None:
    """Drop the closest-point kinematics kept for ``pairs`` (and their interface's parent)."""
    for p in (pairs, pairs.parent):
        if p is not None:
            p.__dict__.pop("_last_compact", None)
            p.__dict__.pop("_last", None)


def gap_change(
    pairs: ContactPairs, u_full: np.ndarray, du_full: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's gap g at ``u_full`` and its linearised change ∂g/∂u · du along ``du_full``.

    Closest-point pairs on their chosen segments (the projection at ``u_full`` is the one the
    force evaluation there made, reused); same-x pairs on their six DOFs.
    """
    if pairs.search == "closest-point":
        c = _own_compact(pairs, u_full)
        dofs = np.take_along_axis(pairs.support_dofs, c.cols, axis=1)
        return c.gap, np.einsum("ij,ij->i", c.grad, du_full[dofs])
    k = pair_kinematics(pairs, u_full)
    return k.gap, np.einsum("ij,ij->i", k.grad, du_full[pairs.block_dofs])


def _own_compact(pairs: ContactPairs, u_full: np.ndarray) -> _Compact:
    """Closest-point kinematics of ``pairs`` on their chosen segments, in their own layout.

    A group of :func:`contact_pair_groups` reads its rows of the interface's one projection
    (``parent``) and shifts the block columns to its own, narrower block.
    """
    if pairs.parent is None:
        return _cached_compact(pairs, u_full)
    c = _cached_compact(pairs.parent, u_full)
    rows = pairs.parent_rows
    shift = 4 * ((pairs.parent.core_nodes.shape[1] - pairs.core_nodes.shape[1]) // 2)
    cols = c.cols[rows]  # parent slot j ↔ own slot j − k_Δ
    return _Compact(c.gap[rows], c.grad[rows], c.hess[rows],
                    np.where(cols >= 2, cols - shift, cols), c.sliding[rows], c.xi[rows],
                    c.segment[rows] - shift // 4, c.outside[rows])


def _scatter(pairs: ContactPairs, c: _Compact) -> PairKinematics:
    """Place compact kinematics (own layout) in the pair's whole block."""
    m = pairs.size
    n = pairs.support_dofs.shape[1]
    g_full = np.zeros((m, n))
    h_full = np.zeros((m, n, n))
    r = np.arange(m)
    g_full[r[:, None], c.cols] = c.grad
    h_full[r[:, None, None], c.cols[:, :, None], c.cols[:, None, :]] = c.hess
    return PairKinematics(c.gap, g_full, h_full, c.sliding, c.xi, c.segment, c.outside)


def _projection_residual(ξ, l, xa, U, W, xs, ws):
    """φ = r·X_ξ, φ_ξ and X_ξ = (a, c) on every candidate segment at ξ."""
    N = hermite_basis(ξ, l, orders=3)  # (3, m, s, 4)
    r1 = xs - (xa + l * ξ + np.sum(N[0] * U, -1))
    r2 = ws - np.sum(N[0] * W, -1)
    a, c = l + np.sum(N[1] * U, -1), np.sum(N[1] * W, -1)
    aξ, cξ = np.sum(N[2] * U, -1), np.sum(N[2] * W, -1)
    return r1 * a + r2 * c, -(a**2 + c**2) + r1 * aξ + r2 * cξ, a, c


@functools.cache
def _contact_kernel(name: str):
    """A compiled function of :mod:`sandwich.beam.contact_kernel`, or None without numba."""
    try:
        from sandwich.beam import contact_kernel
    except ImportError:
        return None
    return getattr(contact_kernel, name)


def _closest_point_kernel():
    """The compiled closest-point kinematics, or None without numba."""
    return _contact_kernel("closest_point_kernel")


def _penalty_kernel():
    """The compiled penalty blocks, or None without numba."""
    return _contact_kernel("penalty_blocks")


def _compact_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> _Compact:
    """Closest-point kinematics of every pair: compiled where numba is, else NumPy."""
    kernel = _closest_point_kernel()
    if kernel is None or pairs.size == 0:
        return _compact_kinematics_numpy(pairs, u_full)
    v_face = u_full[pairs.dofs[:, :2]]  # (m, 2): u_face, w_face
    x, node_dofs, core_nodes, valid = _kernel_geometry(pairs)
    x_node = x[pairs.nodes]
    out = kernel(x, u_full[node_dofs], core_nodes,  # every core node's (u, u_x, w, w_x)
                 np.ascontiguousarray(x_node + v_face[:, 0]), np.ascontiguousarray(v_face[:, 1]),
                 x_node, valid, NORMAL_SIGN[pairs.interface], PROJECTION_TOL,
                 PROJECTION_MAX_ITERATIONS, PROJECTION_RESIDUAL_TOL, IN_SEGMENT_TOL)
    return _Compact(*out)


def _kernel_geometry(pairs: ContactPairs) -> tuple[np.ndarray, ...]:
    """The kernel's fixed inputs, formed once per pairs.

    Node x, the core boundary DOFs of every node (n, 4) in CORE_NODE_ROLES order, the windows
    and their valid segments.
    """
    cached = pairs.__dict__.get("_kernel_geometry")
    if cached is None:
        names = CONTACT_DOFS[pairs.interface]
        every = np.arange(pairs.x.size)
        node_dofs = np.stack([global_dof(every, names[r]) for r in CORE_NODE_ROLES], axis=-1)
        cached = (np.ascontiguousarray(pairs.x, dtype=float), node_dofs,
                  np.ascontiguousarray(pairs.core_nodes, dtype=np.int64),
                  np.ascontiguousarray(pairs.segment_valid))
        object.__setattr__(pairs, "_kernel_geometry", cached)
    return cached


def _compact_kinematics_numpy(pairs: ContactPairs, u_full: np.ndarray) -> _Compact:
    """The NumPy reference of :func:`_compact_kinematics` (the module docstring's equations)."""
    m = pairs.size
    xa, l, U, W, xs, ws = _segment_geometry(pairs, u_full)
    x_node = pairs.x[pairs.nodes][:, None]
    valid = pairs.segment_valid
    # Newton for φ(ξ) = r·X_ξ = 0 on every candidate segment, from the node's own x (clamped);
    # iterations stop when every candidate that can still hold its projection has settled
    ξ = np.clip((x_node - xa) / l, 0.0, 1.0)
    for _ in range(PROJECTION_MAX_ITERATIONS):
        φ, φξ, a, c = _projection_residual(ξ, l, xa, U, W, xs, ws)
        φξ = np.where(φξ < -1e-3 * (a**2 + c**2), φξ, -(a**2 + c**2))  # keep the descent
        new = np.clip(ξ + np.clip(-φ / φξ, -0.5, 0.5), -0.5, 1.5)
        change = np.max(np.abs(new - ξ), initial=0.0, where=valid)
        ξ = new
        if change < PROJECTION_TOL:
            break
    # a candidate counts only if its Newton converged (|φ| / |X_ξ|² = the remaining |Δξ|) and
    # its projection lies on the segment
    φ, _, a, c = _projection_residual(ξ, l, xa, U, W, xs, ws)
    converged = np.abs(φ) <= PROJECTION_RESIDUAL_TOL * (a**2 + c**2)
    inside = valid & converged & (ξ >= -IN_SEGMENT_TOL) & (ξ <= 1 + IN_SEGMENT_TOL)
    N = hermite_basis(ξ, l, orders=1)
    r1 = xs - (xa + l * ξ + np.sum(N[0] * U, -1))
    r2 = ws - np.sum(N[0] * W, -1)
    dist = np.hypot(r1, r2)
    outside = ~inside.any(axis=1)
    seg = np.argmin(np.where(inside, dist, np.inf), axis=1)
    if outside.any():
        # No projection on the searched curve: the nearer end of the searched stretch, at fixed
        # ξ (0 on the first valid segment, 1 on the last). The gap there, n·r, is the distance
        # to the tangent line at that end; it equals the projection's gap when the projection
        # leaves through that end (r ∥ n there), so the gap stays continuous (and C¹: g̃_ξ = 0)
        first = np.argmax(valid, axis=1)
        last = valid.shape[1] - 1 - np.argmax(valid[:, ::-1], axis=1)
        ends = []
        for j, e in ((first, 0.0), (last, 1.0)):
            r = np.arange(m)
            Ne = hermite_basis(np.full(m, e), l[r, j], orders=1)[0]
            Xe = xa[r, j] + l[r, j] * e + np.sum(Ne * U[r, j], -1)
            ends.append(np.hypot(xs[:, 0] - Xe, ws[:, 0] - np.sum(Ne * W[r, j], -1)))
        right = ends[1] < ends[0]
        end_seg = np.where(right, last, first)
        seg = np.where(outside, end_seg, seg)
        ξ = ξ.copy()
        ξ[outside, seg[outside]] = np.where(right, 1.0, 0.0)[outside]
    rows = np.arange(m)
    ξs, ls, Us, Ws = ξ[rows, seg], l[rows, seg], U[rows, seg], W[rows, seg]
    N = hermite_basis(ξs, ls)  # (4, m, 4)
    r1 = xs[:, 0] - (xa[rows, seg] + ls * ξs + np.sum(N[0] * Us, -1))
    r2 = ws[:, 0] - np.sum(N[0] * Ws, -1)
    a, c = ls + np.sum(N[1] * Us, -1), np.sum(N[1] * Ws, -1)
    aξ, cξ = np.sum(N[2] * Us, -1), np.sum(N[2] * Ws, -1)
    aξξ, cξξ = np.sum(N[3] * Us, -1), np.sum(N[3] * Ws, -1)
    s_n = NORMAL_SIGN[pairs.interface]
    gap, dg, d2g = _gap_derivatives(r1, r2, a, c, s_n)
    # Variables y = (ξ, u_f, w_f, U0..U3, W0..W3); J = ∂(r1, r2, a, c)/∂y, Z_α = ∂²(·)_α/∂y²:
    # ∂²r/∂ξ² = −X_ξξ, ∂²r/∂ξ∂(U, W) = −N', ∂²X_ξ/∂ξ² = X_ξξξ, ∂²X_ξ/∂ξ∂(U, W) = N''.
    J = np.zeros((m, 4, 11))
    J[:, 0, 0], J[:, 0, 1], J[:, 0, 3:7] = -a, 1.0, -N[0]
    J[:, 1, 0], J[:, 1, 2], J[:, 1, 7:11] = -c, 1.0, -N[0]
    J[:, 2, 0], J[:, 2, 3:7] = aξ, N[1]
    J[:, 3, 0], J[:, 3, 7:11] = cξ, N[1]
    # Σ_α g̃_α Z_α: only the ξ row and column are non-zero
    Zg = np.zeros((m, 11, 11))
    Zg[:, 0, 0] = -dg[:, 0] * aξ - dg[:, 1] * cξ + dg[:, 2] * aξξ + dg[:, 3] * cξξ
    Zg[:, 0, 3:7] = -dg[:, 0, None] * N[1] + dg[:, 2, None] * N[2]
    Zg[:, 0, 7:11] = -dg[:, 1, None] * N[1] + dg[:, 3, None] * N[2]
    Zg[:, 1:, 0] = Zg[:, 0, 1:]
    Jt = J.transpose(0, 2, 1)
    G = (dg[:, None, :] @ J)[:, 0]  # ∂g̃/∂y
    H = Jt @ d2g @ J + Zg
    dφ = np.stack([a, c, r1, r2], axis=-1)  # ∂φ/∂(r1, r2, a, c), φ = r1 a + r2 c
    Φ = (dφ[:, None, :] @ J)[:, 0]
    ξq = -Φ[:, 1:] / Φ[:, :1]  # dξ/dq from φ(ξ(q), q) = 0
    ξq[outside] = 0.0  # beyond the searched stretch ξ stays at its end
    grad = G[:, 1:]  # + g̃_ξ ξ_q, zero at the projection (g̃_ξ = s_n r·n_ξ ∝ φ) and outside
    hess = (H[:, 1:, 1:] + H[:, 1:, :1] * ξq[:, None, :] + ξq[:, :, None] * H[:, :1, 1:]
            + H[:, :1, :1] * ξq[:, :, None] * ξq[:, None, :])
    # the block columns of the segment's 10 DOFs
    base = 2 + 4 * seg[:, None]
    cols = np.concatenate([np.zeros((m, 1), int), np.ones((m, 1), int),
                           base + np.array([0, 1, 4, 5]), base + np.array([2, 3, 6, 7])], axis=1)
    sliding = xa[rows, seg] + ls * ξs - x_node[:, 0]
    return _Compact(gap, grad, hess, cols, sliding, ξs, seg, outside)


SHIFT = 25.0  # c: the softplus is centred at g = −c s, so dp/dg jumps by only ε e⁻²⁵ at g = 0


def pressure_law(
    gap: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Contact pressure p(g) (MPa) and its derivative dp/dg (N/mm³) of the shifted softplus.

    ``penalty`` is ε (N/mm³), ``smoothing`` the width s (mm) of the regularisation (see the
    module docstring); s = 0 is the plain penalty ε ⟨−g⟩.
    """
    _check_law(penalty, smoothing)
    g = np.asarray(gap, dtype=float)
    if smoothing == 0:
        return penalty * np.maximum(-g, 0.0), np.where(g < 0, -penalty, 0.0)
    closed = g < 0
    x = -np.minimum(g, 0.0) / smoothing - SHIFT
    p = penalty * smoothing * (_softplus(x) - _softplus(-SHIFT))
    dp = -penalty * 0.5 * (1.0 + np.tanh(0.5 * x))  # −ε / (1 + e⁻ˣ)
    return np.where(closed, p, 0.0), np.where(closed, dp, 0.0)


def _check_law(penalty: float, smoothing: float) -> None:
    if not (np.isfinite(penalty) and penalty > 0):
        raise ValueError(f"contact penalty must be positive, got {penalty!r}")
    if not (np.isfinite(smoothing) and smoothing >= 0):
        raise ValueError(f"contact smoothing must be >= 0 mm, got {smoothing!r}")


def _softplus(x: np.ndarray | float) -> np.ndarray:
    """ln(1 + eˣ) without overflow."""
    return np.maximum(x, 0.0) + np.log1p(np.exp(-np.abs(x)))


def _softplus_integral(x: np.ndarray | float) -> np.ndarray:
    """∫_−∞^x ln(1 + eᵗ) dt = −Li₂(−eˣ), with Li₂(z) = ``scipy.special.spence(1 − z)``.

    For x > 0 the inversion formula −Li₂(−eˣ) = π²/6 + x²/2 + Li₂(−e⁻ˣ) avoids overflowing eˣ.
    """
    from scipy.special import spence

    x = np.asarray(x, dtype=float)
    a = np.abs(x)
    low = -spence(1.0 + np.exp(-a))  # the integral at −|x|
    return np.where(x > 0, np.pi**2 / 6 + 0.5 * a**2 - low, low)


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
    f, K, p = _penalty_blocks(k.gap, k.grad, k.hess, pairs.area, penalty, smoothing)
    return f, K, p, k


def _penalty_blocks(
    gap: np.ndarray, grad: np.ndarray, hess: np.ndarray, area: np.ndarray, penalty: float,
    smoothing: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force −p A ∂g, tangent −A p'(g) ∂g ∂gᵀ − p A ∂²g and pressure p of each pair.

    Compiled (:func:`sandwich.beam.contact_kernel.penalty_blocks`, the same law per pair) where
    numba is, else in NumPy from :func:`pressure_law`.
    """
    kernel = _penalty_kernel()
    if kernel is not None and gap.size:
        _check_law(penalty, smoothing)
        return kernel(np.ascontiguousarray(gap, dtype=float),
                      np.ascontiguousarray(grad, dtype=float),
                      np.ascontiguousarray(hess, dtype=float),
                      np.ascontiguousarray(area, dtype=float), float(penalty), float(smoothing),
                      SHIFT)
    return _penalty_blocks_numpy(gap, grad, hess, area, penalty, smoothing)


def _penalty_blocks_numpy(
    gap: np.ndarray, grad: np.ndarray, hess: np.ndarray, area: np.ndarray, penalty: float,
    smoothing: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_penalty_blocks` in NumPy (the reference the compiled one is tested against)."""
    p, dp = pressure_law(gap, penalty, smoothing)  # eq. (41): contact pressure, MPa
    f = -(p * area)[:, None] * grad
    K = (-dp * area)[:, None, None] * grad[:, :, None] * grad[:, None, :]
    K -= (p * area)[:, None, None] * hess
    return f, K, p


def compact_response(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics, np.ndarray]:
    """Closest-point pairs: :func:`penalty_response` on each pair's chosen segment only.

    Returns forces (m, 10), tangents (m, 10, 10), pressures (m,), the kinematics (gap,
    sliding, ξ, segment, outside; gradient and Hessian on the 10 DOFs) and the 10 DOFs'
    columns in the pair's block (``block_dofs``). The same numbers as the blocks of
    :func:`penalty_response` at those DOFs (its other entries are zero), without forming the
    (m, n, n) blocks: on a fine mesh the 1 mm reach spans dozens of segments.
    """
    if pairs.search != "closest-point":
        raise ValueError("compact_response is for closest-point pairs")
    c = _own_compact(pairs, u_full)
    f, K, p = _penalty_blocks(c.gap, c.grad, c.hess, pairs.area, penalty, smoothing)
    k = PairKinematics(c.gap, c.grad, c.hess, c.sliding, c.xi, c.segment, c.outside)
    return f, K, p, k, c.cols


def contact_state(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, PairKinematics]:
    """Pressures (m,) MPa and kinematics of the pairs (gap, sliding, …), without the blocks.

    Closest-point pairs through :func:`compact_response` (no (m, n, n) block is formed).
    """
    if pairs.search == "closest-point":
        return compact_response(pairs, u_full, penalty, smoothing)[2:4]
    return penalty_response(pairs, u_full, penalty, smoothing)[2:4]
