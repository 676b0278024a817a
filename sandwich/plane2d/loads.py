"""Edge tractions as assembled load vectors (dead loads, per unit width times the width b)."""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc as fem_petsc
from petsc4py import PETSc

EDGE_TAG = 1


def edge_facets(msh, on_edge) -> np.ndarray:
    """Boundary facets whose every node satisfies ``on_edge(x)`` (x of shape (3, n))."""
    msh.topology.create_connectivity(1, 2)
    return mesh.locate_entities_boundary(msh, 1, on_edge)


def edge_load_vector(V, facets: np.ndarray, traction: tuple[float, float], width: float,
                     n_local: int) -> np.ndarray:
    """B ∫_edge t · v ds over ``facets`` as a local array (owned DOFs, ghosts summed in)."""
    msh = V.mesh
    facets = np.sort(np.asarray(facets, dtype=np.int32))
    tags = mesh.meshtags(msh, 1, facets, np.full(len(facets), EDGE_TAG, dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    v = ufl.TestFunction(V)
    t = ufl.as_vector([fem.Constant(msh, PETSc.ScalarType(c)) for c in traction])
    L = fem.form(width * ufl.inner(t, v) * ds(EDGE_TAG))
    b = fem_petsc.assemble_vector(L)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    out = np.zeros(n_local)
    out[: b.getLocalSize()] = b.array
    b.destroy()
    return out


def edge_length(msh, facets: np.ndarray) -> float:
    """Total length of ``facets`` (mm), summed over ranks."""
    facets = np.sort(np.asarray(facets, dtype=np.int32))
    tags = mesh.meshtags(msh, 1, facets, np.full(len(facets), EDGE_TAG, dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    one = fem.Constant(msh, PETSc.ScalarType(1.0))
    local = fem.assemble_scalar(fem.form(one * ds(EDGE_TAG)))
    return float(msh.comm.allreduce(local))
