"""Key stations along the beam, degenerate-geometry handling, and the half model.

Every x where something happens (beam ends, debond ends, supports, load-patch edges, point loads,
probes) becomes a *station*: a column of block corners in the mesh. Stations closer than the snap
tolerance are merged onto the most important one with a warning; a change that would destroy a
feature (a debond shorter than the tolerance, two debonds of one interface closer than it) is
refused with a ``ValueError`` that says why.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from sandwich.scene import Problem, Scene, SceneError

GEOM_TOL = 1e-9  # mm: coordinates closer than this are the same station

# priority of a station kind when merging close stations (lower wins, 0 never moves)
PRIORITY = {"end": 0, "symmetry": 0, "debond": 1, "support": 2, "load": 3, "probe": 4}
SHARP = ("debond", "support", "load")  # kinds whose station gets the tip element size


def crack_extent(scene: Scene, index: int) -> tuple[float, float]:
    """The stretch of interface debond ``index`` has lips over (mm).

    The debond, and for a debond grown by a cohesive law its spans too
    (:meth:`sandwich.scene.Scene.cohesive_spans`), whose face and core sides the law holds together
    until it lets them go.
    """
    d = scene.debonds[index]
    lo, hi = d.start, d.end
    for span in scene.cohesive_spans():
        if span.debond == index:
            lo, hi = min(lo, span.far), max(hi, span.far)
    return lo, hi


@dataclass(frozen=True)
class Crack:
    """A debond as meshed: scene index, interface and its (possibly snapped) lips' ends (mm).

    A debond grown by a cohesive law has lips over its spans too (:func:`crack_extent`): its
    ends are then the spans' far ends, where the lips meet in a bonded corner (or an open mouth).
    """

    index: int
    interface: str  # "top" | "bottom"
    start: float
    end: float

    def contains(self, x: float) -> bool:
        """Whether x is strictly between the tips."""
        return self.start + GEOM_TOL < x < self.end - GEOM_TOL


@dataclass(frozen=True)
class Layout:
    """Stations and features of the meshed stretch [0, x_end] (the whole beam or its half)."""

    length: float  # scene length L (mm)
    x_end: float  # L, or L/2 for a half model
    half: bool
    stations: tuple[float, ...]  # sorted, from 0 to x_end
    sharp: tuple[bool, ...]  # per station: tip element size wanted there
    cracks: tuple[Crack, ...]  # every debond of positive length touching [0, x_end]
    supports: tuple[tuple[int, float], ...]  # (scene index, x) in [0, x_end]
    loads: tuple[tuple[int, float, float], ...]  # (scene index, lo, hi); lo == hi: point load
    probes: tuple[tuple[str, float], ...]  # (name, x); mirrored into the half for a half model

    def debonded(self, a: float, b: float) -> bool:
        """Whether [a, b] lies on a debond of either interface."""
        return any(c.start - GEOM_TOL <= a and b <= c.end + GEOM_TOL for c in self.cracks)

    def is_open(self, crack: Crack, x: float) -> bool:
        """Whether the two lips of ``crack`` have separate corners at station x."""
        if crack.contains(x):
            return True
        at_end = abs(x) < GEOM_TOL or abs(x - self.length) < GEOM_TOL
        return at_end and (abs(x - crack.start) < GEOM_TOL or abs(x - crack.end) < GEOM_TOL)


def symmetry_problem(scene: Scene, tol: float = 1e-6) -> str | None:
    """Why ``scene`` is not symmetric about mid-span, or None if it is.

    A pin and a roller count as mirror images: with the symmetry plane holding u_x, both ends
    only hold u_z.
    """
    L = scene.length

    def kind(t: str) -> str:
        return "hinge" if t in ("pin", "roller") else t

    def same(a: list[tuple], b: list[tuple]) -> bool:
        return len(a) == len(b) and all(
            p[0] == q[0] and all(abs(u - v) < tol for u, v in zip(p[1:], q[1:], strict=True))
            for p, q in zip(sorted(a), sorted(b), strict=True))

    deb = [(d.interface, d.start, d.end) for d in scene.debonds if d.length > 0]
    if not same(deb, [(i, L - e, L - s) for i, s, e in deb]):
        return "the debonds are not symmetric about mid-span"
    sup = [(f"{s.on}:{kind(s.type)}", s.x) for s in scene.supports]
    if not same(sup, [(k, L - x) for k, x in sup]):
        return "the supports are not symmetric about mid-span"
    if any(abs(s.x - 0.5 * L) < tol for s in scene.supports):
        return "a support lies on the symmetry plane"
    lds = [(ld.on, ld.x, ld.width, ld.force) for ld in scene.loads]
    if not same(lds, [(o, L - x, w, f) for o, x, w, f in lds]):
        return "the loads are not symmetric about mid-span"
    return None


def _entries(scene: Scene, x_end: float, half: bool) -> list[tuple[float, str, str]]:
    """(x, kind, label) of every key station inside [0, x_end]."""
    L = scene.length
    out = [(0.0, "end", "beam end x=0")]
    out.append((x_end, "symmetry" if half else "end", "mid-span" if half else f"beam end x={L:g}"))
    for i, d in enumerate(scene.debonds):
        if d.length > 0:
            out += [(d.start, "debond", f"debonds[{i}].start"),
                    (d.end, "debond", f"debonds[{i}].end")]
            lo, hi = crack_extent(scene, i)
            out += [(x, "debond", f"debonds[{i}].growth.zone ({which})")
                    for x, which, at in ((lo, "start", d.start), (hi, "end", d.end)) if x != at]
    for i, s in enumerate(scene.supports):
        out.append((s.x, "support", f"supports[{i}].x"))
    for i, ld in enumerate(scene.loads):
        lo, hi = ld.span
        if ld.width > 0:
            out += [(lo, "load", f"loads[{i}] start"), (hi, "load", f"loads[{i}] end")]
        else:
            out.append((ld.x, "load", f"loads[{i}].x"))
    for p in scene.probes:
        x = L - p.x if half and p.x > x_end else p.x
        out.append((x, "probe", f"probes[{p.name}].x"))
    return [e for e in out if -GEOM_TOL <= e[0] <= x_end + GEOM_TOL]


def _snap(entries: list[tuple[float, str, str]], tol: float,
          interface: dict[str, str]) -> dict[str, float]:
    """Merge stations closer than ``tol``; return label -> new x, warning about every move."""
    entries = sorted(entries)
    clusters: list[list[tuple[float, str, str]]] = [[entries[0]]]
    for e in entries[1:]:
        if e[0] - clusters[-1][-1][0] < tol:
            clusters[-1].append(e)
        else:
            clusters.append([e])
    where: dict[str, float] = {}
    for cl in clusters:
        anchor = min(cl, key=lambda e: PRIORITY[e[1]])
        debond_ends = [e[2] for e in cl if e[1] == "debond"]
        owners = [lbl.split(".")[0] for lbl in debond_ends]
        if len(set(owners)) < len(owners):
            raise _Unmeshable(owners[0], f"shorter than {tol:g} mm, the smallest debond this "
                              "mesh level can resolve; remove it (bonded) or use a finer "
                              "[reference2d] level")
        sides = [interface[o] for o in owners]
        if len(set(sides)) < len(sides):
            raise _Unmeshable(owners[0], f"{' and '.join(owners)} on one interface are less "
                              f"than {tol:g} mm apart (one element): merge them into one debond "
                              "or use a finer [reference2d] level")
        for e in cl:
            if abs(e[0] - anchor[0]) > GEOM_TOL:
                warnings.warn(f"mesh: {e[2]} moved from {e[0]:g} to {anchor[0]:g} mm onto "
                              f"{anchor[2]} (closer than {tol:g} mm)", stacklevel=4)
            where[e[2]] = anchor[0]
    return where


def _check_gaps(cracks: list[Crack], tol: float) -> None:
    """Refuse overlapping debonds, or debonds of one interface closer than ``tol``."""
    for itf in ("top", "bottom"):
        same = sorted((c for c in cracks if c.interface == itf), key=lambda c: c.start)
        for c1, c2 in zip(same, same[1:], strict=False):
            if c2.start - c1.end < tol:
                raise _Unmeshable(
                    f"debonds[{c1.index}]",
                    f"debonds[{c1.index}] and debonds[{c2.index}] on the {itf} interface are "
                    f"{c2.start - c1.end:g} mm apart (less than {tol:g} mm, one element): "
                    "merge them into one debond or use a finer [reference2d] level")


class _Unmeshable(ValueError):
    """A scene feature the mesh level cannot resolve: the scene key and the reason."""

    def __init__(self, key: str, reason: str):
        self.key, self.reason = key, reason
        super().__init__(f"{key}: {reason}")


def make_layout(scene: Scene, snap_tolerance: float, half: bool = False) -> Layout:
    """The stations and features of ``scene``, merged where closer than ``snap_tolerance``.

    Raises
    ------
    SceneError
        Naming the scene file and key, where a feature is smaller than the level resolves.
    """
    try:
        return _layout(scene, snap_tolerance, half)
    except _Unmeshable as exc:
        where = str(scene.source) if scene.source is not None else scene.name
        raise SceneError([Problem(where, exc.key, exc.reason)]) from None


def _layout(scene: Scene, snap_tolerance: float, half: bool) -> Layout:
    L = scene.length
    if half:
        why = symmetry_problem(scene)
        if why is not None:
            raise ValueError(f"scene {scene.name!r} cannot be meshed as a half model: {why}")
    x_end = 0.5 * L if half else L
    entries = _entries(scene, x_end, half)
    where = _snap(entries, snap_tolerance,
                  {f"debonds[{i}]": d.interface for i, d in enumerate(scene.debonds)})
    cracks = []
    for i, d in enumerate(scene.debonds):
        if d.length <= 0:
            continue  # zero length: bonded
        lo, hi = crack_extent(scene, i)
        a = where.get(f"debonds[{i}].growth.zone (start)", where.get(f"debonds[{i}].start", lo))
        b = where.get(f"debonds[{i}].growth.zone (end)", where.get(f"debonds[{i}].end", hi))
        if half and a >= x_end - GEOM_TOL:
            continue
        cracks.append(Crack(i, d.interface, a, b))
    _check_gaps(cracks, snap_tolerance)
    stations = sorted(set(where.values()))
    sharp_x = {where[lbl] for _, kind, lbl in entries if kind in SHARP}
    supports = tuple((i, where[f"supports[{i}].x"]) for i, s in enumerate(scene.supports)
                     if f"supports[{i}].x" in where)
    loads = []
    for i, ld in enumerate(scene.loads):
        if ld.width > 0:
            lo, hi = where.get(f"loads[{i}] start"), where.get(f"loads[{i}] end")
            if lo is None:
                continue  # right half of a symmetric scene
            loads.append((i, lo, x_end if hi is None else hi))
        elif f"loads[{i}].x" in where:
            x = where[f"loads[{i}].x"]
            loads.append((i, x, x))
    probes = tuple((p.name, where[f"probes[{p.name}].x"]) for p in scene.probes)
    sharp = tuple(any(abs(x - s) < GEOM_TOL for s in sharp_x) for x in stations)
    if not math.isclose(stations[-1], x_end):
        raise AssertionError("the last station must be the end of the meshed stretch")
    return Layout(L, x_end, half, tuple(stations), sharp, tuple(cracks), supports,
                  tuple(loads), probes)
