"""Contact pairs on debonded stretches: which face node meets which stretch of the core.

Nodes strictly inside a debond are untied; at each of them the face's inner surface point
(master) meets the core's boundary curve (slave). Two searches (``contact_pairs(search=)``):

* ``"closest-point"`` (option of ``contact_search`` in :func:`sandwich.beam.build.build_model`,
  docs/contact.md): node-to-segment. The master point is projected on the deformed core
  boundary curve, the gap is measured along the slave's deformed normal at the projection, and
  the linearisation includes the motion of the projection point
  (:mod:`sandwich.beam.contact_projection`).
* ``"same-x"`` (the default of :func:`contact_pairs`): node-to-node, the core boundary point of
  the *same material coordinate x* (:mod:`sandwich.beam.contact_gap`). It assumes small relative
  sliding; the sliding s = t·Δ is returned so a user can check it.

The closest-point search follows the sliding: its window of core segments (``reach`` mm on each
side, at least one segment) is centred, at every evaluation, on the core node the master point
faces in the deformed state — the node whose deformed x (x + u_c) is nearest the master's
(:func:`located`) — not on the master's own node. A face may slide any distance along the core;
the window only has to hold the projection's offset from the facing point (the gap times the
slope), so its width, and each pair's work, does not grow with the sliding. A closest-point
pair's force and tangent act on its chosen segment (:mod:`sandwich.beam.contact_projection`);
its block is the located window's (face node + core nodes). :func:`contact_pair_groups`
groups an interface's pairs by search width (blocks no wider than needed on graded meshes) and
the projection is computed once for all its groups.
"""

from __future__ import annotations

import dataclasses
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
#: ... in at most this many segments. The window follows the sliding (:func:`located`), so it
#: only has to hold the projection's offset from the node faced: nil for a pair in contact (a
#: pair open by g is offset by about g times the core's slope, and carries no force). The cap
#: keeps a pair's work and memory independent of the element size (at 16 000 elements the
#: default scene's 1 mm spanned 259 segments: 10 357 pairs × 519 nodes, 2.2 GB).
MAX_WINDOW = 8


@dataclass(frozen=True)
class ContactPairs:
    """Contact pairs of one interface: one per untied face node (master).

    ``dofs`` are the node's own six same-x DOFs (PAIR_ROLES); the linear analysis
    (:func:`sandwich.beam.linear_step.linear_solution`) and the same-x search use them. A
    closest-point pair (``search == "closest-point"``) also carries the core boundary nodes
    ``core_nodes`` (c − k … c + k, clamped to the mesh) whose segments it searches, c the node
    it faces (its own node at rest; :func:`located` gives the pairs at a deformed state); its
    force and tangent live on ``block_dofs`` = (u_face, w_face, then CORE_NODE_ROLES of each
    core node). ``half_width`` (m,): each pair's own search half-width in segments.
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
    half_width: np.ndarray | None = None  # (m,) closest-point: segments searched on each side
    # a growing tip's cohesive pairs (same-x): their law and damage
    # (:class:`sandwich.beam.cohesive.CohesiveZone`); None: contact pairs
    cohesive: object | None = None

    @property
    def size(self) -> int:
        """Number of pairs."""
        return int(self.nodes.size)

    @property
    def block_dofs(self) -> np.ndarray:
        """Full DOF indices of the force and tangent blocks (:mod:`~sandwich.beam.contact`)."""
        return self.dofs if self.search == "same-x" else self.support_dofs


def contact_pairs(
    interface: str, nodes: np.ndarray, x: np.ndarray, width: float, *, search: str = "same-x",
    reach: float = DEFAULT_REACH,
) -> ContactPairs:
    """Pairs at ``nodes`` (indices into the node coordinates ``x``) of a debonded interface.

    ``search`` is ``"same-x"`` (the face node against the core point of the same x) or
    ``"closest-point"`` (the face node projected on the core boundary curve, searched over the
    segments within ``reach`` mm on each side of the node it faces, at least one segment and at
    most ``MAX_WINDOW`` per side).
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
    # (at least one segment and at most MAX_WINDOW per side, stopping at the mesh ends). A
    # common width 2k + 1 keeps the arrays rectangular; slots beyond a node's own range repeat
    # its end node (no extra coupling in the sparse pattern) and their segments are marked
    # invalid.
    lo, hi = _search_range(nodes, x, reach)
    k = int(max(np.max(nodes - lo, initial=1), np.max(hi - nodes, initial=1)))
    raw = nodes[:, None] + np.arange(-k, k + 1)[None, :]
    core_nodes = np.clip(raw, lo[:, None], hi[:, None])
    valid = (raw[:, :-1] >= lo[:, None]) & (raw[:, 1:] <= hi[:, None])
    half = np.maximum(np.maximum(nodes - lo, hi - nodes), 1)
    return ContactPairs(interface, nodes, area, dofs, search, x, core_nodes, valid,
                        _support(interface, dofs, core_nodes), half_width=half)


def _support(interface: str, dofs: np.ndarray, core_nodes: np.ndarray) -> np.ndarray:
    """Block DOFs of closest-point pairs: (u_face, w_face), then each core node's four."""
    names = CONTACT_DOFS[interface]
    core = np.stack([global_dof(core_nodes, names[r]) for r in CORE_NODE_ROLES], axis=-1)
    return np.concatenate([dofs[:, :2], core.reshape(dofs.shape[0], -1)], axis=1)


def facing_nodes(pairs: ContactPairs, u_full: np.ndarray) -> np.ndarray:
    """The core node each closest-point pair's master point faces at ``u_full``.

    The node whose deformed x, x + u_c, is nearest the master's x_i + u_face (the deformed
    node positions made non-decreasing first, so that a sheared core cannot break the search).
    """
    x = pairs.x
    core_u = pairs.__dict__.get("_core_u_dofs")
    if core_u is None:
        core_u = global_dof(np.arange(x.size), CONTACT_DOFS[pairs.interface]["u_core"])
        object.__setattr__(pairs, "_core_u_dofs", core_u)
    X = np.maximum.accumulate(x + u_full[core_u])
    xs = x[pairs.nodes] + u_full[pairs.dofs[:, 0]]
    j = np.clip(np.searchsorted(X, xs), 1, x.size - 1)
    return np.where(xs - X[j - 1] < X[j] - xs, j - 1, j)


def located(pairs: ContactPairs, u_full: np.ndarray) -> ContactPairs:
    """Closest-point ``pairs`` with each window centred on the node it faces at ``u_full``.

    The window keeps its width (``core_nodes.shape[1]``) and each pair its own half-width
    (``half_width`` segments each side of the facing node, clamped to the mesh). ``pairs``
    itself where every pair faces its own node (at rest); the last located pairs are kept
    for the next call with the same facing nodes. Same-x pairs: ``pairs``.
    """
    if pairs.search != "closest-point" or pairs.size == 0:
        return pairs
    centre = facing_nodes(pairs, u_full)
    if np.array_equal(centre, pairs.nodes):
        return pairs
    cached = pairs.__dict__.get("_located")
    if cached is not None and np.array_equal(cached[0], centre):
        return cached[1]
    k = pairs.core_nodes.shape[1] // 2
    lo = np.maximum(centre - pairs.half_width, 0)
    hi = np.minimum(centre + pairs.half_width, pairs.x.size - 1)
    raw = centre[:, None] + np.arange(-k, k + 1)[None, :]
    core_nodes = np.clip(raw, lo[:, None], hi[:, None])
    valid = (raw[:, :-1] >= lo[:, None]) & (raw[:, 1:] <= hi[:, None])
    out = dataclasses.replace(pairs, core_nodes=core_nodes, segment_valid=valid,
                              support_dofs=_support(pairs.interface, pairs.dofs, core_nodes))
    object.__setattr__(pairs, "_located", (centre, out))
    return out


def _search_range(nodes: np.ndarray, x: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """First and last core node each face node searches: ``reach`` mm each side.

    At least one segment and at most ``MAX_WINDOW`` on each side, within the mesh.
    """
    tol = 1e-12 * (x[-1] - x[0])
    lo = np.searchsorted(x, x[nodes] - reach + tol, side="right") - 1
    lo = np.clip(np.minimum(lo, nodes - 1), np.maximum(nodes - MAX_WINDOW, 0), None)
    hi = np.searchsorted(x, x[nodes] + reach - tol, side="left")
    hi = np.clip(np.maximum(hi, nodes + 1), None, np.minimum(nodes + MAX_WINDOW, x.size - 1))
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
