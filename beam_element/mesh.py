"""Nodes along the beam: a target element size, with nodes exactly at every special station.

Special stations are the beam ends, debond ends, supports, load points and patch edges, and
probes. Stations closer than ``merge_tol`` are merged. Each stretch between consecutive stations
is divided uniformly into round(stretch / target size) elements (at least one), so every special
station is a node and no sliver element appears.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BeamMesh:
    """Node coordinates x (mm), increasing; element e joins nodes e and e + 1."""

    x: np.ndarray

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return int(self.x.size)

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return int(self.x.size - 1)

    @property
    def lengths(self) -> np.ndarray:
        """Element lengths l (mm)."""
        return np.diff(self.x)

    @property
    def length(self) -> float:
        """Beam length (mm)."""
        return float(self.x[-1] - self.x[0])

    def node_at(self, x: float, tol: float | None = None) -> int:
        """Index of the node at ``x``; ValueError if there is none within ``tol``."""
        tol = 1e-9 * self.length if tol is None else tol
        i = int(np.argmin(np.abs(self.x - x)))
        if abs(self.x[i] - x) > tol:
            raise ValueError(f"no node at x = {x} (nearest node at {self.x[i]})")
        return i

    def element_at(self, x: float) -> tuple[int, float]:
        """Element containing ``x`` and the reference coordinate η of ``x`` in it."""
        if not (self.x[0] - 1e-12 * self.length <= x <= self.x[-1] + 1e-12 * self.length):
            raise ValueError(f"x = {x} lies outside the beam [{self.x[0]}, {self.x[-1]}]")
        e = int(np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, self.n_elements - 1))
        η = 2.0 * (x - self.x[e]) / (self.x[e + 1] - self.x[e]) - 1.0
        return e, float(np.clip(η, -1.0, 1.0))


def build_mesh(
    length: float,
    elements: int,
    stations: Iterable[float] = (),
    merge_tol: float | None = None,
) -> BeamMesh:
    """Nodes over [0, length] with about ``elements`` elements and a node at every station.

    Parameters
    ----------
    length
        Beam length (mm), positive.
    elements
        Target number of elements over the length (≥ 1).
    stations
        x positions (mm) that must be nodes; each must lie in [0, length].
    merge_tol
        Stations closer than this are merged (default 1e-6 × length).
    """
    if not (np.isfinite(length) and length > 0):
        raise ValueError(f"beam length must be positive, got {length!r}")
    if not (isinstance(elements, int | np.integer) and elements >= 1):
        raise ValueError(f"element count must be a positive integer, got {elements!r}")
    tol = 1e-6 * length if merge_tol is None else merge_tol
    pts = np.array([0.0, length, *stations], dtype=float)
    if not np.all(np.isfinite(pts)):
        raise ValueError("mesh stations must be finite numbers")
    outside = pts[(pts < -tol) | (pts > length + tol)]
    if outside.size:
        raise ValueError(f"stations {outside.tolist()} lie outside the beam [0, {length}]")
    pts = np.sort(np.clip(pts, 0.0, length))
    keep = np.concatenate([[True], np.diff(pts) > tol])
    pts = pts[keep]
    pts[-1] = length  # a station merged into the end keeps the end exact
    h = length / elements
    nodes = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(1, int(round((b - a) / h)))
        nodes.append(np.linspace(a, b, n + 1)[1:])
    return BeamMesh(np.concatenate(nodes))
