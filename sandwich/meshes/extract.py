"""Read the generated gmsh mesh back into numpy: nodes, cells, facet groups, lips, tips, points."""

from __future__ import annotations

import gmsh
import numpy as np

from sandwich.meshes.blocks import INTERFACE_LEVEL, SUBLAYERS, BlockModel
from sandwich.meshes.layered_mesh import LAYER_TAGS
from sandwich.meshes.layout import Layout
from sandwich.scene import Scene

QUAD9, LINE3 = 10, 8  # gmsh element types
FACE_SUBLAYER = {"bottom": 0, "top": 3}
OUTER_LEVEL = {"bottom": 0, "top": 4}
FLIP = [0, 3, 2, 1, 7, 6, 5, 4, 8]  # reverses a 9-node quadrilateral's orientation
FACET_TAG0, POINT_TAG0 = 11, 101


def _elements(dim: int, tag: int, etype: int) -> np.ndarray:
    types, _, nodes = gmsh.model.mesh.getElements(dim, tag)
    if list(types) != [etype]:
        raise RuntimeError(f"gmsh made element types {list(types)} on entity ({dim}, {tag}), "
                           f"expected only type {etype}")
    width = 9 if etype == QUAD9 else 3
    return np.asarray(nodes[0], dtype=np.int64).reshape(-1, width) - 1


def _point_node(tag: int) -> int:
    nodes, _, _ = gmsh.model.mesh.getNodes(0, tag)
    return int(nodes[0]) - 1


def nodes() -> np.ndarray:
    """All node coordinates (n, 2), row i = gmsh node tag i + 1 (tags must be contiguous)."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, dtype=np.int64)
    if not np.array_equal(np.sort(tags), np.arange(1, len(tags) + 1)):
        raise RuntimeError("gmsh node tags are not contiguous after renumberNodes")
    pts = np.empty((len(tags), 2))
    pts[tags - 1] = np.asarray(coords).reshape(-1, 3)[:, :2]
    return pts


def cells(bm: BlockModel, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cells (n, 9), counter-clockwise, and their layer tag (n,)."""
    blocks, layers = [], []
    for (_, k), tag in sorted(bm.surfaces.items()):
        c = _elements(2, tag, QUAD9)
        blocks.append(c)
        layers.append(np.full(len(c), SUBLAYERS[k].layer))
    c = np.concatenate(blocks)
    p = points[c[:, :4]]
    area2 = np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1)
                   - np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1], axis=1)
    c[area2 < 0] = c[area2 < 0][:, FLIP]
    return c, np.concatenate(layers)


def facet_groups(scene: Scene, layout: Layout, bm: BlockModel) -> dict[str, list[int]]:
    """Dimension-1 groups: name -> curve tags."""
    xs = bm.xs
    mids = [0.5 * (a + b) for a, b in zip(xs, xs[1:], strict=False)]
    out: dict[str, list[int]] = {}
    for c in layout.cracks:
        lev = INTERFACE_LEVEL[c.interface]
        cols = [j for j, m in enumerate(mids) if c.contains(m)]
        out[f"debond{c.index}_face_lip"] = [bm.hcurves[(j, lev, "face")] for j in cols]
        out[f"debond{c.index}_core_lip"] = [bm.hcurves[(j, lev, "core")] for j in cols]
    for i, x in layout.supports:
        st = bm.station(x)
        out[f"support{i}"] = [bm.vcurves[(st, FACE_SUBLAYER[f])] for f in scene.supports[i].faces]
    for i, lo, hi in layout.loads:
        if hi > lo:
            lev = OUTER_LEVEL[scene.loads[i].on]
            out[f"load{i}"] = [bm.hcurves[(j, lev, "")] for j, m in enumerate(mids) if lo < m < hi]
    if layout.half:
        out["symmetry"] = [bm.vcurves[(len(xs) - 1, k)] for k in range(len(SUBLAYERS))]
    return out


def facets(groups: dict[str, list[int]]) -> tuple[np.ndarray, np.ndarray, dict[str, int]]:
    """Facets (n, 3), their tags (n,), and name -> tag; refuse a facet in two groups."""
    arrays, tags, names = [], [], {}
    for g, (name, curves) in enumerate(groups.items()):
        names[name] = FACET_TAG0 + g
        for cv in curves:
            f = _elements(1, cv, LINE3)
            arrays.append(f)
            tags.append(np.full(len(f), FACET_TAG0 + g))
    if not arrays:
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64), names
    f, t = np.concatenate(arrays), np.concatenate(tags)
    key = np.sort(f, axis=1)
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    if np.any(count > 1):
        dup = {int(t[i]) for i in first[count > 1]}
        clash = sorted(n for n, tg in names.items() if tg in dup)
        raise ValueError(f"mesh: groups {clash} share edges (e.g. a support on a symmetry plane)")
    return f, t, names


def lips(layout: Layout, bm: BlockModel, points: np.ndarray, f: np.ndarray, ft: np.ndarray,
         names: dict[str, int]) -> tuple[dict[int, np.ndarray], dict[int, tuple[int, ...]],
                                         dict[str, int]]:
    """Lip node pairs and tip nodes per debond, and the tips as named points."""
    pairs, tips, named = {}, {}, {}
    scale = max(1.0, float(np.abs(points).max()))
    for c in layout.cracks:
        lev = INTERFACE_LEVEL[c.interface]
        tip = []
        for end, x in (("start", c.start), ("end", c.end)):
            if -1e-9 <= x <= layout.x_end + 1e-9 and not layout.is_open(c, x):
                node = _point_node(bm.points[(bm.station(x), lev, "")])
                tip.append(node)
                named[f"debond{c.index}_tip_{end}"] = node
        tips[c.index] = tuple(tip)
        sides = []
        for side in ("face", "core"):
            n = np.setdiff1d(np.unique(f[ft == names[f"debond{c.index}_{side}_lip"]]), tip)
            sides.append(n[np.lexsort((points[n, 1], points[n, 0]))])
        face, core = sides
        if len(face) != len(core) or not np.allclose(points[face], points[core], rtol=0,
                                                      atol=1e-9 * scale):
            raise RuntimeError(f"lips of debonds[{c.index}] do not match node for node")
        if np.any(face == core):
            raise RuntimeError(f"lips of debonds[{c.index}] share nodes between the tips")
        pairs[c.index] = np.column_stack([face, core])
    return pairs, tips, named


def named_points(scene: Scene, layout: Layout, bm: BlockModel, points: np.ndarray
                 ) -> dict[str, int]:
    """Point loads (on the loaded face's outer surface) and probes (face mid-thickness)."""
    out = {}
    for i, lo, hi in layout.loads:
        if hi == lo:
            out[f"load{i}"] = _point_node(bm.points[(bm.station(lo), OUTER_LEVEL[scene.loads[i].on],
                                                      "")])
    zs = bm.zs
    mid = {"bottom": 0.5 * (zs[0] + zs[1]), "top": 0.5 * (zs[3] + zs[4])}
    for name, x in layout.probes:
        on = scene.probe(name).on
        d = np.hypot(points[:, 0] - x, points[:, 1] - mid[on])
        k = int(np.argmin(d))
        if d[k] > 1e-9 * max(1.0, abs(x)):
            raise RuntimeError(f"no node at the mid-thickness of the {on} face at x = {x:g}")
        out[f"probe_{name}"] = k
    return out


def layer_groups() -> dict[str, tuple[int, int]]:
    """The three layer surfaces: name -> (2, tag)."""
    return {name: (2, tag) for name, tag in LAYER_TAGS.items()}
