"""XDMF time series for ParaView: displacement (Q2 on the Q2 mesh) and DG0 Cauchy stresses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.io import XDMFFile
from mpi4py import MPI

from sandwich.plane2d.constitutive import deformation_gradient, green_lagrange
from sandwich.plane2d.mesh import allreduce_array


def write_fields(solution, path: str | Path, every: int = 1) -> Path:
    """Write the states kept by ``solve(..., keep_states=True)`` to ``path`` (.xdmf + .h5).

    Written per step (time = step number): ``displacement`` (mm), and cell averages (DG0, at the
    cell centre) of the Cauchy stress σ = F S Fᵀ / det F: ``sigma_x``, ``sigma_z``, ``tau``
    and the plane-stress ``von_mises`` (MPa). The file is written collectively over the mesh's
    communicator (one file, as dolfinx does).
    """
    if not hasattr(solution, "reference2d_states"):
        raise ValueError("write_fields needs the solution of solve(..., keep_states=True)")
    model, states = solution.reference2d_states
    path = Path(path).with_suffix(".xdmf")
    if model.disc.mesh.comm.rank == 0:
        path.parent.mkdir(parents=True, exist_ok=True)
    msh = model.disc.mesh
    u = model.system.u
    F = deformation_gradient(u)
    S = model.stiffness.pk2(green_lagrange(u))
    sigma = F * S * F.T / ufl.det(F)
    Q0 = fem.FunctionSpace(msh, ("DG", 0))
    pts = Q0.element.interpolation_points()
    vm = ufl.sqrt(sigma[0, 0] ** 2 - sigma[0, 0] * sigma[1, 1] + sigma[1, 1] ** 2
                  + 3 * sigma[0, 1] ** 2)
    outs = {}
    for name, expr in (("sigma_x", sigma[0, 0]), ("sigma_z", sigma[1, 1]),
                       ("tau", sigma[0, 1]), ("von_mises", vm)):
        f = fem.Function(Q0, name=name)
        outs[name] = (f, fem.Expression(expr, pts))
    u.name = "displacement"
    with XDMFFile(msh.comm, str(path), "w") as xdmf:
        xdmf.write_mesh(msh)
        for step, _lam, state in states:
            if every > 1 and step % every and step != states[-1][0]:
                continue
            model.system._set_u(state)
            xdmf.write_function(u, float(step))
            for f, expr in outs.values():
                f.interpolate(expr)
                xdmf.write_function(f, float(step))
    return path


# gmsh quad9 (corners 0-3, mid-sides 4-7, centre 8) split into four counter-clockwise sub-quads
QUAD9_SUBQUADS = np.array([[0, 4, 8, 7], [4, 1, 5, 8], [8, 5, 2, 6], [7, 8, 6, 3]])
REGION_OF_BAND = {"core": 0, "top": 1, "bottom": 2}  # FieldFrame region codes


def cauchy_cell_values(model, u: np.ndarray) -> dict[str, np.ndarray]:
    """Cell-centre (DG0) Cauchy stresses σ = F S Fᵀ / det F at state ``u``, per local cell."""
    msh = model.disc.mesh
    system = model.system
    system._set_u(u)
    uf = system.u
    F = deformation_gradient(uf)
    S = model.stiffness.pk2(green_lagrange(uf))
    sigma = F * S * F.T / ufl.det(F)
    vm = ufl.sqrt(sigma[0, 0] ** 2 - sigma[0, 0] * sigma[1, 1] + sigma[1, 1] ** 2
                  + 3 * sigma[0, 1] ** 2)
    Q0 = fem.FunctionSpace(msh, ("DG", 0))
    pts = Q0.element.interpolation_points()
    n = msh.topology.index_map(2).size_local
    out = {}
    for name, expr in (("sigma_x", sigma[0, 0]), ("sigma_z", sigma[1, 1]),
                       ("tau", sigma[0, 1]), ("von_mises", vm)):
        f = fem.Function(Q0)
        f.interpolate(fem.Expression(expr, pts))
        dofs = np.array([Q0.dofmap.cell_dofs(c)[0] for c in range(n)])
        out[name] = f.x.array[dofs].copy()
    return out


def field_frame(model, step: int, load_factor: float, u: np.ndarray):
    """A :class:`sandwich.results.FieldFrame` of state ``u`` on the input mesh (every rank).

    Points are the input mesh's nodes (x, z), each 9-node quad split into 4 counter-clockwise
    sub-quads; point data ``displacement``; cell data (per sub-quad, the parent cell's centre
    value) ``sigma_x``, ``sigma_z``, ``tau``, ``von_mises`` (Cauchy, MPa) and ``region``
    (0 core, 1 top face, 2 bottom face).
    """
    from sandwich.plane2d.model import layer_bands
    from sandwich.results import FieldFrame

    msh = model.disc.mesh
    comm = msh.comm
    points = np.asarray(model.mesh.points, dtype=float)[:, :2]
    cells9 = np.asarray(model.mesh.cells, dtype=np.int64)
    # displacement per input node from the owned DOF blocks of every rank
    owned = model.system.n_owned // 2
    to_block = model.disc.node_to_block
    nodes = np.array([n for n, b in to_block.items() if b < owned], dtype=np.int64)
    blocks = np.array([to_block[int(n)] for n in nodes], dtype=np.int64)
    u_loc = np.zeros(model.system.n_local)
    u_loc[: len(u)] = u
    disp = np.zeros((len(points), 2))
    disp[nodes] = u_loc.reshape(-1, 2)[blocks]
    # input cell -> owned dolfinx cell, matched by the set of input node indices
    inputs = msh.geometry.input_global_indices
    dm = msh.geometry.dofmap
    n = msh.topology.index_map(2).size_local
    by_nodes = {frozenset(map(int, c)): i for i, c in enumerate(cells9)}
    mine = np.array([by_nodes[frozenset(int(inputs[g]) for g in dm.links(c))]
                     for c in range(n)], dtype=np.int64)
    values = cauchy_cell_values(model, u)
    names = [b.name for b in layer_bands(model.scene)]
    region_local = np.array([REGION_OF_BAND[names[k]] for k in model.stiffness.layer_index[:n]])
    per_cell = {k: np.zeros(len(cells9)) for k in values}
    region = np.zeros(len(cells9))
    for k, v in values.items():
        per_cell[k][mine] = v
    region[mine] = region_local
    if comm.size > 1:  # every node / cell is owned by exactly one rank: sums are gathers
        disp = allreduce_array(comm, disp, MPI.SUM)
        per_cell = {k: allreduce_array(comm, v, MPI.SUM) for k, v in per_cell.items()}
        region = allreduce_array(comm, region, MPI.SUM)
    sub = cells9[:, QUAD9_SUBQUADS].reshape(-1, 4)
    cell_data = {k: np.repeat(v, 4) for k, v in per_cell.items()}
    cell_data["region"] = np.repeat(region, 4).astype(np.int32)
    return FieldFrame(int(step), float(load_factor), points, sub, disp, {}, cell_data)
