"""The compiled evaluation of a beam model: free-DOF force and reduced tangent in one pass.

The layers are evaluated by the compiled kernels (:mod:`sandwich.beam.kernels`), which add each
element's tangent straight into the CSR values of the reduced matrix through the pattern's slot
maps; the contact groups' blocks are added by slot map (same-x) or, for closest-point pairs, on
each pair's chosen segment only (:func:`sandwich.beam.kernels.scatter_compact_known`). The
pattern holds the layers and, of each closest-point pair, the segments next to its node; it
grows by the segments the projections of pairs in contact meet (:meth:`CompiledAssembly.grow`;
an open pair's block is zero and needs no slots). A Newton iterate asks for the tangent at
every u whose residual it evaluates (fig. 5: 139 forces, 140 tangents), so the tangent comes
with every force.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from sandwich.beam.assembly import ReducedPattern, reduced_pattern
from sandwich.beam.contact import compact_response, penalty_response
from sandwich.beam.contact_search import CORE_NODE_ROLES, ContactPairs
from sandwich.beam.dofs import CONTACT_DOFS, NODE_DOFS, dof, global_dof
from sandwich.beam.element import layer_state, layer_tangent
from sandwich.solver.spares import free_array

SPARE_VALUES = 3  # tangent value arrays kept for reuse (CompiledAssembly.zeroed_values)


class ContactTerm(NamedTuple):
    """One contact group's blocks as added into a tangent's values (to be taken out again)."""

    group: int  # block family of the pattern
    values: np.ndarray  # (B, m, m) blocks
    # closest-point groups: each block's reduced DOFs and their signs; None: the family's slots
    compact: tuple[np.ndarray, np.ndarray] | None


@dataclass(eq=False)
class Assembled:
    """What a compiled evaluation keeps of its u.

    The reduced tangent and, per contact group, the pressures and kinematics (reused by
    :meth:`BeamModel.contact_summary <sandwich.beam.model.BeamModel.contact_summary>`); the
    contact terms added into the tangent and the pattern they were added on, for
    :meth:`BeamModel.internal_force_nearby <sandwich.beam.model.BeamModel.internal_force_nearby>`
    (``pattern`` None once spent).
    """

    K: sp.csr_matrix
    contact: list = field(default_factory=list)
    pattern: ReducedPattern | None = None
    terms: list[ContactTerm] = field(default_factory=list)


class CompiledAssembly:
    """The compiled path of a :class:`~sandwich.beam.model.BeamModel`, with its own pattern.

    Attributes
    ----------
    pattern : ReducedPattern
        The layers' blocks and, of each closest-point pair, the segments met so far.
    growths : int
        How many times :meth:`grow` widened the pattern.
    spare_values : list of ndarray
        Tangent value arrays kept for reuse (:meth:`zeroed_values`).
    """

    def __init__(self, model: object) -> None:
        self.model = model
        layers = model.block_dofs[:len(model.block_dofs) - len(model.pairs)]
        self.seed_families = layers + [_seed_dofs(p) for p in model.pairs]
        self.contact_met: list[np.ndarray] = []
        self.growths = 0
        self.pattern = reduced_pattern(self.seed_families, model.dof_map)
        self.spare_values: list[np.ndarray] = []
        self._compact_slots: tuple | None = None  # (pattern, {group: (free, slots)})

    def grow(self, dofs: np.ndarray) -> None:
        """Add contact blocks on full DOFs ``dofs`` (B, 10) to the pattern.

        Called when a closest-point projection lands on a segment the pattern lacks; the
        segments met are kept (the pattern only grows), the slot maps of the old pattern are
        dropped (and with it the model's factorisation structures, kept per pattern).
        """
        met = np.unique(np.sort(dofs, axis=1), axis=0)
        if self.contact_met:
            met = np.unique(np.concatenate([self.contact_met[0], met]), axis=0)
        self.contact_met = [met]
        self.pattern = reduced_pattern(self.seed_families + self.contact_met,
                                       self.model.dof_map)
        self.growths += 1

    def evaluate(
        self, u_full: np.ndarray, kernels: object, nearby: Assembled | None = None
    ) -> tuple[np.ndarray, Assembled]:
        """Force on the free DOFs and reduced tangent in one pass (layers by the kernels).

        Contact compact; each family's force is added into the free DOFs by
        :func:`sandwich.beam.kernels.add_reduced`. A closest-point pair whose chosen segment
        the pattern lacks grows it (:meth:`grow`) and the pass is made again on the grown
        pattern (in full). With ``nearby`` (the last evaluation) the layers give their force
        only and the tangent is ``nearby``'s values with its contact terms replaced by this
        u's; ``nearby`` is spent (its matrix is this one).
        """
        model = self.model
        pattern = self.pattern  # block families: element_families(), then the contact pairs
        lengths = model.mesh.lengths
        forces = []
        terms = []
        force_dofs = list(model.block_dofs)  # a closest-point group's force: on its 10 DOFs
        families = model.element_families()
        if nearby is not None:
            data = nearby.K.data  # taken over: the last contact terms out, the new ones in
            for term in nearby.terms:
                if term.compact is not None:
                    self._scatter_compact(kernels, term.group, *term.compact, -term.values,
                                          pattern, data)
                else:
                    kernels.scatter_blocks(-term.values, *pattern.slots_of(term.group), data)
            nearby.pattern = None
            for op, _, els, dofs in families:
                if kernels.supports(op):
                    forces.append(kernels.layer_blocks(op, u_full[dofs], lengths[els],
                                                       model.width, False)[0])
                    continue
                u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
                u_e[:, op.dofs] = u_full[dofs]
                forces.append(layer_state(op, u_e, lengths[els], model.width).f)
            kept, families = len(families), []  # the layers' tangent: nearby's
        else:
            kept = 0
            data = self.zeroed_values(pattern.indices.size)
        for i, (op, products, els, dofs) in enumerate(families):
            if kernels.supports(op):
                forces.append(kernels.layer_assemble(op, u_full[dofs], lengths[els], model.width,
                                                     *pattern.slots_of(i), data))
                continue
            u_e = np.zeros((els.size, int(op.dofs.max()) + 1))  # membrane_average: NumPy path
            u_e[:, op.dofs] = u_full[dofs]
            st = layer_state(op, u_e, lengths[els], model.width)
            forces.append(st.f)
            kernels.scatter_blocks(layer_tangent(op, st, products), *pattern.slots_of(i), data)
        contact = []
        for j, pairs in enumerate(model.pairs, start=len(families) + kept):
            if pairs.search == "closest-point":  # on each pair's chosen segment only
                f10, K10, p, k, dofs10 = compact_response(pairs, u_full, model.penalty,
                                                          model.smoothing)
                forces.append(f10)
                force_dofs[j] = dofs10
                contact.append((p, k))
                # an open pair's block is exactly zero (the law is nil for g ≥ 0): it needs no
                # slots, so the pattern grows only by the segments of pairs in contact
                free = np.where(k.gap[:, None] >= 0.0, -1, model.dof_map.free[dofs10])
                free = np.ascontiguousarray(free, dtype=np.int64)
                sign = np.where(free >= 0, model.dof_map.sign[dofs10], 0).astype(np.int8)
                K10 = np.ascontiguousarray(K10)
                if self._scatter_compact(kernels, j, free, sign, K10, pattern, data):
                    self.grow(_segments_around(pairs, dofs10))
                    return self.evaluate(u_full, kernels)
                terms.append(ContactTerm(j, K10, (free, sign)))
                continue
            f, K, p, k = penalty_response(pairs, u_full, model.penalty, model.smoothing)
            forces.append(f)
            contact.append((p, k))
            K = np.ascontiguousarray(K)
            kernels.scatter_blocks(K, *pattern.slots_of(j), data)
            terms.append(ContactTerm(j, K, None))
        n = self.pattern.n
        K = sp.csr_matrix((data, self.pattern.indices, self.pattern.indptr), shape=(n, n))
        assembled = Assembled(K, contact, pattern, terms)
        return self.reduced_force(kernels, force_dofs, forces), assembled

    def _scatter_compact(self, kernels: object, group: int, free: np.ndarray, sign: np.ndarray,
                         K: np.ndarray, pattern: ReducedPattern, data: np.ndarray) -> int:
        """Closest-point group ``group``'s blocks into ``data``, its slots remembered.

        :func:`sandwich.beam.kernels.scatter_compact_known` with this group's remembered DOFs
        and slots on ``pattern`` (dropped when the pattern grows). Returns the misses.
        """
        known = self._compact_slots
        if known is None or known[0] is not pattern:
            known = self._compact_slots = (pattern, {})
        if group not in known[1] or known[1][group][0].shape != free.shape:
            B, m = free.shape
            known[1][group] = (np.full((B, m), -9, dtype=np.int64),
                               np.empty((B, m, m), dtype=np.int64))
        known_free, known_slots = known[1][group]
        return kernels.scatter_compact_known(free, sign, K, pattern.indptr, pattern.indices,
                                             data, known_free, known_slots)

    def zeroed_values(self, size: int) -> np.ndarray:
        """A zeroed array for a tangent's CSR values: a spare no one else holds, or a new one.

        :func:`sandwich.solver.spares.free_array` (fresh large arrays cost page faults); the
        model's cached tangent keeps the last one.
        """
        values = free_array(self.spare_values, size, SPARE_VALUES)
        values.fill(0.0)
        return values

    def reduced_force(self, kernels: object, rows: list[np.ndarray],
                      forces: list[np.ndarray]) -> np.ndarray:
        """Σ of the local ``forces`` on full DOFs ``rows``, on the free DOFs (Tᵀ f).

        Family by family in one order, so that every compiled evaluation of a force sums its
        terms alike (the model's force alone equals its force with the tangent bit for bit).
        """
        dm = self.model.dof_map
        f = np.zeros(dm.n_free)
        for dofs, fe in zip(rows, forces, strict=True):
            kernels.add_reduced(dofs, np.ascontiguousarray(fe, dtype=float), dm.free, dm.sign, f)
        return f


def _segments_around(pairs: ContactPairs, dofs10: np.ndarray) -> np.ndarray:
    """Full DOFs (3m, 10) of each closest-point pair's chosen segment and its two neighbours.

    ``dofs10`` are the chosen segments' 10 full DOFs (:func:`compact_response`): the face
    node's two, then the core boundary DOFs of the segment's nodes a and a + 1. A projection
    slides from segment to segment, so the pattern grows by the neighbours too: the next
    slide finds its couplings in place instead of rebuilding the pattern, slot maps and
    factorisation structure (fig. 5 with auto levels: 22 rebuilds). At a mesh end the
    neighbour is the segment itself (duplicate rows are dropped by
    :meth:`CompiledAssembly.grow`).
    """
    names = CONTACT_DOFS[pairs.interface]
    a = (dofs10[:, 2] - dof(names["u_core"])) // NODE_DOFS  # the segment's first node
    last = pairs.x.size - 2
    out = []
    for shift in (-1, 0, 1):
        n0 = np.clip(a + shift, 0, last)
        core = [global_dof(n, names[r]) for n in (n0, n0 + 1) for r in CORE_NODE_ROLES]
        out.append(np.column_stack([dofs10[:, :2], *core]))
    return np.concatenate(out)


def _seed_dofs(pairs: ContactPairs) -> np.ndarray:
    """A contact group's DOFs in the compiled path's first pattern.

    Same-x: the pair's six DOFs. Closest-point: the face node's (u, w) and the core nodes
    i − 1, i, i + 1 (the segments on either side of the node, where an unslid projection
    lies).
    """
    if pairs.search != "closest-point":
        return pairs.block_dofs
    k = pairs.core_nodes.shape[1] // 2  # the node's own slot
    cols = np.r_[0, 1, np.arange(2 + 4 * (k - 1), 2 + 4 * (k + 2))]
    return pairs.support_dofs[:, cols]
