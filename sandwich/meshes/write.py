"""Write a :class:`LayeredMesh`: gmsh ``.msh`` (format 4.1), XDMF for ParaView, lip pairs JSON.

The XDMF holds its data inline (no ``.h5`` file beside it).

The ``.msh`` is rebuilt from the numpy arrays as a discrete gmsh model, so the file holds exactly
what ``build_mesh`` returned: one surface per layer, one curve per facet group, one point per named
point, each with its physical group. ``dolfinx.io.gmshio.model_to_mesh`` reads it (physical points
are ignored there; their nodes are in the JSON).
"""

from __future__ import annotations

import json
from pathlib import Path

import gmsh
import numpy as np

from sandwich.meshes.layered_mesh import LayeredMesh
from sandwich.meshes.xdmf import write_xdmf

QUAD9, LINE3, POINT = 10, 8, 15  # gmsh element types


def _write_msh(mesh: LayeredMesh, path: Path) -> None:
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(path.stem)
        xyz = np.column_stack([mesh.points, np.zeros(len(mesh.points))]).ravel()
        next_elem = 1
        first = True
        for name, (dim, tag) in mesh.groups.items():
            gmsh.model.addDiscreteEntity(dim, tag)
            if first:  # every node lives on the first surface; other entities reference them
                gmsh.model.mesh.addNodes(dim, tag, np.arange(1, len(mesh.points) + 1), xyz)
                first = False
            if dim == 2:
                conn = mesh.cells[mesh.cell_layer == tag]
                etype = QUAD9
            elif dim == 1:
                conn = mesh.facets[mesh.facet_tag == tag]
                etype = LINE3
            else:
                conn = np.array([[mesh.point_nodes[name]]])
                etype = POINT
            tags = np.arange(next_elem, next_elem + len(conn))
            next_elem += len(conn)
            gmsh.model.mesh.addElementsByType(tag, etype, tags, (conn + 1).ravel())
            gmsh.model.addPhysicalGroup(dim, [tag], tag)
            gmsh.model.setPhysicalName(dim, tag, name)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def lip_pairs_dict(mesh: LayeredMesh) -> dict:
    """What the JSON holds: lip pairs, tips, named points and groups (node indices from 0)."""
    return {
        "level": mesh.level, "refine": mesh.refine,
        "debonds": {str(i): {"face_lip": f"debond{i}_face_lip", "core_lip": f"debond{i}_core_lip",
                             "pairs": mesh.lip_pairs[i].tolist(),
                             "tips": list(mesh.tip_nodes[i])} for i in mesh.lip_pairs},
        "point_nodes": mesh.point_nodes,
        "groups": {k: list(v) for k, v in mesh.groups.items()},
    }


def write_mesh(mesh: LayeredMesh, out_dir: Path, stem: str) -> dict[str, Path]:
    """Write ``<stem>.msh``, ``<stem>.xdmf``, ``<stem>_facets.xdmf``, ``<stem>_lip_pairs.json``.

    The cell XDMF carries the layer tag per cell, the facet XDMF the group tag per facet.

    Returns
    -------
    dict
        "msh", "xdmf", "facets_xdmf" and "lip_pairs" -> path written in ``out_dir``.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {"msh": out_dir / f"{stem}.msh", "xdmf": out_dir / f"{stem}.xdmf",
             "facets_xdmf": out_dir / f"{stem}_facets.xdmf",
             "lip_pairs": out_dir / f"{stem}_lip_pairs.json"}
    _write_msh(mesh, paths["msh"])
    write_xdmf(paths["xdmf"], mesh.points, "Quadrilateral_9", mesh.cells, mesh.cell_layer)
    write_xdmf(paths["facets_xdmf"], mesh.points, "Edge_3", mesh.facets, mesh.facet_tag)
    paths["lip_pairs"].write_text(json.dumps(lip_pairs_dict(mesh), indent=1), encoding="utf-8")
    return paths
