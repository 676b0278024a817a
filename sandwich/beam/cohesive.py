"""A debond grown by a cohesive law: the interface ahead of each tip as nodal cohesive pairs.

Where a scene's debond has ``growth = { method = "cohesive", … }``, the nodes from each tip
over its span (:meth:`sandwich.scene.Scene.cohesive_spans`) are untied and each carries the law
of :mod:`sandwich.beam.cohesive_law` between the face's inner surface and the core boundary of
the same x (the same-x pairs of the contact, :mod:`sandwich.beam.contact_gap`): the opening g
along the core's deformed normal and the sliding s along its tangent,

    f = A [(t_n(g, s) − p(g)) ∂g + t_s(g, s) ∂s],
    K = A [T_nn ∂g ∂gᵀ + T_ns (∂g ∂sᵀ + ∂s ∂gᵀ) + T_ss ∂s ∂sᵀ + (t_n − p) ∂²g + t_s ∂²s],

A the node's tributary area (b × half of each adjacent element inside the span), p(g) the
contact law of the debonded stretches (acting in compression, so a fully damaged pair is the
contact of a debond), T the law's tangent less p'(g) on T_nn. Nodal (trapezoidal) integration
of the interface, as is usual for cohesive interfaces: it keeps the tractions free of the
oscillations a Gauss rule gives on a stiff interface.

The damage D of each pair (the history) is committed at every converged state
(:meth:`sandwich.beam.model.BeamModel.commit`); within an increment the law works from the
committed damage, so a rejected or retried step leaves no trace. A state carried onto another
model (core levels raised, elements split) takes the damage with it by x
(:func:`carry_damage`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from sandwich.beam.cohesive_law import CohesiveLaw, default_stiffness
from sandwich.beam.contact_gap import PairKinematics, same_x_kinematics, same_x_sliding
from sandwich.beam.contact_law import pressure_law
from sandwich.beam.contact_search import contact_pairs

#: a pair whose damage is at least this is fully debonded (the law's D reaches 1 exactly)
DEBONDED = 1.0 - 1e-9
#: prefixes of the history columns of :func:`growth_columns`
GROWTH_COLUMNS = ("tip_", "process_zone_")


@dataclass(eq=False)
class CohesiveZone:
    """One tip's cohesive pairs: the law, where the tip started, and the committed damage."""

    law: CohesiveLaw
    debond: int
    tip: str  # "start" | "end"
    origin: float  # the tip's x at the start of the run (mm)
    direction: int  # +1: the tip grows towards larger x
    damage: np.ndarray  # (m,) committed, per pair (changed in place by commit)


def cohesive_response(
    pairs: object, u_full: np.ndarray, penalty: float, smoothing: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics]:
    """Forces (m, 6), tangents (m, 6, 6), contact pressures (m,) and kinematics of the pairs.

    ``pairs`` a same-x :class:`~sandwich.beam.contact_search.ContactPairs` whose ``cohesive``
    is a :class:`CohesiveZone`; ``penalty`` and ``smoothing`` the contact law's (compression).
    """
    zone: CohesiveZone = pairs.cohesive
    k = same_x_kinematics(pairs, u_full)
    s, ds, d2s = same_x_sliding(pairs, u_full)
    t, T, _ = zone.law.response(k.gap, s, zone.damage)
    p, dp = pressure_law(k.gap, penalty, smoothing)
    tn, ts = t[:, 0] - p, t[:, 1]
    A = pairs.area
    dg = k.grad
    f = A[:, None] * (tn[:, None] * dg + ts[:, None] * ds)
    gg = dg[:, :, None] * dg[:, None, :]
    gs = dg[:, :, None] * ds[:, None, :]
    ss = ds[:, :, None] * ds[:, None, :]
    K = ((T[:, 0, 0] - dp)[:, None, None] * gg + T[:, 0, 1][:, None, None] * (gs + np.swapaxes(
        gs, 1, 2)) + T[:, 1, 1][:, None, None] * ss + tn[:, None, None] * k.hess
        + ts[:, None, None] * d2s)
    K *= A[:, None, None]
    return f, K, p, PairKinematics(k.gap, k.grad, k.hess, s)


def pair_damage(pairs: object, u_full: np.ndarray) -> np.ndarray:
    """The damage the pairs would commit at ``u_full`` (committed history included)."""
    zone: CohesiveZone = pairs.cohesive
    k = same_x_kinematics(pairs, u_full)
    s = same_x_sliding(pairs, u_full)[0]
    return zone.law.damage(k.gap, s, zone.damage)


def commit_damage(groups: list, u_full: np.ndarray) -> None:
    """Commit the damage of every cohesive group at the converged state ``u_full``."""
    for pairs in groups:
        if pairs.cohesive is not None:
            pairs.cohesive.damage[:] = pair_damage(pairs, u_full)


def carry_damage(source: object, target: object) -> None:
    """Give ``target``'s cohesive pairs the committed damage of ``source``'s, by x.

    Both are :class:`~sandwich.beam.model.BeamModel`; a node of ``target`` between two of
    ``source``'s (elements split in two) takes the larger damage of the two, so that no
    damage is lost and the carried state is never less debonded.
    """
    x_s, x_t = source.mesh.x, target.mesh.x
    for t in target.pairs:
        if t.cohesive is None:
            continue
        match = [s for s in source.pairs if s.cohesive is not None
                 and (s.cohesive.debond, s.cohesive.tip) == (t.cohesive.debond, t.cohesive.tip)]
        if not match:
            continue
        s = match[0]
        xs, ds = x_s[s.nodes], s.cohesive.damage
        order = np.argsort(xs)
        xs, ds = xs[order], ds[order]
        xt = x_t[t.nodes]
        j = np.searchsorted(xs, xt)
        lo, hi = np.clip(j - 1, 0, xs.size - 1), np.clip(j, 0, xs.size - 1)
        t.cohesive.damage[:] = np.where(
            np.isclose(xs[hi], xt), ds[hi],
            np.where(np.isclose(xs[lo], xt), ds[lo], np.maximum(ds[lo], ds[hi])))


def growth_columns(model: object) -> dict[str, float]:
    """History columns of the committed damage: each cohesive tip's position and process zone.

    ``tip_<debond>_<tip>``: x (mm) of the farthest fully debonded node reached from the tip's
    origin through fully debonded nodes only (the origin itself while none is);
    ``process_zone_<debond>_<tip>``: the length (mm) from there to the farthest damaged node.
    """
    out = {}
    for pairs in model.pairs:
        zone = pairs.cohesive
        if zone is None:
            continue
        x = model.mesh.x[pairs.nodes]
        order = np.argsort(zone.direction * (x - zone.origin))
        dist = zone.direction * (x[order] - zone.origin)
        D = zone.damage[order]
        broken = np.cumprod(D >= DEBONDED).astype(bool)
        reach = float(dist[broken].max()) if broken.any() else 0.0
        damaged = float(dist[D > 0].max()) if np.any(D > 0) else reach
        key = f"{zone.debond}_{zone.tip}"
        out[f"tip_{key}"] = float(zone.origin + zone.direction * reach)
        out[f"process_zone_{key}"] = max(damaged - reach, 0.0)
    return out


def cohesive_groups(scene: object, x: np.ndarray, core_modulus: float) -> list:
    """The cohesive pairs of every growing tip of ``scene`` on the nodes ``x`` (mm).

    One same-x :class:`~sandwich.beam.contact_search.ContactPairs` per tip
    (:meth:`sandwich.scene.Scene.cohesive_spans`): the nodes from the tip (included) over its
    span, the far end included only at a beam end (elsewhere the node there stays tied). The
    tip node's area is the half element ahead of it (the one behind is debonded).
    ``core_modulus`` is the core's through-thickness modulus (MPa), for the default stiffness.
    """
    tol = 1e-9 * scene.length
    out = []
    for span in scene.cohesive_spans():
        d = scene.debonds[span.debond]
        g, t = d.growth, d.toughness
        lo, hi = sorted((span.origin, span.far))
        inside = (x >= lo - tol) & (x <= hi + tol)
        at_end = span.far <= tol or span.far >= scene.length - tol
        if not at_end:
            inside &= np.abs(x - span.far) > tol
        nodes = np.flatnonzero(inside)
        if nodes.size == 0:
            continue
        pairs = contact_pairs(span.interface, nodes, x, scene.width)
        area = pairs.area.copy()
        tip = int(np.argmin(np.abs(x[nodes] - span.origin)))
        nb = nodes[tip] + span.direction
        area[tip] = 0.5 * scene.width * (abs(x[nb] - x[nodes[tip]]) if 0 <= nb < x.size
                                         else 0.0)
        floor = max(g.sigma_c**2 / (2 * t.GIc), g.tau_c**2 / (2 * t.GIIc))
        stiffness = g.stiffness or default_stiffness(core_modulus, scene.core.thickness, floor)
        law = CohesiveLaw(stiffness, g.sigma_c, g.tau_c, t.GIc, t.GIIc, t.eta)
        zone = CohesiveZone(law, span.debond, span.tip, span.origin, span.direction,
                            np.zeros(nodes.size))
        out.append(dataclasses.replace(pairs, area=area, cohesive=zone))
    return out
