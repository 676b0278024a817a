"""A debond grown by a cohesive law in the 2D model: the lips ahead of each tip, held by the law.

Where a scene's debond has ``growth = { method = "cohesive", … }``, the mesh gives it lips over
its spans too (:func:`sandwich.meshes.layout.crack_extent`): coincident face and core nodes,
as on the debond. On a span each face-lip node (the slave of the lips' contact,
:mod:`sandwich.plane2d.contact`) is held to its coincident core-lip node c (its anchor) by the
law of :mod:`sandwich.cohesive_law`, on the jump Δ = x_s − x_c split along the core lip's
deformed normal and tangent at c, the chord a = x_{c+1} − x_{c−1} of c's neighbours on the chain
(one-sided at a chain's end):

    g = n · Δ = a × Δ / |a|   (the opening; the contact's tangent-line gap at c),
    s = t · Δ = a · Δ / |a|   (the sliding),

a function of the four nodes (s, c, c − 1, c + 1). The law is integrated along the span by the
face lip's nodal (Simpson) weights w over the span's quadratic facets, as is usual for cohesive
interfaces (it keeps the tractions free of the oscillations a Gauss rule gives on a stiff
interface); the first node, at the tip, has the weight of the facet ahead of it only. With b the
width, A = b w, and the law's tractions t and tangent T:

    f = A (t_n ∂g + t_s ∂s),
    K = A (T_nn ∂g ∂gᵀ + T_ns ∂g ∂sᵀ + T_sn ∂s ∂gᵀ + T_ss ∂s ∂sᵀ + t_n ∂²g + t_s ∂²s).

In compression the lips' contact acts as well (its slaves are every face-lip node, spans
included), so a fully damaged stretch is the contact of a debond. K is not symmetric where the
damage grows under a changing mode mix: the system then solves with the whole matrix
(:mod:`sandwich.plane2d.system`).

The damage of each node (the history) is committed at every converged state
(:meth:`sandwich.plane2d.system.Reference2DSystem.commit`); within an increment the law works
from the committed damage, so a rejected or retried step leaves no trace. This is the beam's
law (:mod:`sandwich.beam.cohesive`) on the 2D model's lips: the same scene keys, tips and
columns.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sandwich.cohesive_law import CohesiveLaw, CohesiveTip
from sandwich.growth.cohesive import tip_columns
from sandwich.plane2d.contact import (
    CHORD_MAP,
    JUMP_MAP,
    gaps_with_derivatives,
    slave_weights,
)

#: a node whose damage is at least this is fully debonded (the law's D reaches 1 exactly)
DEBONDED = 1.0 - 1e-9


@dataclass(eq=False)
class CohesiveLips(CohesiveTip):
    """One tip's cohesive nodes on a debond's lips: the tip and its law, the nodes, the damage."""

    slaves: np.ndarray  # (m,) positions in the pair's slave list
    weight: np.ndarray  # (m,) Simpson weights over the span (mm)
    x: np.ndarray  # (m,) reference x of the nodes (mm)
    damage: np.ndarray = field(default=None)  # (m,) committed (changed in place by commit)

    def __post_init__(self):
        """No damage at the start."""
        if self.damage is None:
            self.damage = np.zeros(len(self.slaves))


@dataclass
class CohesiveState:
    """The law at one state: per node its rows, forces, tangent blocks and trial damage."""

    rows: np.ndarray  # (m, 4) nodes (s, c, c − 1, c + 1)
    forces: np.ndarray  # (m, 8)
    tangents: np.ndarray | None  # (m, 8, 8), not symmetric where the damage grows
    opening: np.ndarray  # (m,) g (mm)
    sliding: np.ndarray  # (m,) s (mm)
    damage: np.ndarray  # (m,) the damage the state would commit

    def nodal_forces(self, n_nodes: int) -> np.ndarray:
        """The forces summed per node, (n_nodes, 2)."""
        f = np.zeros((n_nodes, 2))
        np.add.at(f, self.rows.ravel(), self.forces.reshape(-1, 2))
        return f


def slidings_with_derivatives(d: np.ndarray, a: np.ndarray):
    """Slidings s = a · d / |a| of n jumps d (n, 2) along chords a (n, 2), with derivatives.

    The gradient (n, 8) and Hessian (n, 8, 8) with respect to X = (x_s, x_0, x_1, x_2), d =
    x_s − x_0 and a = x_2 − x_1: the layout of
    :func:`~sandwich.plane2d.contact.gaps_with_derivatives`.
    """
    L2 = np.einsum("ni,ni->n", a, a)
    L = np.sqrt(L2)
    t = a / L[:, None]
    s = np.einsum("ni,ni->n", t, d)
    s_a = d / L[:, None] - (s / L)[:, None] * t  # ∂s/∂a
    H_da = np.eye(2)[None] / L[:, None, None] - np.einsum("ni,nj->nij", t, t) / L[:, None, None]
    H_aa = (-np.einsum("ni,nj->nij", s_a, t) - np.einsum("ni,nj->nij", t, s_a)
            - (s / L)[:, None, None] * (np.eye(2)[None] - np.einsum("ni,nj->nij", t, t))
            ) / L[:, None, None]
    grad = np.concatenate([t, -t, -s_a, s_a], axis=1)
    cross = np.einsum("ia,nij,jb->nab", JUMP_MAP, H_da, CHORD_MAP)
    hess = cross + cross.transpose(0, 2, 1) + np.einsum("ia,nij,jb->nab", CHORD_MAP, H_aa,
                                                        CHORD_MAP)
    return s, grad, hess


def jumps(pair, lips: CohesiveLips, x_ref: np.ndarray, u: np.ndarray, want_hessian: bool):
    """Openings and slidings of ``lips`` (on the compact ``pair``) with their derivatives.

    Returns the rows (m, 4), g, s (m,), their gradients (m, 8) and Hessians (m, 8, 8) (None
    unless asked for), with respect to the rows' positions.
    """
    last = len(pair.master) - 1
    c = pair.anchor[lips.slaves]
    s_nodes = pair.slave[lips.slaves]
    rows = np.column_stack([s_nodes, pair.master[c], pair.master[np.maximum(c - 1, 0)],
                            pair.master[np.minimum(c + 1, last)]])

    def offset(i, j):
        return (x_ref[i] - x_ref[j]) + (u[i] - u[j])

    d, a = offset(rows[:, 0], rows[:, 1]), offset(rows[:, 3], rows[:, 2])
    g, dg, hg = gaps_with_derivatives(d, a)
    s, ds, hs = slidings_with_derivatives(d, a)
    return rows, g, s, dg, ds, (hg if want_hessian else None), (hs if want_hessian else None)


def evaluate(pair, lips: CohesiveLips, x_ref: np.ndarray, u: np.ndarray,
             want_tangent: bool = True) -> CohesiveState:
    """The law's forces and tangent blocks of ``lips`` at reference positions + displacements."""
    rows, g, s, dg, ds, hg, hs = jumps(pair, lips, x_ref, u, want_tangent)
    t, T, D, _ = lips.law.response(g, s, lips.damage)
    A = pair.width * lips.weight
    f = (A * t[:, 0])[:, None] * dg + (A * t[:, 1])[:, None] * ds
    K = None
    if want_tangent:
        def outer(p, q):
            return np.einsum("ni,nj->nij", p, q)
        K = (T[:, 0, 0, None, None] * outer(dg, dg) + T[:, 0, 1, None, None] * outer(dg, ds)
             + T[:, 1, 0, None, None] * outer(ds, dg) + T[:, 1, 1, None, None] * outer(ds, ds)
             + t[:, 0, None, None] * hg + t[:, 1, None, None] * hs) * A[:, None, None]
    return CohesiveState(rows, f, K, g, s, D)


def growth_columns(lips_list: list[CohesiveLips]) -> dict[str, float]:
    """Each cohesive tip's position and process zone, of the committed damage.

    The columns of :func:`sandwich.growth.cohesive.tip_columns`, as the beam's.
    """
    out = {}
    for z in lips_list:
        out.update(tip_columns(z.debond, z.tip, z.origin, z.direction, z.x,
                               z.damage >= DEBONDED, z.damage > 0))
    return out


def lip_element_length(lips_list: list[CohesiveLips]) -> float:
    """The longest element (mm) over the cohesive spans (two node spacings of a Q2 facet)."""
    return max((2.0 * float(np.max(np.diff(np.sort(z.x)), initial=0.0)) for z in lips_list),
               default=0.0)


def cohesive_lips(scene, x_slave: np.ndarray, index: int, core_modulus: float,
                  tol: float) -> list[CohesiveLips]:
    """The cohesive nodes of debond ``index``'s tips among its face-lip nodes at ``x_slave``.

    Each tip's span (:meth:`sandwich.scene.Scene.cohesive_spans`) from the tip (included) to its
    far end (included only at an open mouth: elsewhere the lips meet there, bonded).
    ``core_modulus`` is the core's through-thickness modulus (MPa), for the default stiffness.
    """
    from sandwich.cohesive_law import (
        default_shear_strength,
        default_stiffness,
        least_stiffness,
    )
    d = scene.debonds[index]
    g, tough = d.growth, d.toughness
    out = []
    for span in scene.cohesive_spans():
        if span.debond != index:
            continue
        lo, hi = sorted((span.origin, span.far))
        mouth = span.far <= tol or span.far >= scene.length - tol
        inside = (x_slave >= lo - tol) & (x_slave <= hi + tol)
        if not mouth:
            inside &= np.abs(x_slave - span.far) > tol
        slaves = np.flatnonzero(inside)
        if slaves.size == 0:
            continue
        far = None if mouth else span.far
        left, right = (None, far) if span.direction > 0 else (far, None)
        weight = slave_weights(x_slave[slaves], left, right)
        tau = g.tau_c if g.tau_c is not None else default_shear_strength(g.sigma_c, tough.GIc,
                                                                         tough.GIIc)
        floor = least_stiffness(g.sigma_c, tau, tough.GIc, tough.GIIc)
        stiffness = g.stiffness or default_stiffness(core_modulus, scene.core.thickness, floor)
        law = CohesiveLaw(stiffness, g.sigma_c, tau, tough.GIc, tough.GIIc, tough.eta)
        out.append(CohesiveLips(law, index, span.tip, span.origin, span.direction, slaves,
                                weight, x_slave[slaves].copy()))
    return out
