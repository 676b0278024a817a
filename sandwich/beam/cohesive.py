"""A debond grown by a cohesive law: the interface ahead of each tip as nodal cohesive pairs.

Where a scene's debond has ``growth = { method = "cohesive", … }``, the nodes from each tip
over its span (:meth:`sandwich.scene.Scene.cohesive_spans`) are untied and each carries the law
of :mod:`sandwich.cohesive_law` between the face's inner surface and the core boundary of
the same x (the same-x pairs of the contact, :mod:`sandwich.beam.contact_gap`): the opening g
along the core's deformed normal and the sliding s along its tangent. The tie of a bonded node
also holds the slopes (w_face,x = w_core,x, section 2.3); their jump θ = w_face,x − w_core,x
makes the opening vary across the node's tributary length l, so the law is integrated at two
points of it, at ±l/(2√3) (the Gauss points of a linear opening over l), each with half the
node's area A and its own damage:

    g_± = g ± θ l/(2√3),
    f = Σ± (A/2) [t_n(g_±, s) ∂g_± + t_s(g_±, s) ∂s] − A p(g) ∂g,
    K = Σ± (A/2) [T_nn ∂g_± ∂g_±ᵀ + T_ns ∂g_± ∂sᵀ + T_sn ∂s ∂g_±ᵀ + T_ss ∂s ∂sᵀ
                  + t_n ∂²g + t_s ∂²s] − A p'(g) ∂g ∂gᵀ − A p ∂²g,

p(g) the contact law of the debonded stretches on the node's gap (so a fully damaged pair is the
contact of a debond), T the law's tangent (not symmetric where the damage grows under a changing
mode mix: :mod:`sandwich.beam.unsymmetric`). Undamaged, θ's stiffness is K A l²/12. Node-wise
(trapezoidal) integration along x, as is usual for cohesive interfaces: it keeps the tractions
free of the oscillations a Gauss rule gives on a stiff interface. Undamaged, the pairs are the
tie up to the compliance 1/K: on the face cantilever's mesh the load at a deflection is 0.31 %
below the tied model's at the default K, 5e-6 below at 1000 × it
(tests/growth/test_beam_cohesive.py).

The damage D of each point (the history) is committed at every converged state
(:meth:`sandwich.beam.model.BeamModel.commit`); within an increment the law works from the
committed damage, so a rejected or retried step leaves no trace. A state carried onto another
model (core levels raised, elements split) takes its own damage with it by x
(:func:`carry_damage`; the model keeps each committed state's damage,
:meth:`sandwich.beam.model.BeamModel.committed_damage`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from sandwich.beam.contact_gap import PairKinematics, same_x_kinematics, same_x_sliding
from sandwich.beam.contact_law import pressure_law
from sandwich.beam.contact_search import contact_pairs
from sandwich.beam.dofs import global_dof
from sandwich.cohesive_law import (
    CohesiveLaw,
    CohesiveTip,
    default_shear_strength,
    default_stiffness,
    least_stiffness,
)
from sandwich.growth.cohesive import tip_columns

#: the pair's seven DOFs: the same-x contact pair's six (PAIR_ROLES), then the face's slope
SLOPE, CORE_SLOPE = 6, 5
#: a pair whose damage is at least this is fully debonded (the law's D reaches 1 exactly)
DEBONDED = 1.0 - 1e-9
#: prefixes of the history columns of :func:`growth_columns`
GROWTH_COLUMNS = ("tip_", "process_zone_")


@dataclass(eq=False)
class CohesiveZone(CohesiveTip):
    """One tip's cohesive pairs: the tip and its law, and the committed damage."""

    damage: np.ndarray  # (m, 2) committed, per pair and point (changed in place by commit)
    width: float  # the beam's width b (mm): a pair's tributary length is its area / b


def _points(pairs: object, u_full: np.ndarray) -> tuple:
    """Openings, slidings and their derivatives at each pair's two points (see the module).

    Returns g (m, 2), s (m,), ∂g (m, 2, 7), ∂s (m, 7), ∂²g (m, 7, 7) (the same at both points:
    θ is linear in the DOFs), ∂²s (m, 7, 7) and the same-x kinematics.
    """
    k = same_x_kinematics(pairs, u_full)
    s, ds, d2s = same_x_sliding(pairs, u_full)
    v = u_full[pairs.dofs]
    theta = v[:, SLOPE] - v[:, CORE_SLOPE]
    reach = (pairs.area / pairs.cohesive.width) / (2.0 * np.sqrt(3.0))  # l / (2√3)
    offset = reach[:, None] * np.array([-1.0, 1.0])  # (m, 2)
    g = k.gap[:, None] + offset * theta[:, None]
    dtheta = np.zeros((pairs.size, 7))
    dtheta[:, SLOPE], dtheta[:, CORE_SLOPE] = 1.0, -1.0
    dg = _seven(k.grad)[:, None, :] + offset[:, :, None] * dtheta[:, None, :]
    return g, s, dg, _seven(ds), _seven(k.hess), _seven(d2s), k


def cohesive_response(
    pairs: object, u_full: np.ndarray, penalty: float, smoothing: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics]:
    """Forces (m, 7), tangents (m, 7, 7), contact pressures (m,) and kinematics of the pairs.

    ``pairs`` a same-x :class:`~sandwich.beam.contact_search.ContactPairs` whose ``cohesive``
    is a :class:`CohesiveZone`; ``penalty`` and ``smoothing`` the contact law's (compression,
    on the node's gap, as the contact of a debond).
    """
    zone: CohesiveZone = pairs.cohesive
    g, s, dg, ds, hg, hs, k = _points(pairs, u_full)
    m = pairs.size
    t, T, _, _ = zone.law.response(g.ravel(), np.repeat(s, 2), zone.damage.ravel())
    t, T = t.reshape(m, 2, 2), T.reshape(m, 2, 2, 2)  # (pair, point, component[, component])
    half = 0.5 * pairs.area  # each point's area
    tn, ts = t[..., 0], t[..., 1]
    f = np.einsum("mp,mpi->mi", half[:, None] * tn, dg) + (half * ts.sum(1))[:, None] * ds
    K = np.einsum("mp,mpi,mpj->mij", half[:, None] * T[..., 0, 0], dg, dg)
    K += np.einsum("mp,mpi,mj->mij", half[:, None] * T[..., 0, 1], dg, ds)
    K += np.einsum("mp,mi,mpj->mij", half[:, None] * T[..., 1, 0], ds, dg)
    K += (half * T[..., 1, 1].sum(1))[:, None, None] * ds[:, :, None] * ds[:, None, :]
    K += (half * tn.sum(1))[:, None, None] * hg + (half * ts.sum(1))[:, None, None] * hs
    # the contact of the node's gap, as on a debonded stretch
    p, dp = pressure_law(k.gap, penalty, smoothing)
    grad = _seven(k.grad)
    f -= (pairs.area * p)[:, None] * grad
    K -= (pairs.area * dp)[:, None, None] * grad[:, :, None] * grad[:, None, :]
    K -= (pairs.area * p)[:, None, None] * hg
    return f, K, p, PairKinematics(k.gap, k.grad, k.hess, s)


def _seven(a: np.ndarray) -> np.ndarray:
    """A (m, 6) gradient or (m, 6, 6) Hessian of the same-x DOFs on the pair's seven DOFs."""
    out = np.zeros(a.shape[:1] + (7,) * (a.ndim - 1))
    out[(slice(None),) + (slice(0, 6),) * (a.ndim - 1)] = a
    return out


def pair_damage(pairs: object, u_full: np.ndarray) -> np.ndarray:
    """The damage (m, 2) the pairs' points would commit at ``u_full`` (history included)."""
    g, s = _points(pairs, u_full)[:2]
    law, committed = pairs.cohesive.law, pairs.cohesive.damage
    return law.damage(g.ravel(), np.repeat(s, 2), committed.ravel()).real.reshape(g.shape)


def commit_damage(groups: list, u_full: np.ndarray) -> None:
    """Commit the damage of every cohesive group at the converged state ``u_full``."""
    for pairs in groups:
        if pairs.cohesive is not None:
            pairs.cohesive.damage[:] = pair_damage(pairs, u_full)


def carry_damage(source: object, target: object, u: np.ndarray | None = None) -> None:
    """Give ``target``'s cohesive pairs the damage of ``source``'s, by x.

    Both are :class:`~sandwich.beam.model.BeamModel`. The damage ``source`` committed at its
    state ``u`` where it committed that state (a path taken again from an earlier state after
    the core levels were raised starts from that state's damage, not from the latest), else
    its latest. A node of ``target`` between two of ``source``'s (elements split in two)
    takes the larger damage of the two, so that no damage is lost.
    """
    kept = None if u is None else source.committed_damage(u)
    x_s, x_t = source.mesh.x, target.mesh.x
    for t in target.pairs:
        if t.cohesive is None:
            continue
        match = [(k, s) for k, s in enumerate(source.pairs) if s.cohesive is not None
                 and (s.cohesive.debond, s.cohesive.tip) == (t.cohesive.debond, t.cohesive.tip)]
        if not match:
            continue
        k, s = match[0]
        xs = x_s[s.nodes]
        ds = s.cohesive.damage if kept is None else kept[k]
        order = np.argsort(xs)
        xs, ds = xs[order], ds[order]
        xt = x_t[t.nodes]
        j = np.searchsorted(xs, xt)
        lo, hi = np.clip(j - 1, 0, xs.size - 1), np.clip(j, 0, xs.size - 1)
        same_hi, same_lo = np.isclose(xs[hi], xt)[:, None], np.isclose(xs[lo], xt)[:, None]
        t.cohesive.damage[:] = np.where(
            same_hi, ds[hi], np.where(same_lo, ds[lo], np.maximum(ds[lo], ds[hi])))


def growth_columns(model: object) -> dict[str, float]:
    """Each cohesive tip's position and process zone, of the committed damage.

    The columns of :func:`sandwich.growth.cohesive.tip_columns`; a node is fully debonded
    where both its points are.
    """
    out = {}
    for pairs in model.pairs:
        z = pairs.cohesive
        if z is not None:
            out.update(tip_columns(z.debond, z.tip, z.origin, z.direction,
                                   model.mesh.x[pairs.nodes], z.damage.min(axis=1) >= DEBONDED,
                                   z.damage.max(axis=1) > 0))
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
        tau = g.tau_c if g.tau_c is not None else default_shear_strength(g.sigma_c, t.GIc,
                                                                         t.GIIc)
        floor = least_stiffness(g.sigma_c, tau, t.GIc, t.GIIc)
        stiffness = g.stiffness or default_stiffness(core_modulus, scene.core.thickness, floor)
        law = CohesiveLaw(stiffness, g.sigma_c, tau, t.GIc, t.GIIc, t.eta)
        zone = CohesiveZone(law, span.debond, span.tip, span.origin, span.direction,
                            np.zeros((nodes.size, 2)), float(scene.width))
        slope = global_dof(nodes, "w_t,x" if span.interface == "top" else "w_b,x")
        out.append(dataclasses.replace(pairs, area=area, dofs=np.column_stack([pairs.dofs, slope]),
                                       cohesive=zone))
    return out
