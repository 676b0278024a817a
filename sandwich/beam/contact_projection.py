"""Closest-point contact: the face node projected on the deformed core boundary curve.

Node-to-segment (cf. Wriggers, Computational Contact Mechanics, ch. 4 and 8, the
2D node-to-segment element on a curved segment; written here via the implicit function ξ(q)).
On a core segment [x_a, x_b] of length l, ξ ∈ [0, 1], the deformed boundary is

    X(ξ) = (x_a + l ξ + Σ_k N_k(ξ) U_k,  z + Σ_k N_k(ξ) W_k),

N = (H_a, l H̄_a, H_b, l H̄_b) the element's cubic Hermite functions in x (``"H"``, ``"Hbar"`` of
:mod:`sandwich.beam.shape_functions` with η = 2ξ − 1), U = (u_c, u_c,x) and W = (w_c, w_c,x) at
the segment's two nodes. The master point is x_s = (x_i + u_face, z + w_face) (face and core
surfaces coincide in the reference state, so z cancels). With r(ξ) = x_s − X(ξ) and the tangent
X_ξ = (a, c) = (l + Σ N'_k U_k, Σ N'_k W_k), the projection solves

    φ(ξ, q) = r · X_ξ = 0          (Newton: ξ ← ξ − φ/φ_ξ, φ_ξ = −|X_ξ|² + r·X_ξξ),

vectorised over pairs and candidate segments (those within ``reach`` mm on each side of the core
node the master faces, at least one and at most 8 per side: the window follows the sliding,
:func:`~sandwich.beam.contact_search.located`; at most 30 iterations, stopping when every |Δξ| <
1e-12). A candidate counts only if its Newton converged (|φ|/|X_ξ|² ≤ 1e-9) to a ξ in [0, 1];
the chosen one is the nearest (smallest |r|) of those. The core boundary is C¹ across nodes
(shared slope DOFs), so at a node both neighbours give the same point, and between two distinct
projections the nearest rule switches at equal distance, where g = ±|r| agrees. A window moves
when the facing node changes; the projection lies inside both windows then (the window holds ≥ 1
segment on each side of the facing point), so the gap does not notice. If no candidate counts (a
projection farther than the window from the facing point, or beyond a mesh end) the pair is
flagged ``outside`` and held at the nearer end of the searched stretch at fixed ξ (ξ_q = 0): its
gap n·r is the distance to the tangent line at that end, equal to the projection's gap when the
projection leaves through that end (r ∥ n there), so g stays continuous and C¹ (g̃_ξ = 0 there)
along any motion (docs/contact.md: the earlier fallback, an extrapolated "least outside"
segment, made the c3 cantilever's internal force jump).
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
(n and the nodal values are continuous there); its Hessian jumps with the curvature. The
sliding reported is the material distance x(ξ) − x_i of the projection.

The projection is computed by a compiled kernel (:mod:`sandwich.beam.contact_kernel`) where
numba is, else in NumPy (:func:`closest_point_kinematics_numpy`, the equations above written
array-wise), once per state for all the groups of an interface, and kept for the next
evaluation at the same state (:func:`forget_kinematics` drops it).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from sandwich.beam.contact_gap import PairKinematics, gap_derivatives
from sandwich.beam.contact_search import CORE_NODE_ROLES, NORMAL_SIGN, ContactPairs, located
from sandwich.beam.dofs import CONTACT_DOFS, global_dof

PROJECTION_TOL = 1e-12  # |Δξ| at which the projection Newton stops
PROJECTION_MAX_ITERATIONS = 30
PROJECTION_RESIDUAL_TOL = 1e-9  # a candidate counts if |φ| / |X_ξ|² (≈ its remaining |Δξ|) is below
IN_SEGMENT_TOL = 1e-10  # ξ ∈ [−tol, 1 + tol] counts as on the segment


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
class ChosenSegment:
    """Closest-point kinematics on the chosen segment's 10 DOFs (u_f, w_f, U, W)."""

    gap: np.ndarray  # (m,)
    grad: np.ndarray  # (m, 10)
    hess: np.ndarray  # (m, 10, 10)
    cols: np.ndarray  # (m, 10) columns in the block of the pairs they were computed on
    sliding: np.ndarray
    xi: np.ndarray
    segment: np.ndarray
    outside: np.ndarray
    dofs: np.ndarray  # (m, 10) the full DOFs of the 10 columns


def _kept_projection(pairs: ContactPairs, u_full: np.ndarray) -> ChosenSegment:
    """:func:`closest_point_kinematics` of ``pairs`` (located), kept for the next call there."""
    pairs = located(pairs, u_full)
    v = u_full[pairs.support_dofs]
    cached = getattr(pairs, "_last_compact", None)
    if cached is not None and np.array_equal(cached[0], v):
        return cached[1]
    c = closest_point_kinematics(pairs, u_full)
    object.__setattr__(pairs, "_last_compact", (v, c))
    return c


def forget_kinematics(pairs: ContactPairs) -> None:
    """Drop the closest-point kinematics kept for ``pairs`` (and their interface's parent)."""
    for p in (pairs, pairs.parent):
        if p is not None:
            kept = p.__dict__.get("_located")
            for q in (p, None if kept is None else kept[1]):
                if q is not None:
                    q.__dict__.pop("_last_compact", None)
                    q.__dict__.pop("_last", None)


def chosen_segment_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> ChosenSegment:
    """Closest-point kinematics of ``pairs`` on their chosen segments, in their own layout.

    On the windows located at ``u_full`` (:func:`~sandwich.beam.contact_search.located`; the
    columns ``cols`` are in the located block). A group of
    :func:`~sandwich.beam.contact_search.contact_pair_groups` reads its rows of the
    interface's one projection (``parent``) and shifts the block columns to its own, narrower
    block.
    """
    if pairs.parent is None:
        return _kept_projection(pairs, u_full)
    c = _kept_projection(pairs.parent, u_full)
    rows = pairs.parent_rows
    shift = 4 * ((pairs.parent.core_nodes.shape[1] - pairs.core_nodes.shape[1]) // 2)
    cols = c.cols[rows]  # parent slot j ↔ own slot j − k_Δ
    return ChosenSegment(c.gap[rows], c.grad[rows], c.hess[rows],
                         np.where(cols >= 2, cols - shift, cols), c.sliding[rows], c.xi[rows],
                         c.segment[rows] - shift // 4, c.outside[rows], c.dofs[rows])


def _on_block(pairs: ContactPairs, c: ChosenSegment) -> PairKinematics:
    """Place chosen-segment kinematics (own layout) in the pair's whole block."""
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


def pair_block_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> PairKinematics:
    """Closest-point kinematics of ``pairs`` on their whole located blocks.

    The block is ``located(pairs, u_full).block_dofs``
    (:func:`~sandwich.beam.contact_search.located`).
    """
    # the model asks for the force, then the tangent, at the same u: reuse the projection
    here = located(pairs, u_full)
    v = u_full[here.support_dofs]
    cached = here.__dict__.get("_last")
    if cached is not None and np.array_equal(cached[0], v):
        return cached[1]
    k = _on_block(here, chosen_segment_kinematics(pairs, u_full))  # one projection, all groups
    object.__setattr__(here, "_last", (v, k))
    return k


@functools.cache
def closest_point_kernel():
    """The compiled closest-point kinematics, or None without numba.

    :func:`sandwich.beam.contact_kernel.closest_point_kernel`, imported on first use.
    """
    try:
        from sandwich.beam import contact_kernel
    except ImportError:
        return None
    return contact_kernel.closest_point_kernel


def closest_point_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> ChosenSegment:
    """Closest-point kinematics of every pair: compiled where numba is, else NumPy."""
    kernel = closest_point_kernel()
    if kernel is None or pairs.size == 0:
        return closest_point_kinematics_numpy(pairs, u_full)
    v_face = u_full[pairs.dofs[:, :2]]  # (m, 2): u_face, w_face
    x, node_dofs, core_nodes, valid = _kernel_geometry(pairs)
    x_node = x[pairs.nodes]
    out = kernel(x, u_full[node_dofs], core_nodes,  # every core node's (u, u_x, w, w_x)
                 np.ascontiguousarray(x_node + v_face[:, 0]), np.ascontiguousarray(v_face[:, 1]),
                 x_node, valid, NORMAL_SIGN[pairs.interface], PROJECTION_TOL,
                 PROJECTION_MAX_ITERATIONS, PROJECTION_RESIDUAL_TOL, IN_SEGMENT_TOL)
    return ChosenSegment(*out, np.take_along_axis(pairs.support_dofs, out[3], axis=1))


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


def closest_point_kinematics_numpy(pairs: ContactPairs, u_full: np.ndarray) -> ChosenSegment:
    """The NumPy reference of :func:`closest_point_kinematics`: the module docstring's equations."""
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
    gap, dg, d2g = gap_derivatives(r1, r2, a, c, s_n)
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
    return ChosenSegment(gap, grad, hess, cols, sliding, ξs, seg, outside,
                         np.take_along_axis(pairs.support_dofs, cols, axis=1))
