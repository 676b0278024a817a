"""Geometric grading of element lengths along the beam axis.

A stretch between two key stations is cut into *segments*, each meshed with ``n`` elements whose
lengths follow a geometric progression (gmsh's transfinite ``Progression``). Near a *sharp*
station (crack tip, load-patch edge, support) the first element has the tip size and each next one
is at most ``growth`` times longer, until the far-field size is reached; the rest is uniform.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

REL_TOL = 1e-9


@dataclass(frozen=True)
class Segment:
    """A stretch [x0, x1] meshed with ``n`` elements growing by ``ratio`` from x0 towards x1."""

    x0: float  # mm
    x1: float  # mm
    n: int
    ratio: float  # element length ratio of neighbours, in the direction x0 -> x1

    def subdivided(self, times: int) -> Segment:
        """The same segment with every element split into ``times`` (nested refinement)."""
        return Segment(self.x0, self.x1, self.n * times, self.ratio ** (1.0 / times))

    def element_lengths(self) -> list[float]:
        """The ``n`` element lengths from x0 to x1 (mm)."""
        w = [self.ratio**i for i in range(self.n)]
        s = (self.x1 - self.x0) / sum(w)
        return [s * wi for wi in w]


def _ratio_for(length: float, h0: float, n: int) -> float:
    """Ratio r > 1 with h0 (1 + r + ... + r^(n-1)) = length (bisection)."""
    lo, hi = 1.0, 2.0
    while h0 * sum(hi**i for i in range(n)) < length:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if h0 * sum(mid**i for i in range(n)) < length:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _graded_length(h0: float, hmax: float, growth: float) -> tuple[int, float]:
    """Number of elements and length of a full ramp from h0 up to (just below) hmax."""
    if hmax <= h0 * (1 + REL_TOL):
        return 0, 0.0
    k = max(1, math.ceil(math.log(hmax / h0) / math.log(growth)))
    return k, h0 * (growth**k - 1.0) / (growth - 1.0)


def _short_ramp(length: float, h0: float, growth: float) -> tuple[int, float]:
    """Fewest elements starting at h0 with neighbour ratio <= growth filling ``length``."""
    n = 1
    while True:
        if length <= n * h0 * (1 + REL_TOL):
            return n, 1.0
        if n > 1:  # one element cannot grow
            r = _ratio_for(length, h0, n)
            if r <= growth * (1 + REL_TOL):
                return n, r
        n += 1


def grade_block(a: float, b: float, sharp_a: bool, sharp_b: bool,
                tip: float, far: float, growth: float) -> list[Segment]:
    """Segments covering [a, b], fine at the sharp ends and at most ``far`` long elsewhere.

    Parameters
    ----------
    a, b
        Block ends (mm), a < b.
    sharp_a, sharp_b
        Whether the element at that end must have the tip size.
    tip, far
        Element length at a sharp station and far from it (mm).
    growth
        Largest ratio of the lengths of neighbouring elements (> 1).

    Returns
    -------
    list of Segment
        From a to b, contiguous.
    """
    length = b - a
    k, ramp = _graded_length(tip, far, growth)
    if not (sharp_a or sharp_b) or k == 0:
        return [Segment(a, b, max(1, math.ceil(length / far - REL_TOL)), 1.0)]
    if sharp_a and sharp_b:
        if length >= 2.0 * ramp + tip:  # ramp up, plateau, ramp down
            mid = length - 2.0 * ramp
            return [Segment(a, a + ramp, k, growth),
                    Segment(a + ramp, b - ramp, max(1, math.ceil(mid / far - REL_TOL)), 1.0),
                    Segment(b - ramp, b, k, 1.0 / growth)]
        n, r = _short_ramp(0.5 * length, tip, growth)
        m = 0.5 * (a + b)
        return [Segment(a, m, n, r), Segment(m, b, n, 1.0 / r)]
    if length >= ramp + tip:  # ramp from the sharp end, then plateau
        n_rest = max(1, math.ceil((length - ramp) / far - REL_TOL))
        if sharp_a:
            return [Segment(a, a + ramp, k, growth), Segment(a + ramp, b, n_rest, 1.0)]
        return [Segment(a, b - ramp, n_rest, 1.0), Segment(b - ramp, b, k, 1.0 / growth)]
    n, r = _short_ramp(length, tip, growth)
    return [Segment(a, b, n, r)] if sharp_a else [Segment(a, b, n, 1.0 / r)]
