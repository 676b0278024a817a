"""``build_mesh``: a scene in, a :class:`LayeredMesh` of its 2D plane-stress model out."""

from __future__ import annotations

import gmsh

from sandwich.meshes import extract
from sandwich.meshes.blocks import add_blocks
from sandwich.meshes.grading import Segment, grade_block
from sandwich.meshes.layered_mesh import LayeredMesh
from sandwich.meshes.layout import Layout, make_layout
from sandwich.meshes.levels import Sizing, sizing_for
from sandwich.scene import Scene


def segments_for(layout: Layout, sizing: Sizing) -> list[Segment]:
    """The x segments of the mesh: graded between key stations, then subdivided.

    Over a debond the elements are at most ``sizing.debond_size`` long, elsewhere
    ``sizing.far_size``.
    """
    segs: list[Segment] = []
    st, sharp = layout.stations, layout.sharp
    for a, b, sa, sb in zip(st, st[1:], sharp, sharp[1:], strict=False):
        far = sizing.debond_size if layout.debonded(a, b) else sizing.far_size
        segs += grade_block(a, b, sa, sb, sizing.tip_size, far, sizing.growth)
    return [s.subdivided(sizing.subdivision) for s in segs]


def z_levels(scene: Scene) -> list[float]:
    """Z of the bottom surface, bottom interface, core mid-plane, top interface, top surface."""
    hc2 = 0.5 * scene.core.thickness
    return [-hc2 - scene.bottom.thickness, -hc2, 0.0, hc2, hc2 + scene.top.thickness]


def build_mesh(scene: Scene, *, level: str | None = None, refine: int | None = None,
               size_factor: float = 1.0) -> LayeredMesh:
    """Mesh ``scene``'s beam (x-z plane) with 9-node quadrilaterals and crack lips.

    Parameters
    ----------
    scene
        The problem; ``scene.reference2d`` gives the defaults of the resolution and half model.
    level
        "coarse", "medium", "fine" or "explicit"; default ``scene.reference2d.level``.
    refine
        Extra uniform halvings of every element size (each gives 4x the cells); default
        ``scene.reference2d.refine``.
    size_factor
        Multiplies the element lengths along x of the level (before ``refine``).

    Returns
    -------
    LayeredMesh
        Plain numpy arrays and named groups; gmsh is finalized before returning.

    Raises
    ------
    ValueError
        A level, a half model or a geometry this mesh cannot honour, with the reason.
    """
    sizing = sizing_for(scene, level, refine, size_factor)
    layout = make_layout(scene, sizing.snap_tolerance, half=scene.reference2d.half_model)
    segments = segments_for(layout, sizing)
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)  # keep coincident lip points apart
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)  # 9-node, not 8-node, quads
        gmsh.model.add(scene.name)
        bm = add_blocks(layout, segments, z_levels(scene), sizing)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.renumberNodes()
        gmsh.model.mesh.renumberElements()
        points = extract.nodes()
        cells, layer = extract.cells(bm, points)
        fgroups = extract.facet_groups(scene, layout, bm)
        facets, ftag, fnames = extract.facets(fgroups)
        pairs, tips, tip_points = extract.lips(layout, bm, points, facets, ftag, fnames)
        named = {**extract.named_points(scene, layout, bm, points), **tip_points}
    finally:
        gmsh.finalize()
    groups = extract.layer_groups()
    groups.update({name: (1, tag) for name, tag in fnames.items()})
    groups.update({name: (0, extract.POINT_TAG0 + k) for k, name in enumerate(named)})
    return LayeredMesh(points=points, cells=cells, cell_layer=layer, facets=facets,
                       facet_tag=ftag, groups=groups, lip_pairs=pairs, tip_nodes=tips,
                       point_nodes=named, level=sizing.level, refine=sizing.refine)



