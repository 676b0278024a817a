"""Mesh quality report: counts, aspect ratios, angles and lip pairs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.meshes.layered_mesh import LayeredMesh


@dataclass(frozen=True)
class MeshQuality:
    """Numbers to judge a mesh by; angles in degrees."""

    n_cells: int
    n_nodes: int
    min_aspect_ratio: float  # longest / shortest corner-to-corner edge of a cell
    max_aspect_ratio: float
    min_angle: float  # smallest corner angle of any cell (deg)
    lip_pairs: dict[int, int]  # debond index -> matched node pairs

    def __str__(self) -> str:
        lips = ", ".join(f"debond{i}: {n}" for i, n in sorted(self.lip_pairs.items())) or "none"
        return (f"cells {self.n_cells}, nodes {self.n_nodes}, aspect ratio "
                f"{self.min_aspect_ratio:.2f} .. {self.max_aspect_ratio:.2f}, "
                f"min angle {self.min_angle:.1f} deg, lip pairs: {lips}")


def quality_report(mesh: LayeredMesh) -> MeshQuality:
    """Measure ``mesh``: aspect ratios and angles from the four corners of each cell."""
    p = mesh.points[mesh.cells[:, :4]]  # (c, 4, 2) counter-clockwise corners
    edges = np.roll(p, -1, axis=1) - p
    length = np.linalg.norm(edges, axis=2)
    aspect = length.max(axis=1) / length.min(axis=1)
    a, b = -np.roll(edges, 1, axis=1), edges  # the two edges leaving each corner
    cos = np.sum(a * b, axis=2) / (np.linalg.norm(a, axis=2) * np.linalg.norm(b, axis=2))
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return MeshQuality(mesh.n_cells, len(mesh.points), float(aspect.min()), float(aspect.max()),
                       float(angle.min()), {i: len(v) for i, v in mesh.lip_pairs.items()})
