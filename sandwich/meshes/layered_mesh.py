"""The mesh of the layered beam as plain numpy arrays: what ``build_mesh`` returns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LAYER_TAGS = {"bottom_face": 1, "core": 2, "top_face": 3}  # cell_layer values = surface tags


@dataclass(frozen=True)
class LayeredMesh:
    """A 9-node-quadrilateral mesh of the beam's x-z plane, with its named groups.

    Coordinates are in mm: x along the beam, z = 0 at the core mid-plane. Node orderings follow
    gmsh: cells are 9-node quadrilaterals (corners counter-clockwise, then edge mid-nodes, then
    the centre); facets are 3-node lines (two ends, then the middle).
    """

    points: np.ndarray  # (n_nodes, 2) x, z in mm
    cells: np.ndarray  # (n_cells, 9) node indices
    cell_layer: np.ndarray  # (n_cells,) 1 = bottom face, 2 = core, 3 = top face
    facets: np.ndarray  # (n_facets, 3) node indices of the edges in facet groups
    facet_tag: np.ndarray  # (n_facets,) physical tag of each facet
    groups: dict[str, tuple[int, int]]  # name -> (dim, tag)
    lip_pairs: dict[int, np.ndarray]  # debond index -> (n_pairs, 2) [face-lip, core-lip] nodes
    tip_nodes: dict[int, tuple[int, ...]]  # debond index -> shared tip nodes
    point_nodes: dict[str, int]  # named points (probe_<name>, load<i>, debond<i>_tip_*) -> node
    level: str
    refine: int

    @property
    def n_cells(self) -> int:
        """Number of cells."""
        return len(self.cells)

    def facets_of(self, name: str) -> np.ndarray:
        """The facets (n, 3) of the dimension-1 group ``name``."""
        dim, tag = self.groups[name]
        if dim != 1:
            raise KeyError(f"{name!r} is not a facet group (dimension {dim})")
        return self.facets[self.facet_tag == tag]

    def cells_of(self, name: str) -> np.ndarray:
        """The cells (n, 9) of the layer ``name`` ("bottom_face", "core", "top_face")."""
        return self.cells[self.cell_layer == LAYER_TAGS[name]]
