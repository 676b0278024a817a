"""The dolfinx mesh of a layered beam, built from the arrays of a ``meshes.LayeredMesh``.

The mesh arrives as numpy arrays in gmsh node order (9-node quadrilaterals). Only rank 0 passes
cells and points to :func:`dolfinx.mesh.create_mesh`; dolfinx distributes them. Every input node
keeps its index (``geometry.input_global_indices``), which is how the crack-lip node pairs, whose
coordinates coincide, are found again as degrees of freedom.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.io.gmshio import cell_perm_array
from dolfinx.mesh import CellType, create_mesh
from mpi4py import MPI

NODES_PER_CELL = 9  # gmsh "quad9": 4 corners, 4 mid-sides, 1 centre


@dataclass
class Discretisation:
    """A Q2 mesh, its vector Q2 space, and the map from input node index to local DOF block."""

    mesh: object
    V: object
    node_to_block: dict[int, int]  # input node index -> local block (node) index of V

    def blocks(self, nodes: np.ndarray) -> np.ndarray:
        """Local DOF blocks of the input ``nodes`` (all must be on this rank)."""
        return np.array([self.node_to_block[int(n)] for n in np.asarray(nodes).ravel()],
                        dtype=np.int32).reshape(np.shape(nodes))


def quad9_domain() -> ufl.Mesh:
    """The UFL domain of a 2D mesh of quadratic quadrilaterals."""
    return ufl.Mesh(ufl.VectorElement("Lagrange", "quadrilateral", 2))


def build_discretisation(points: np.ndarray, cells: np.ndarray,
                         comm: MPI.Comm = MPI.COMM_WORLD) -> Discretisation:
    """Create the dolfinx mesh and the vector Q2 space from gmsh-ordered arrays.

    Parameters
    ----------
    points : (n, 2) or (n, 3) array of node coordinates (x, z) in mm (read on rank 0 only).
    cells : (n_cells, 9) array of node indices in gmsh quad9 order (read on rank 0 only).
    """
    perm = cell_perm_array(CellType.quadrilateral, NODES_PER_CELL)
    if comm.rank == 0:
        x = np.ascontiguousarray(np.asarray(points, dtype=np.float64)[:, :2])
        c = np.ascontiguousarray(np.asarray(cells, dtype=np.int64)[:, perm])
    else:
        x = np.zeros((0, 2), dtype=np.float64)
        c = np.zeros((0, NODES_PER_CELL), dtype=np.int64)
    msh = create_mesh(comm, c, x, quad9_domain())
    V = fem.VectorFunctionSpace(msh, ("Lagrange", 2))
    return Discretisation(msh, V, input_node_blocks(V))


def input_node_blocks(V) -> dict[int, int]:
    """Input node index -> local DOF block of V, for every node of this rank's cells (ghosts too).

    The coordinate element and V are both Lagrange Q2, so the local node order of a cell is the
    same in the geometry dofmap and in V's dofmap: geometry node -> DOF block, cell by cell.
    """
    msh = V.mesh
    x_dofmap = msh.geometry.dofmap
    inputs = msh.geometry.input_global_indices
    n_cells = msh.topology.index_map(2).size_local + msh.topology.index_map(2).num_ghosts
    geo = np.array([x_dofmap.links(c) for c in range(n_cells)]).ravel()
    dofs = np.array([V.dofmap.cell_dofs(c) for c in range(n_cells)]).ravel()
    return dict(zip(np.asarray(inputs)[geo].tolist(), dofs.tolist(), strict=True))


def block_input_coordinates(V) -> np.ndarray:
    """(local blocks, 2): the coordinates of every DOF block copied from the mesh geometry.

    ``V.tabulate_dof_coordinates()`` evaluates the coordinate map in a cell, so two input nodes
    at the same point but in different cells (the face and core nodes of a debond lip) can come
    out a few ulps apart. The geometry array holds the input points themselves: coincident lip
    nodes get bitwise equal coordinates, and their reference gap is exactly zero.
    """
    msh = V.mesh
    x_dofmap = msh.geometry.dofmap
    n_cells = msh.topology.index_map(2).size_local + msh.topology.index_map(2).num_ghosts
    geo = np.array([x_dofmap.links(c) for c in range(n_cells)]).ravel()
    dofs = np.array([V.dofmap.cell_dofs(c) for c in range(n_cells)]).ravel()
    n_blocks = V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts
    out = np.zeros((n_blocks, 2))
    out[dofs] = msh.geometry.x[geo, :2]
    return out


def allreduce_array(comm, a: np.ndarray, op) -> np.ndarray:
    """Element-wise MPI reduction of a numpy array (a new array, same shape and dtype)."""
    a = np.ascontiguousarray(a)
    out = np.empty_like(a)
    comm.Allreduce(a, out, op=op)
    return out
