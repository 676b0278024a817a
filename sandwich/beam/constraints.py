"""Interface ties and supports, imposed exactly by elimination: u_full = T u_free.

Every constraint here is homogeneous and says that a DOF is zero, equal to another DOF, or equal
to minus another DOF. So each row of T holds at most one entry, ±1, and T is stored as two arrays:
for each full DOF, the free DOF it follows (−1 when it is fixed at zero) and the sign.

Supports act on face DOFs only (the core is free unless tied to a face):

- ``clamp``: u at both face surfaces, w and w,x are zero;
- ``pin``: w = 0 and the face mid-surface does not move axially, (u_top + u_bottom)/2 = 0,
  eliminated as u_bottom = −u_top;
- ``roller``: w = 0.

Ties (section 2.3) at every bonded node of an interface, debond tips included:
u_ct = u_tb, w_ct = w_t, w_ct,x = w_t,x (top) and u_cb = u_bt, w_cb = w_b, w_cb,x = w_b,x
(bottom). A tied core DOF follows whatever its face DOF follows after the supports.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from sandwich.beam.dofs import FACE_DOFS, NODE_DOFS, TIES, global_dof

SUPPORT_TYPES = ("clamp", "pin", "roller")


@dataclass(frozen=True)
class NodeSupport:
    """A support of ``type`` acting on ``face`` ("top" | "bottom") at node ``node``."""

    node: int
    face: str
    type: str


@dataclass(frozen=True)
class DofMap:
    """The elimination u_full = T u_free: T[a, free[a]] = sign[a], row a empty if free[a] < 0."""

    free: np.ndarray  # (n_full,) int
    sign: np.ndarray  # (n_full,) float, 0 or ±1
    n_free: int

    @property
    def n_full(self) -> int:
        """Number of DOFs before elimination (20 per node, plus the core enrichment)."""
        return int(self.free.size)

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """u_full = T u_free."""
        return self.sign * np.asarray(u_free)[np.maximum(self.free, 0)]

    def reduce(self, f_full: np.ndarray) -> np.ndarray:
        """Tᵀ f_full (forces on the free DOFs)."""
        live = self.free >= 0
        return np.bincount(self.free[live], weights=self.sign[live] * f_full[live],
                           minlength=self.n_free)

    @property
    def T(self) -> sp.csr_matrix:
        """T as a sparse matrix, shape ``(n_full, n_free)``."""
        rows = np.flatnonzero(self.free >= 0)
        return sp.csr_matrix((self.sign[rows], (rows, self.free[rows])),
                             shape=(self.n_full, self.n_free))


def build_dof_map(
    n_nodes: int,
    bonded: dict[str, np.ndarray],
    supports: list[NodeSupport],
    mode_active: np.ndarray | None = None,
) -> DofMap:
    """Eliminate supports, then ties; number the remaining DOFs node by node.

    Parameters
    ----------
    n_nodes
        Number of nodes.
    bonded
        For "top" and "bottom", a boolean array over nodes: True where the interface is tied.
    supports
        Supports at nodes.
    mode_active
        Core enrichment DOFs (:mod:`sandwich.beam.core_basis`), shape ``(n_nodes, m)``: True where
        the node's level carries the DOF, False where it is fixed at zero. They follow the
        ``NODE_DOFS · n_nodes`` paper DOFs in the full vector (node i's at
        ``NODE_DOFS · n_nodes + m i + j``) and are numbered with their node's paper DOFs, so the
        reduced matrix stays banded. ``None``: no enrichment.
    """
    if mode_active is None:
        mode_active = np.zeros((n_nodes, 0), dtype=bool)
    mode_active = np.asarray(mode_active, dtype=bool)
    if mode_active.ndim != 2 or mode_active.shape[0] != n_nodes:
        raise ValueError(f"mode_active must have shape (n_nodes, m), got {mode_active.shape}")
    n_paper = NODE_DOFS * n_nodes
    n_full = n_paper + mode_active.size
    target = np.arange(n_full)  # the DOF each DOF follows
    sign = np.ones(n_full)
    for s in supports:
        if s.type not in SUPPORT_TYPES:
            raise ValueError(f"unknown support type {s.type!r}; expected one of {SUPPORT_TYPES}")
        if s.face not in FACE_DOFS:
            raise ValueError(f"a support acts on 'top' or 'bottom', got {s.face!r}")
        if not 0 <= s.node < n_nodes:
            raise ValueError(f"support node {s.node} outside 0..{n_nodes - 1}")
    # Clamps first, then pins (which respect clamped DOFs), then rollers.
    order = {"clamp": 0, "pin": 1, "roller": 2}
    for s in sorted(supports, key=lambda s: order[s.type]):
        names = FACE_DOFS[s.face]
        w = global_dof(s.node, names["w"])
        sign[w] = 0.0
        if s.type == "clamp":
            for role in ("u_top", "u_bottom", "w,x"):
                sign[global_dof(s.node, names[role])] = 0.0
        elif s.type == "pin":
            top, bottom = global_dof(s.node, names["u_top"]), global_dof(s.node, names["u_bottom"])
            if sign[top] == 0.0 or sign[bottom] == 0.0:
                sign[top] = sign[bottom] = 0.0
            elif target[bottom] == bottom:  # (u_top + u_bottom)/2 = 0
                target[bottom], sign[bottom] = top, -1.0
    for interface, pairs in TIES.items():
        mask = np.asarray(bonded[interface], dtype=bool)
        if mask.shape != (n_nodes,):
            raise ValueError(f"bonded[{interface!r}] must have one entry per node")
        nodes = np.flatnonzero(mask)
        for core_name, face_name in pairs:
            c, f = global_dof(nodes, core_name), global_dof(nodes, face_name)
            target[c], sign[c] = target[f], sign[f]
    sign[n_paper:] = np.where(mode_active.ravel(), 1.0, 0.0)
    independent = (target == np.arange(n_full)) & (sign != 0.0)
    # Node-wise numbering: each node's paper DOFs, then its enrichment DOFs.
    node_of = np.concatenate([np.arange(n_paper) // NODE_DOFS,
                              np.repeat(np.arange(n_nodes), mode_active.shape[1])])
    order = np.argsort(node_of, kind="stable")
    number = np.empty(n_full, dtype=np.int64)
    number[order] = np.cumsum(independent[order]) - 1
    free = np.where(sign != 0.0, number[target], -1)
    assert np.all(independent[target[sign != 0.0]]), "a constraint chain was left unresolved"
    return DofMap(free=free, sign=np.where(free >= 0, sign, 0.0), n_free=int(independent.sum()))
