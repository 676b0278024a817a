"""Every element split in two: the mesh, its core levels, and a state carried onto it.

The element length's share of a state's error is estimated by re-converging the state on the
bisected mesh (:meth:`sandwich.beam.one_pass.OnePass.length_estimate`). Every old node is a node
of the bisected mesh (stations stay nodes) and each half keeps its element's core level. The
state is carried over node by node: the old nodes' DOFs as they are, a midpoint's the mean of
its element's two nodes (the 20 nodal DOFs, the faces' stretch and the core's enrichment alike).
It is a start for Newton, not the same field: on fig. 9 d10 at −5 mm (60 elements, level 2) the
probe-held Newton from it converges in 9 iterations, in 11 from the cubic Hermite midpoint
values and slopes, whose residual is 6× the mean's (the faces' averaged membrane strain, taken
over each half, is not the coarse element's).
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.cohesive import carry_damage
from sandwich.beam.dofs import NODE_DOFS
from sandwich.beam.mesh import BeamMesh
from sandwich.beam.model import BeamModel


def bisected_mesh(mesh: BeamMesh) -> BeamMesh:
    """``mesh`` with a node at the middle of every element."""
    x = np.empty(2 * mesh.n_nodes - 1)
    x[0::2] = mesh.x
    x[1::2] = 0.5 * (mesh.x[:-1] + mesh.x[1:])
    return BeamMesh(x)


def bisected_levels(levels: np.ndarray) -> np.ndarray:
    """Each element's core level on both its halves."""
    return np.repeat(np.asarray(levels, dtype=int), 2)


def bisected_state(u: np.ndarray, src: BeamModel, dst: BeamModel) -> np.ndarray:
    """Free DOFs of ``dst`` (``src`` bisected) carrying the state ``u`` of ``src``.

    Node by node (the 20 nodal DOFs, then each node's extra block): old nodes as they are,
    midpoints the mean of their element's two nodes. A cohesive interface's damage goes with
    the state (:func:`~sandwich.beam.cohesive.carry_damage`: a midpoint the larger of its two).
    """
    n = src.mesh.n_nodes
    if dst.mesh.n_nodes != 2 * n - 1 or not np.array_equal(dst.mesh.x[0::2], src.mesh.x):
        raise ValueError("the destination model's mesh is not the source's bisected")
    full = src.expand(u)
    m_src = (full.size - NODE_DOFS * n) // n
    m_dst = (dst.dof_map.n_full - NODE_DOFS * dst.mesh.n_nodes) // dst.mesh.n_nodes
    extra = np.zeros((n, m_dst))
    k = min(m_src, m_dst)
    extra[:, :k] = full[NODE_DOFS * n:].reshape(n, m_src)[:, :k]
    out = np.concatenate([_with_midpoints(full[:NODE_DOFS * n].reshape(n, NODE_DOFS)).ravel(),
                          _with_midpoints(extra).ravel()])
    free = np.zeros(dst.size)
    live = dst.dof_map.free >= 0
    free[dst.dof_map.free[live]] = dst.dof_map.sign[live] * out[live]
    carry_damage(src, dst, u)
    return free


def _with_midpoints(rows: np.ndarray) -> np.ndarray:
    """Rows per node with the mean of each element's two rows inserted between them."""
    out = np.empty((2 * rows.shape[0] - 1, rows.shape[1]))
    out[0::2] = rows
    out[1::2] = 0.5 * (rows[:-1] + rows[1:])
    return out
