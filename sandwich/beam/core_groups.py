"""The core elements grouped by level, with the DOFs of their hierarchical enrichment.

Each level of the core hierarchy (:mod:`sandwich.beam.core_basis`) has its own layer rows; the
model evaluates the core family by family, one family per level present
(:class:`~sandwich.beam.model.BeamModel`, ``core``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.beam.core_basis import CoreBasis, mode_dofs
from sandwich.beam.dofs import NODE_DOFS
from sandwich.beam.element import GeometricProducts, geometric_products
from sandwich.beam.layer_operators import LayerOperators


@dataclass(frozen=True)
class CoreGroup:
    """The core elements of one level: their rows, products and (extended) DOF indices."""

    level: int
    elements: np.ndarray  # (E_g,) element indices, increasing
    op: LayerOperators
    products: GeometricProducts
    dofs: np.ndarray  # (E_g, n) full DOF indices of op.dofs


def node_levels(element_levels: np.ndarray) -> np.ndarray:
    """Level of each node: the lowest of its elements' (so every element is conforming).

    An enrichment amplitude lives at a node only if every element there carries it; the
    element of the higher level then sees it vanish at that node.
    """
    e = np.asarray(element_levels, dtype=int)
    return np.minimum(np.concatenate([e[:1], e]), np.concatenate([e, e[-1:]]))


def core_groups(
    basis: CoreBasis,
    element_levels: np.ndarray,
    element_dofs: np.ndarray,
    n_nodes: int,
    make_op: object,
    stride: int | None = None,
    offset: int = 0,
) -> list[CoreGroup]:
    """Group core elements by level; extended DOFs = paper 40, then each node's enrichment.

    ``stride``: extra DOFs per node in the full vector (default: the core enrichment's);
    ``offset``: where the core enrichment starts in a node's block (after the face stretch).
    """
    m = 4 * basis.count(basis.max_level) if stride is None else stride
    groups = []
    for level in np.unique(element_levels):
        els = np.flatnonzero(element_levels == level)
        op = make_op(int(level))
        k = len(mode_dofs(basis, int(level)))
        ext = [element_dofs[els]]
        for node in (0, 1):
            ext.append(NODE_DOFS * n_nodes + m * (els + node)[:, None] + offset
                       + np.arange(k)[None, :])
        ext_dofs = np.concatenate(ext, axis=1)
        groups.append(CoreGroup(level=int(level), elements=els, op=op,
                                products=geometric_products(op), dofs=ext_dofs[:, op.dofs]))
    return groups
