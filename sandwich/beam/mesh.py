"""Nodes along the beam: exactly the requested element count, graded towards key stations.

Stations are x positions that must be nodes: the beam ends, debond ends, supports, load points and
patch edges, probes. A subset of them, the *refinement centres* (supports, debond tips, point
loads and patch edges), attracts small elements, and so may whole intervals, the *refinement
zones* (the debonded stretches, where a face buckles or wrinkles over its whole free length).

Element sizes follow a size function h(x) (mm):

* ``uniform``: h = const;
* ``graded`` (default): h(x) = min(h_max, h_min + (r − 1) d(x)), d = distance to the nearest
  refinement centre or zone (0 inside a zone), h_max = q · h_min. Elements next to a centre
  (and all along a zone) have length ≈ h_min and grow geometrically by about r per element
  (``growth``, default 1.2, bounded by 1.3) until they reach h_max (``size_ratio`` q, default
  12). h_min is set by bisection so that ∫ dx / h = the requested element count.

Each stretch between consecutive stations receives a whole number of elements (≥ 1) by largest
remainders of ∫ dx/h over it, so the total is **exactly** the requested count (ValueError if that
is smaller than the number of stretches), and its nodes equidistribute ∫ dx/h, so every station is
a node and sizes vary smoothly across stations.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

GRADINGS = ("graded", "uniform")
DEFAULT_GROWTH = 1.2
MAX_GROWTH = 1.3
DEFAULT_SIZE_RATIO = 12.0


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
        e, η = self.elements_at(np.array([x], dtype=float))
        return int(e[0]), float(η[0])

    def elements_at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`element_at` of an array of points on the beam (not checked), all at once."""
        e = np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, self.n_elements - 1)
        η = 2.0 * (x - self.x[e]) / (self.x[e + 1] - self.x[e]) - 1.0
        return e, np.clip(η, -1.0, 1.0)


def _clean(points: Iterable[float], length: float, tol: float, what: str) -> np.ndarray:
    pts = np.array(list(points), dtype=float)
    if not np.all(np.isfinite(pts)):
        raise ValueError(f"mesh {what} must be finite numbers")
    outside = pts[(pts < -tol) | (pts > length + tol)]
    if outside.size:
        raise ValueError(f"{what} {outside.tolist()} lie outside the beam [0, {length}]")
    return np.sort(np.clip(pts, 0.0, length))


def _clean_zones(zones: Iterable[tuple[float, float]], length: float, tol: float) -> np.ndarray:
    z = np.array([tuple(map(float, ab)) for ab in zones], dtype=float).reshape(-1, 2)
    if z.size:
        _clean(z.ravel(), length, tol, "refinement zones")
        if np.any(z[:, 1] <= z[:, 0]):
            raise ValueError(f"refinement zones must have start < end, got {z.tolist()}")
    return np.clip(z, 0.0, length)


def _largest_remainders(share: np.ndarray, total: int) -> np.ndarray:
    """Integers n_k ≥ 1 summing to ``total`` and close to the positive reals ``share``."""
    k = share.size
    if total < k:
        raise ValueError(f"{total} elements cannot give every one of the {k} stretches between "
                         "mesh stations an element; ask for more elements")
    # Give each stretch one element, distribute the rest in proportion to what is left over.
    extra = np.maximum(share - 1.0, 0.0)
    rest = total - k
    if extra.sum() <= 0:
        extra = share.copy()
    want = extra * rest / extra.sum()
    n = np.floor(want).astype(int)
    short = rest - int(n.sum())
    if short > 0:
        n[np.argsort(-(want - n), kind="stable")[:short]] += 1
    return n + 1


def build_mesh(
    length: float,
    elements: int,
    stations: Iterable[float] = (),
    merge_tol: float | None = None,
    *,
    centres: Iterable[float] | None = None,
    zones: Iterable[tuple[float, float]] = (),
    grading: str = "graded",
    growth: float = DEFAULT_GROWTH,
    size_ratio: float = DEFAULT_SIZE_RATIO,
) -> BeamMesh:
    """Nodes over [0, length]: exactly ``elements`` elements and a node at every station.

    Parameters
    ----------
    length
        Beam length (mm), positive.
    elements
        Number of elements over the length (≥ the number of stretches between stations).
    stations
        x positions (mm) that must be nodes; each must lie in [0, length].
    merge_tol
        Stations closer than this are merged (default 1e-6 × length).
    centres
        Refinement centres for ``graded`` (default: the stations and the beam ends).
    zones
        Refinement zones (a, b), a < b, for ``graded``: h = h_min across each of them.
    grading
        ``"graded"`` or ``"uniform"`` (see the module docstring).
    growth
        Size growth per element away from a centre, in (1, 1.3].
    size_ratio
        Largest over smallest element size q ≥ 1 (``graded``).
    """
    if not (np.isfinite(length) and length > 0):
        raise ValueError(f"beam length must be positive, got {length!r}")
    if not (isinstance(elements, int | np.integer) and elements >= 1):
        raise ValueError(f"element count must be a positive integer, got {elements!r}")
    if grading not in GRADINGS:
        raise ValueError(f"grading must be one of {GRADINGS}, got {grading!r}")
    if not (1.0 < growth <= MAX_GROWTH):
        raise ValueError(f"growth must lie in (1, {MAX_GROWTH}], got {growth!r}")
    if not size_ratio >= 1.0:
        raise ValueError(f"size_ratio must be ≥ 1, got {size_ratio!r}")
    tol = 1e-6 * length if merge_tol is None else merge_tol
    pts = _clean([0.0, length, *stations], length, tol, "stations")
    keep = np.concatenate([[True], np.diff(pts) > tol])
    pts = pts[keep]
    pts[-1] = length  # a station merged into the end keeps the end exact
    if grading == "uniform" or size_ratio == 1.0:
        density = lambda x: np.ones_like(x)  # noqa: E731  (relative 1/h)
    else:
        c = _clean([0.0, length] if centres is None else [0.0, length, *centres], length, tol,
                   "refinement centres")
        c = np.unique(c)
        z = _clean_zones(zones, length, tol)

        def density(x: np.ndarray) -> np.ndarray:
            # distance d to the nearest centre or zone; h/h_min = min(q, 1 + (r − 1) d / h_min)
            d = np.min(np.abs(x[:, None] - c[None, :]), axis=1)
            if z.size:
                dz = np.maximum(z[None, :, 0] - x[:, None], x[:, None] - z[None, :, 1])
                d = np.minimum(d, np.maximum(dz, 0.0).min(axis=1))
            return d

    # Fine sampling grid containing every station, for ∫ dx/h by the trapezoidal rule.
    m = max(4000, 40 * int(elements))
    grid = np.unique(np.concatenate([np.linspace(0.0, length, m + 1), pts]))
    if grading == "uniform" or size_ratio == 1.0:
        inv_h = np.full(grid.size, elements / length)
    else:
        d = density(grid)

        def inverse_size(h_min: float) -> np.ndarray:
            return 1.0 / np.minimum(size_ratio * h_min, h_min + (growth - 1.0) * d)

        def count(h_min: float) -> float:
            v = inverse_size(h_min)
            return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(grid)))

        lo, hi = length / elements / size_ratio * 1e-3, length  # count(lo) > elements > count(hi)
        for _ in range(200):
            mid = np.sqrt(lo * hi)
            lo, hi = (mid, hi) if count(mid) > elements else (lo, mid)
            if hi / lo < 1 + 1e-12:
                break
        inv_h = inverse_size(np.sqrt(lo * hi))
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (inv_h[1:] + inv_h[:-1]) * np.diff(grid))])
    at = np.interp(pts, grid, cum)
    n = _largest_remainders(np.diff(at), int(elements))
    nodes = [pts[:1]]
    for k, (a, b) in enumerate(zip(at[:-1], at[1:], strict=True)):
        if grading == "uniform" or size_ratio == 1.0:  # exact equal division of the stretch
            inner = np.linspace(pts[k], pts[k + 1], n[k] + 1)[1:-1]
        else:
            inner = np.interp(np.linspace(a, b, n[k] + 1)[1:-1], cum, grid)
        nodes.append(np.concatenate([inner, pts[k + 1: k + 2]]))
    return BeamMesh(np.concatenate(nodes))
