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

A closest-point pair's force and tangent act on its block (face node + core nodes of the searched
segments), so the sparse pattern is fixed; :func:`contact_pair_groups` groups an interface's
pairs by search width (blocks no wider than needed on graded meshes) and the projection is
computed once for all its groups.
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


@dataclass(frozen=True)
class ContactPairs:
    """Contact pairs of one interface: one per untied face node (master).

    ``dofs`` are the node's own six same-x DOFs (PAIR_ROLES); the linear analysis
    (:func:`sandwich.beam.linear_step.linear_solution`) and the same-x search use them. A
    closest-point pair (``search == "closest-point"``) also carries the core boundary nodes
    ``core_nodes`` (i − k … i + k, clamped to the mesh) whose segments it searches; its force and
    tangent live on ``block_dofs`` = (u_face, w_face, then CORE_NODE_ROLES of each core node).
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
        """Full DOF indices of the force and tangent blocks (:mod:`~sandwich.beam.contact`)."""
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
