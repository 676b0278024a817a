"""The structured block model of the layered beam in gmsh's built-in (geo) kernel.

The beam is a grid of blocks: one column per x segment, one row per *sublayer* (bottom face, lower
core half, upper core half, top face). Every block is a transfinite, recombined surface, so nodes
line up across blocks. Along a debond, the face side and the core side of the interface are two
different curves between the same x, with their own (coincident) points; the tips are shared
points. Where a debond reaches a beam end, its two mouth corners are distinct (open mouth).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import gmsh

from sandwich.meshes.grading import Segment
from sandwich.meshes.layout import Layout
from sandwich.meshes.levels import Sizing

INTERFACE_LEVEL = {"bottom": 1, "top": 3}  # index into the z levels below


@dataclass(frozen=True)
class Sublayer:
    """A row of blocks between two z levels."""

    name: str
    lo: int  # z level index of its bottom edge
    hi: int  # z level index of its top edge
    layer: int  # physical layer: 1 bottom face, 2 core, 3 top face
    side_lo: str  # side of the interface at its bottom edge ("face", "core" or "")
    side_hi: str


SUBLAYERS = (
    Sublayer("bottom_face", 0, 1, 1, "", "face"),
    Sublayer("core_lower", 1, 2, 2, "core", ""),
    Sublayer("core_upper", 2, 3, 2, "", "core"),
    Sublayer("top_face", 3, 4, 3, "face", ""),
)


@dataclass
class BlockModel:
    """Tags of the geo entities, keyed by grid position."""

    xs: list[float]  # column x (mm)
    zs: list[float]  # z levels (mm): bottom surface, bottom interface, 0, top interface, top
    points: dict[tuple[int, int, str], int] = field(default_factory=dict)
    hcurves: dict[tuple[int, int, str], int] = field(default_factory=dict)  # (column, level, side)
    vcurves: dict[tuple[int, int], int] = field(default_factory=dict)  # (station, sublayer)
    surfaces: dict[tuple[int, int], int] = field(default_factory=dict)  # (column, sublayer)

    def station(self, x: float) -> int:
        """Index of the column boundary at x."""
        i = min(range(len(self.xs)), key=lambda k: abs(self.xs[k] - x))
        if abs(self.xs[i] - x) > 1e-9 * max(1.0, abs(x)):
            raise KeyError(f"no station at x = {x:g}")
        return i


def _open_at(layout: Layout, i_level: int, x: float) -> bool:
    return any(INTERFACE_LEVEL[c.interface] == i_level and layout.is_open(c, x)
               for c in layout.cracks)


def _debonded(layout: Layout, i_level: int, x_mid: float) -> bool:
    return any(INTERFACE_LEVEL[c.interface] == i_level and c.contains(x_mid)
               for c in layout.cracks)


def add_blocks(layout: Layout, segments: list[Segment], zs: list[float],
               sizing: Sizing) -> BlockModel:
    """Create points, curves and transfinite surfaces in the current gmsh model; synchronize."""
    geo = gmsh.model.geo
    xs = [s.x0 for s in segments] + [segments[-1].x1]
    bm = BlockModel(xs, zs)

    def point(i: int, lev: int, side: str) -> int:
        side = side if lev in INTERFACE_LEVEL.values() and _open_at(layout, lev, xs[i]) else ""
        key = (i, lev, side)
        if key not in bm.points:
            bm.points[key] = geo.addPoint(xs[i], zs[lev], 0.0)
        return bm.points[key]

    rows = {
        "bottom_face": (sizing.face_rows, 1.0),
        "core_lower": (sizing.core_rows_half, sizing.core_ratio),
        "core_upper": (sizing.core_rows_half, 1.0 / sizing.core_ratio),
        "top_face": (sizing.face_rows, 1.0),
    }

    def hcurve(j: int, lev: int, side: str) -> int:
        mid = 0.5 * (xs[j] + xs[j + 1])
        side = side if lev in INTERFACE_LEVEL.values() and _debonded(layout, lev, mid) else ""
        key = (j, lev, side)
        if key not in bm.hcurves:
            tag = geo.addLine(point(j, lev, side), point(j + 1, lev, side))
            geo.mesh.setTransfiniteCurve(tag, segments[j].n + 1, "Progression", segments[j].ratio)
            bm.hcurves[key] = tag
        return bm.hcurves[key]

    def vcurve(i: int, k: int) -> int:
        if (i, k) not in bm.vcurves:
            sub = SUBLAYERS[k]
            tag = geo.addLine(point(i, sub.lo, sub.side_lo), point(i, sub.hi, sub.side_hi))
            n, ratio = rows[sub.name]
            geo.mesh.setTransfiniteCurve(tag, n + 1, "Progression", ratio)
            bm.vcurves[(i, k)] = tag
        return bm.vcurves[(i, k)]

    for j in range(len(segments)):
        for k, sub in enumerate(SUBLAYERS):
            loop = geo.addCurveLoop([hcurve(j, sub.lo, sub.side_lo), vcurve(j + 1, k),
                                     -hcurve(j, sub.hi, sub.side_hi), -vcurve(j, k)])
            tag = geo.addPlaneSurface([loop])
            geo.mesh.setTransfiniteSurface(tag)
            geo.mesh.setRecombine(2, tag)
            bm.surfaces[(j, k)] = tag
    geo.synchronize()
    return bm
