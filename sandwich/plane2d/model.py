"""A scene as a 2D model: layer bands, supports, dead loads, probes and debond contact on a mesh.

The mesh is a ``meshes.LayeredMesh`` (or any object with the same arrays: ``points``, ``cells``
in gmsh quad9 order and ``lip_pairs``). Everything else is located geometrically from the scene,
in mm, with z = 0 at the core mid-plane:

- supports act on the face's end section x = x_s, h_face wide: "roller" fixes w on every node of
  the section, "pin" fixes w on every node and u on the node at the face's mid-surface, "clamp"
  fixes u and w on every node (the core's section is free). The section's nodes are the nodes
  of the face's *cells* at x = x_s: where a debond reaches the support (an open mouth), the
  core's corner node sits at the same point as the face's lip node and stays free;
- a patch load is a uniform dead traction on the loaded face's outer edge over [x − w/2, x + w/2],
  scaled so that it carries exactly the scene's total force; a point load is a nodal force at the
  outer-edge node nearest to x;
- a probe is w at (x, z of the face's mid-surface), evaluated with the Q2 basis of the cell
  containing that point, so it is a linear functional c · u.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem, geometry
from mpi4py import MPI
from petsc4py import PETSc

from sandwich.meshes.layout import crack_extent
from sandwich.plane2d import contact as ct
from sandwich.plane2d.cohesive import cohesive_lips
from sandwich.plane2d.constitutive import LayerBand, PlaneStressStiffness, internal_work
from sandwich.plane2d.loads import edge_facets, edge_length, edge_load_vector
from sandwich.plane2d.mesh import Discretisation, build_discretisation
from sandwich.plane2d.system import Reference2DSystem
from sandwich.scene import Scene

GEOM_TOL = 1e-7  # mm: coordinates closer than this are the same point
#: A contact slave penetrating deeper than this × the thinner face never widens its window of
#: master nodes (10 × the penetration the default penalty allows at E_z,min / 5;
#: :mod:`sandwich.plane2d.contact`)
WIDEN_DEPTH = 1e-2


def layer_bands(scene: Scene) -> list[LayerBand]:
    """Bottom face, core and top face as z-bands (mm)."""
    hc = scene.core.thickness
    return [
        LayerBand("bottom", -0.5 * hc - scene.bottom.thickness, -0.5 * hc, scene.bottom.material),
        LayerBand("core", -0.5 * hc, 0.5 * hc, scene.core.material),
        LayerBand("top", 0.5 * hc, 0.5 * hc + scene.top.thickness, scene.top.material),
    ]


def face_band(scene: Scene, face: str) -> LayerBand:
    """The band of face "top" or "bottom"."""
    return {b.name: b for b in layer_bands(scene)}[face]


def outer_z(scene: Scene, face: str) -> float:
    """Z of a face's outer edge (mm)."""
    band = face_band(scene, face)
    return band.z_hi if face == "top" else band.z_lo


def interface_z(scene: Scene, interface: str) -> float:
    """Z of the face/core interface "top" or "bottom" (mm)."""
    return 0.5 * scene.core.thickness * (1.0 if interface == "top" else -1.0)


def default_penalty(scene: Scene) -> float:
    """Contact penalty k (N/mm³): 200 × the softest layer's E_z / the thinnest face's thickness.

    A contact pressure p penetrates p / k = (p / (200 E_z,min)) h_face: within the 1e-3 × h_face
    of the specification for any pressure up to E_z,min / 5, i.e. a transverse strain of 20 % in
    the softer layer (the core of a sandwich), beyond anything the model is meant for. (The first
    version used the *face* modulus, 1.1e7 N/mm³ on the paper scenes, 500× stiffer than this:
    the cantilever scenes with a debond at the clamp then stalled, Newton cycling between
    contact states of the lip nodes near the clamp.)
    """
    h_face = min(scene.top.thickness, scene.bottom.thickness)
    e_min = min(lay.material.Ez for lay in (scene.top, scene.core, scene.bottom))
    return 200.0 * e_min / h_face


@dataclass
class Model2D:
    """Everything the solve needs: the discretisation, the system and what to sample."""

    scene: Scene
    mesh: object
    disc: Discretisation
    stiffness: PlaneStressStiffness
    system: Reference2DSystem
    contact_pairs: list[ct.ContactPair]
    contact_interfaces: list[str]
    penalty: float


def build_model(scene: Scene, mesh, penalty: float | None = None) -> Model2D:
    """Assemble the 2D model of ``scene`` on ``mesh`` (a LayeredMesh)."""
    disc = build_discretisation(mesh.points, mesh.cells)
    V = disc.V
    bands = layer_bands(scene)
    stiffness = PlaneStressStiffness(disc.mesh, bands)
    n_local = (V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts) * 2
    X = V.tabulate_dof_coordinates()[:, :2]
    n_owned = V.dofmap.index_map.size_local
    bc = support_dofs(scene, X, comm=V.mesh.comm,
                      in_face={f: face_node_mask(V, X, face_band(scene, f))
                               for f in ("top", "bottom")})
    f_ref = load_vector(scene, V, X, n_local, n_owned=n_owned)
    probes = {p.name: probe_vector(V, p.x, face_band(scene, p.on), n_local)
              for p in scene.probes}
    k = penalty if penalty is not None else (scene.reference2d.contact_penalty
                                             or default_penalty(scene))
    pairs, ifaces = contact_pairs(scene, mesh, disc, k)
    system = Reference2DSystem(
        V, lambda u, v: internal_work(u, v, stiffness, scene.width), f_ref, bc, pairs, probes)
    return Model2D(scene, mesh, disc, stiffness, system, pairs, ifaces, k)


def face_node_mask(V, X: np.ndarray, band: LayerBand) -> np.ndarray:
    """(local blocks,) True for the DOF blocks of cells whose centroid lies in ``band``.

    The layer of a cell is the band containing its centroid (as for the material). A node on a
    bonded interface belongs to cells of both layers; a core node on a debond lip does not
    belong to any face cell, even where it coincides with the face's lip node. Under MPI the
    flags are summed onto the owners and sent back to the ghosts, so a node whose face cell lies
    on another rank is still flagged.
    """
    n_cell_dofs = V.dofmap.dof_layout.num_dofs
    blocks = np.asarray(V.dofmap.list.array, dtype=np.int64).reshape(-1, n_cell_dofs)
    zc = X[blocks, 1].mean(axis=1)
    cells = (zc > band.z_lo) & (zc < band.z_hi)
    e = fem.Function(V)
    e.x.array[:] = 0.0
    e.x.array[2 * np.unique(blocks[cells])] = 1.0
    e.vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    e.vector.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return e.x.array[0::2] > 0.0


def support_dofs(scene: Scene, X: np.ndarray, comm=None,
                 in_face: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """Unrolled local DOF indices fixed by the scene's supports (u: 2 i, w: 2 i + 1).

    ``X`` holds the coordinates of this rank's DOF blocks (owned and ghost). ``in_face`` maps
    "top"/"bottom" to a mask of the blocks that belong to that face's cells
    (:func:`face_node_mask`); without it the section is every node at x = x_s within the face's
    z-band, which wrongly takes the core's corner node where a debond reaches the support.
    Under MPI a support section may lie partly or wholly on other ranks: the "no node there"
    check and the pin's mid-surface node are decided over all ranks (``comm``).
    """
    def global_min(v: float) -> float:
        return v if comm is None or comm.size == 1 else comm.allreduce(v, op=MPI.MIN)

    fixed: list[np.ndarray] = []
    for s in scene.supports:
        for face in s.faces:
            band = face_band(scene, face)
            on = ((np.abs(X[:, 0] - s.x) < GEOM_TOL) & (X[:, 1] > band.z_lo - GEOM_TOL)
                  & (X[:, 1] < band.z_hi + GEOM_TOL))
            if in_face is not None:
                on &= in_face[face]
            section = np.flatnonzero(on)
            if global_min(0.0 if len(section) else 1.0) > 0.0:
                raise ValueError(f"support at x = {s.x} on the {face} face: no mesh node there")
            fixed.append(2 * section + 1)  # w on the whole section
            if s.type == "clamp":
                fixed.append(2 * section)
            elif s.type == "pin":
                z_mid = 0.5 * (band.z_lo + band.z_hi)
                dz = np.abs(X[section, 1] - z_mid)
                best = global_min(float(dz.min()) if len(section) else np.inf)
                fixed.append(2 * section[dz <= best])
    return np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, dtype=np.int64)


def load_vector(scene: Scene, V, X: np.ndarray, n_local: int,
                n_owned: int | None = None) -> np.ndarray:
    """Reference load (λ = 1) of every scene load, on the local DOFs.

    A point load goes to the outer-edge node nearest to x over all ranks, added by the rank that
    owns it (blocks below ``n_owned``), so that it is counted once.
    """
    comm = V.mesh.comm
    n_owned_blocks = len(X) if n_owned is None else n_owned
    f = np.zeros(n_local)
    for ld in scene.loads:
        z = outer_z(scene, ld.on)
        if ld.width > 0:
            a, b = ld.span

            def on_patch(x, a=a, b=b, z=z):
                return ((np.abs(x[1] - z) < GEOM_TOL) & (x[0] > a - GEOM_TOL)
                        & (x[0] < b + GEOM_TOL))

            facets = edge_facets(V.mesh, on_patch)
            length = edge_length(V.mesh, facets)
            if length <= 0.0:
                raise ValueError(f"load at x = {ld.x} on the {ld.on} face: no edge under it")
            t_z = ld.force / (length * scene.width)  # MPa, total force exactly ld.force
            f += edge_load_vector(V, facets, (0.0, t_z), scene.width, n_local)
        else:
            own = X[:n_owned_blocks]
            edge = np.where(np.abs(own[:, 1] - z) < GEOM_TOL)[0]
            dist = float(np.min(np.abs(own[edge, 0] - ld.x))) if len(edge) else np.inf
            # the nearest over all ranks; ties go to the lowest rank
            best, rank = comm.allreduce((dist, comm.rank), op=MPI.MIN)
            if not np.isfinite(best):
                raise ValueError(f"point load at x = {ld.x} on the {ld.on} face: no edge node")
            if rank == comm.rank:
                node = edge[np.argmin(np.abs(own[edge, 0] - ld.x))]
                f[2 * node + 1] += ld.force
    return f


def probe_vector(V, x: float, band: LayerBand, n_local: int) -> np.ndarray:
    """C with c · u = w(x, z_mid) of the face ``band`` (Q2 interpolation in its cell).

    Under MPI the point may be found on several ranks (ghost cells, or a point on a partition
    boundary): the lowest rank that finds it builds c, which is then summed onto the DOFs' owners
    (ghost entries of the result are zero), so that c · u summed over ranks counts it once.
    """
    msh = V.mesh
    comm = msh.comm
    z_mid = 0.5 * (band.z_lo + band.z_hi)
    point = np.array([[x, z_mid, 0.0]])
    tree = geometry.BoundingBoxTree(msh, msh.topology.dim)
    cells = geometry.compute_colliding_cells(msh, geometry.compute_collisions(tree, point), point)
    found = len(cells.links(0)) > 0
    c = np.zeros(n_local)
    winner = comm.allreduce(comm.rank if found else comm.size, op=MPI.MIN)
    if winner == comm.size:
        raise ValueError(f"probe point ({x}, {z_mid}) lies outside the mesh")
    e = fem.Function(V)
    if comm.rank == winner:
        cell = cells.links(0)[0]
        for blk in V.dofmap.cell_dofs(cell):
            e.x.array[:] = 0.0
            e.x.array[2 * blk + 1] = 1.0
            c[2 * blk + 1] = e.eval(point, [cell])[1]
    if comm.size == 1:
        return c
    e.x.array[:] = c
    e.vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    n_owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    out = np.zeros(n_local)
    out[:n_owned] = e.vector.array[:n_owned]
    return out


def contact_pairs(scene: Scene, mesh, disc: Discretisation,
                  penalty: float) -> tuple[list[ct.ContactPair], list[str]]:
    """Finite-sliding contact data (:mod:`sandwich.plane2d.contact`) of every debond with lips."""
    pairs, ifaces = [], []
    h_face = min(scene.top.thickness, scene.bottom.thickness)
    lip_pairs = getattr(mesh, "lip_pairs", {}) or {}
    pts = np.asarray(mesh.points)[:, :2]
    for i, debond in enumerate(scene.debonds):
        if i not in lip_pairs or len(lip_pairs[i]) == 0:
            continue
        nodes = np.asarray(lip_pairs[i])
        face_nodes, core_nodes = nodes[:, 0], nodes[:, 1]
        z = interface_z(scene, debond.interface)
        order = np.argsort(pts[core_nodes, 0])
        core_sorted = core_nodes[order]
        lip_set = set(map(int, nodes.ravel()))
        tips = []
        for x_tip in crack_extent(scene, i):  # a cohesive debond's lips run over its spans
            hit = np.where((np.abs(pts[:, 0] - x_tip) < GEOM_TOL)
                           & (np.abs(pts[:, 1] - z) < GEOM_TOL))[0]
            hit = [h for h in hit if int(h) not in lip_set]
            tips.append(hit[0] if hit else None)
        chain = ([tips[0]] if tips[0] is not None else []) + list(core_sorted) + (
            [tips[1]] if tips[1] is not None else [])
        if debond.interface == "bottom":
            chain = chain[::-1]  # so that n = J (x2 − x1)/|…| points out of the core (−z)
        # input node indices (the same on every rank; the system finds their DOFs)
        master = np.array(chain, dtype=np.int64)
        slave = np.asarray(face_nodes, dtype=np.int64)
        position = {int(blk): k for k, blk in enumerate(master)}
        anchor = np.array([position[int(n)] for n in core_nodes], dtype=np.int64)
        x_face = pts[face_nodes, 0]
        # a missing tip is an open mouth (debond reaching the beam end): no bonded corner there
        x_tips = [None if t is None else float(pts[t, 0]) for t in tips]
        weight = ct.slave_weights(x_face, x_tips[0], x_tips[1])  # start < end (scene checks)
        lips = tuple(cohesive_lips(scene, x_face, i, scene.core.material.Qz,
                                   1e-9 * scene.length))
        pairs.append(ct.ContactPair(slave, master, anchor, weight, penalty, scene.width, x_face,
                                    widen_depth=WIDEN_DEPTH * h_face, cohesive=lips))
        ifaces.append(debond.interface)
    return pairs, ifaces
