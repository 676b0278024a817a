"""The discretised sandwich beam, the ``DiscreteSystem`` (``sandwich.solver.system``) to solve.

:func:`build_model` turns a scene into nodes (:mod:`~sandwich.beam.mesh`), layer rules
(:mod:`~sandwich.beam.layer_operators`), the elimination of ties and supports
(:mod:`~sandwich.beam.constraints`), loads and probes (:mod:`~sandwich.beam.loads`) and contact
pairs
on debonded stretches (:mod:`~sandwich.beam.contact`). :class:`BeamModel` evaluates the internal
force and tangent on the free DOFs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from sandwich.beam.assembly import ReducedPattern, reduced_pattern, scatter_vector
from sandwich.beam.constitutive import core_stiffness, face_stiffness
from sandwich.beam.constraints import DofMap, NodeSupport, build_dof_map
from sandwich.beam.contact import compact_response, contact_state, gap_change, penalty_response
from sandwich.beam.contact_law import SHIFT, in_contact
from sandwich.beam.contact_projection import forget_kinematics
from sandwich.beam.contact_search import DEFAULT_REACH, ContactPairs, contact_pair_groups
from sandwich.beam.core_basis import CoreBasis, mode_dofs
from sandwich.beam.dofs import ELEMENT_DOFS, NODE_DOFS
from sandwich.beam.element import (
    GeometricProducts,
    LayerState,
    geometric_products,
    layer_state,
    layer_tangent,
)
from sandwich.beam.fracture import beam_tips, release_columns
from sandwich.beam.layer_operators import (
    LayerOperators,
    build_core_operators,
    build_face_operators,
    build_layer_operators,
)
from sandwich.beam.loads import (
    patch_load,
    point_load,
    probe_row,
    stretch_patch_load,
    stretch_point_load,
    stretch_row,
)
from sandwich.beam.mesh import DEFAULT_GROWTH, DEFAULT_SIZE_RATIO, BeamMesh, build_mesh
from sandwich.beam.quadrature import EXACT_ORDER
from sandwich.scene import FACE_MEMBRANES, GRADINGS, BeamModelOptions
from sandwich.solver.spares import free_array

CHUNK = 1024  # elements per vectorised block (bounds memory at large element counts)
PENALTY_FACTOR = 1e4  # default contact penalty ε = PENALTY_FACTOR · Q_z / h_c  (N/mm³)
PENETRATION_BOUND = 1e-3  # allowed penetration / face thickness
SPARE_VALUES = 3  # tangent value arrays kept for reuse (BeamModel._zeroed_values)
SMOOTHING_FRACTION = 0.002  # default contact regularisation width s = SMOOTHING_FRACTION × bound


@dataclass
class ContactSummary:
    """Contact state of a converged step, per interface, over all pairs."""

    max_penetration: float = 0.0  # mm
    max_pressure: float = 0.0  # MPa
    max_sliding: float = 0.0  # mm, of pairs in contact: |t·Δ| (same-x), |x(ξ) − x_i| (closest)
    active: int = 0  # pairs in contact
    outside_reach: int = 0  # pairs in contact projecting beyond the searched segments


#: The history's contact columns (:func:`contact_columns`).
CONTACT_COLUMNS = ("max_penetration", "max_sliding", "contact_pairs_active")


def contact_columns(summary: dict[str, ContactSummary]) -> dict[str, float]:
    """History columns of a state's contact summary (0 without contact).

    Deepest penetration (mm), largest sliding of a pair in contact (mm) and the pairs in
    contact, over the interfaces.
    """
    return {
        "max_penetration": max((c.max_penetration for c in summary.values()), default=0.0),
        "max_sliding": max((c.max_sliding for c in summary.values()), default=0.0),
        "contact_pairs_active": float(sum(c.active for c in summary.values())),
    }


@dataclass(frozen=True)
class CoreGroup:
    """The core elements of one level: their rows, products and (extended) DOF indices."""

    level: int
    elements: np.ndarray  # (E_g,) element indices, increasing
    op: LayerOperators
    products: GeometricProducts
    dofs: np.ndarray  # (E_g, n) full DOF indices of op.dofs


def node_levels(element_levels: np.ndarray) -> np.ndarray:
    """Level of each node: the lowest of its elements' (so every element is conforming).

    An enrichment amplitude lives at a node only if every element there carries it; the
    element of the higher level then sees it vanish at that node.
    """
    e = np.asarray(element_levels, dtype=int)
    return np.minimum(np.concatenate([e[:1], e]), np.concatenate([e, e[-1:]]))


def core_groups(
    basis: CoreBasis,
    element_levels: np.ndarray,
    element_dofs: np.ndarray,
    n_nodes: int,
    make_op: object,
    stride: int | None = None,
    offset: int = 0,
) -> list[CoreGroup]:
    """Group core elements by level; extended DOFs = paper 40, then each node's enrichment.

    ``stride``: extra DOFs per node in the full vector (default: the core enrichment's);
    ``offset``: where the core enrichment starts in a node's block (after the face stretch).
    """
    m = 4 * basis.count(basis.max_level) if stride is None else stride
    groups = []
    for level in np.unique(element_levels):
        els = np.flatnonzero(element_levels == level)
        op = make_op(int(level))
        k = len(mode_dofs(basis, int(level)))
        ext = [element_dofs[els]]
        for node in (0, 1):
            ext.append(NODE_DOFS * n_nodes + m * (els + node)[:, None] + offset
                       + np.arange(k)[None, :])
        ext_dofs = np.concatenate(ext, axis=1)
        groups.append(CoreGroup(level=int(level), elements=els, op=op,
                                products=geometric_products(op), dofs=ext_dofs[:, op.dofs]))
    return groups


@dataclass
class BeamModel:
    """Equilibrium R(u, λ) = f_int(u) − λ f_ref on the free DOFs of the beam model."""

    name: str
    mesh: BeamMesh
    width: float
    layers: dict[str, LayerOperators]
    products: dict[str, GeometricProducts]
    dof_map: DofMap
    pairs: list[ContactPairs]
    penalty: float
    f_ref_full: np.ndarray
    probe_rows: dict[str, np.ndarray]
    face_thickness: dict[str, float]
    smoothing: float = 0.0  # contact regularisation width s (mm), see sandwich.beam.contact
    core: list[CoreGroup] = field(default_factory=list)  # core elements grouped by level
    element_levels: np.ndarray | None = None  # core level of every element
    # debond tips (sandwich.beam.fracture.BeamTip) whose G every accepted path state carries
    fracture_tips: list = field(default_factory=list)
    # full DOFs of each face's element family when the faces carry their stretch DOF
    face_dofs: dict | None = None
    pattern: ReducedPattern = field(init=False)
    committed: dict[str, ContactSummary] = field(default_factory=dict)
    max_penetration_seen: float = 0.0
    max_sliding_seen: float = 0.0
    # (u, f, K or None, layer states of u): the tangent at the last force's u reuses its states.
    _cache: tuple | None = None
    use_kernels = True  # class attribute, not a field: False forces the NumPy reference path

    def __post_init__(self) -> None:
        e = np.arange(self.mesh.n_elements)[:, None]
        self.element_dofs = NODE_DOFS * e + np.arange(ELEMENT_DOFS)[None, :]
        if not self.core:  # the paper's core everywhere
            op = self.layers["core"]
            self.core = [CoreGroup(1, np.arange(self.mesh.n_elements), op, self.products["core"],
                                   self.element_dofs[:, op.dofs])]
        if self.element_levels is None:
            self.element_levels = np.ones(self.mesh.n_elements, dtype=int)
        # Block families: top face, core groups by level, bottom face, contact groups.
        faces = self.face_dofs or {n: self.element_dofs[:, self.layers[n].dofs]
                                   for n in ("top", "bottom")}
        self.block_dofs = [faces["top"]]
        self.block_dofs += [g.dofs for g in self.core]
        self.block_dofs += [faces["bottom"]]
        self.block_dofs += [p.block_dofs for p in self.pairs]
        # The compiled path's pattern: the layers, and of each closest-point pair only the
        # segments next to its node (it grows by the segments its projections meet, see
        # _grow_pattern); the NumPy path assembles on every searched segment (full_pattern).
        self._pattern_families = self.block_dofs[:len(self.block_dofs) - len(self.pairs)]
        self._pattern_families += [_seed_dofs(p) for p in self.pairs]
        self._contact_met: list[np.ndarray] = []
        self.pattern_growths = 0  # how many times _grow_pattern widened the pattern
        self.pattern = reduced_pattern(self._pattern_families, self.dof_map)
        self.f_ref_free = self.dof_map.reduce(self.f_ref_full)

    @property
    def full_pattern(self) -> ReducedPattern:
        """The pattern of every block family on its whole DOF list (the NumPy path's).

        For closest-point pairs: all searched segments. Built on first use.
        """
        if "_full_pattern" not in self.__dict__:
            self.__dict__["_full_pattern"] = (
                self.pattern if not any(p.search == "closest-point" for p in self.pairs)
                else reduced_pattern(self.block_dofs, self.dof_map))
        return self.__dict__["_full_pattern"]

    def _grow_pattern(self, dofs: np.ndarray) -> None:
        """Add contact blocks on full DOFs ``dofs`` (B, 10) to the compiled path's pattern.

        Called when a closest-point projection lands on a segment the pattern lacks; the
        segments met are kept (the pattern only grows), the slot maps and the factorisation
        structures of the old pattern are dropped.
        """
        met = np.unique(np.sort(dofs, axis=1), axis=0)
        if self._contact_met:
            met = np.unique(np.concatenate([self._contact_met[0], met]), axis=0)
        self._contact_met = [met]
        self.pattern = reduced_pattern(self._pattern_families + self._contact_met,
                                       self.dof_map)
        self.__dict__.pop("_envelopes", None)
        self.pattern_growths += 1

    @property
    def face_extra(self) -> int:
        """Face stretch DOFs per node at the head of each node's extra block (0 or 2)."""
        return 0 if self.face_dofs is None else 2

    def face_family_dofs(self, face: str) -> np.ndarray:
        """Full DOF indices of ``face``'s element family, shape ``(E, n)`` in its rows' order."""
        return self.block_dofs[0 if face == "top" else len(self.core) + 1]

    # --- DiscreteSystem -------------------------------------------------------------------
    @property
    def size(self) -> int:
        """Number of free unknowns."""
        return self.dof_map.n_free

    @property
    def f_ref(self) -> np.ndarray:
        """Reference load on the free DOFs (N, N·mm)."""
        return self.f_ref_free

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """f_int(u) on the free DOFs, contact included (eq. 19 assembled, Tᵀ f)."""
        return self._evaluate(u, tangent=False)[0]

    def tangent(self, u: np.ndarray) -> sp.csr_matrix:
        """Consistent tangent Tᵀ K T at ``u`` (eqs. 24-25 plus contact)."""
        K = self._evaluate(u, tangent=True)[1]
        assert K is not None
        return K

    def residual_roundoff(self, u: np.ndarray) -> float:
        """Round-off level of the residual at ``u`` (N): ε ‖ |K(u)| |u| ‖.

        The state is stored to an ulp of each unknown and the stiffest terms (the faces' axial
        and the ties' through-thickness stiffness) turn that into residual that no Newton
        iterate can remove. It exceeds ``tol ‖λ f_ref‖`` for very soft cores (E_core/E_face
        = 1e-6) and very slender beams (L/h = 1000); the Newton corrector accepts a residual
        at this level once the increment has converged (:mod:`sandwich.solver.newton`).
        """
        K = self.tangent(u)
        kernels = _kernels()
        if kernels is None:
            product = abs(K) @ np.abs(u)
        else:  # the same sums without copying K
            product = kernels.abs_matvec(K.indptr, K.indices, K.data, np.asarray(u, dtype=float))
        return float(np.finfo(float).eps * np.linalg.norm(product))

    def factorize(self, K: sp.spmatrix) -> object:
        """Envelope LDLᵀ of the tangent with its inertia (:mod:`sandwich.solver.envelope`).

        The symbolic part (ordering, envelope of the values) is computed once per sparsity
        pattern and kept, widened when a tangent has a coupling outside it;
        SuperLU (:class:`sandwich.solver.sparse.SparseFactorization`) is the fallback when the
        pivot-free LDLᵀ is untrustworthy, or when numba is not installed.
        """
        try:
            from sandwich.solver.envelope import EnvelopeStructure, factorize_envelope
        except ImportError:  # no numba (or an older shared backend)
            try:
                from sandwich.solver.sparse import SparseFactorization
            except ImportError:
                return _SpluFactorization(K)
            return SparseFactorization(K)
        K = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
        known = self.__dict__.setdefault("_envelopes", [])  # the model's pattern first
        structure = next((s for s in known if s.matches(K)), None)
        if structure is None:
            embedded = self._on_pattern(K)  # e.g. K0 + linear contact: sums drop zeros
            if embedded is not None:
                K = embedded
                structure = next((s for s in known if s.matches(K)), None)
        if structure is None:
            # the envelope of the values: the pattern's contact couplings to unchosen segments
            # and open pairs are zero; a matrix with a coupling outside it widens it
            structure = EnvelopeStructure.of(K, numeric=True)
            known.insert(1 if known else 0, structure)  # keep the model's own pattern's
            del known[4:]
        fac = factorize_envelope(K, structure)
        widened = getattr(fac, "structure", structure)
        if (widened is not structure and widened.matches(K)
                and widened is not structure.kept_natural):  # not the natural-order retry's
            known[known.index(structure)] = widened
        return fac

    def _on_pattern(self, K: sp.csr_matrix) -> sp.csr_matrix | None:
        """``K`` with the model's reduced sparsity pattern, if its non-zeros lie inside it."""
        p = self.pattern
        kernels = _kernels()
        if K.shape != (p.n, p.n) or kernels is None:
            return None
        if not K.has_canonical_format:
            K = K.copy()
            K.sum_duplicates()
        data = np.zeros(p.indices.size)
        if not kernels.embed_pattern(p.indptr, p.indices, K.indptr, K.indices,
                                     np.asarray(K.data, dtype=float), data):
            return None
        return sp.csr_matrix((data, p.indices, p.indptr), shape=K.shape)

    def probe_vector(self, name: str) -> np.ndarray:
        """C on the free DOFs with probe value c · u (mm)."""
        if name not in self.probe_rows:
            raise ValueError(f"unknown probe {name!r}; known: {sorted(self.probe_rows)}")
        return self.dof_map.reduce(self.probe_rows[name])

    def state_columns(self, u: np.ndarray) -> dict[str, float | None]:
        """History columns of a converged state: contact and G at the debond tips.

        Contact: :func:`contact_columns`; G, G_I, G_II at every debond tip (N/mm). Called by the
        path follower on every accepted state (after :meth:`commit`, whose contact summary at
        the same ``u`` it takes), so that a run interrupted mid-path still writes them
        (:mod:`sandwich.beam.fracture`) and the solution's history does not evaluate them again.
        """
        at = self.__dict__.get("_committed_u")
        summary = (self.committed if at is not None and np.array_equal(at, u)
                   else self.contact_summary(u))
        return {**contact_columns(summary), **release_columns(self, u, self.fracture_tips)}

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        """Record the contact state of a converged step."""
        self.committed = self.contact_summary(u)
        self.__dict__["_committed_u"] = np.array(u, dtype=float, copy=True)
        for s in self.committed.values():
            self.max_penetration_seen = max(self.max_penetration_seen, s.max_penetration)
            self.max_sliding_seen = max(self.max_sliding_seen, s.max_sliding)

    # --- evaluation -----------------------------------------------------------------------
    def correction_limit(self, u: np.ndarray, du: np.ndarray) -> float:
        """Largest fraction α ≤ 1 of the correction ``du`` from ``u`` this model trusts.

        A contact pair that is open at ``u`` or in the law's tail (g > −c s, :func:`pressure_law
        <sandwich.beam.contact.pressure_law>`: its stiffness below ε/2) has no contact stiffness
        in the tangent the correction was solved with; α keeps every such pair's linearised gap
        g + α ∂g/∂u·du at or above −``penetration_bound()``. Pairs already in the penalty's
        linear range are left to Newton, exact there. Used by the corrector when the path
        follower asks for it (:mod:`sandwich.solver.newton`, contact-limited corrections).
        """
        bound = self.penetration_bound()
        tail = -SHIFT * self.smoothing
        u_full, du_full = self.expand(u), self.expand(du)
        alpha = 1.0
        for pairs in self.pairs:
            if pairs.size == 0:
                continue
            g, dg = gap_change(pairs, u_full, du_full)
            deep = (g > tail) & (g + dg < -bound)
            if np.any(deep):
                alpha = min(alpha, float(np.min((g[deep] + bound) / -dg[deep])))
        return alpha

    def forget_evaluations(self) -> None:
        """Drop what the last evaluation left for the next one at the same ``u``.

        The model's cached force and tangent, and each contact interface's closest-point
        kinematics (:func:`sandwich.beam.contact.forget_kinematics`): the next call evaluates
        in full, as a Newton iteration at a new iterate does. For benchmarks that time one
        evaluation repeatedly at one state.
        """
        self._cache = None
        for pairs in self.pairs:
            forget_kinematics(pairs)

    def expand(self, u: np.ndarray) -> np.ndarray:
        """Full DOF vector (20 per node, then the core enrichment) of free DOFs ``u``."""
        u = np.asarray(u, dtype=float)
        if u.shape != (self.size,):
            raise ValueError(f"expected a vector of {self.size} free DOFs, got shape {u.shape}")
        return self.dof_map.expand(u)

    def internal_force_only(self, u: np.ndarray) -> np.ndarray:
        """f_int(u) without the tangent, for a line search's trial.

        :meth:`internal_force` bit for bit, at the cost of the force kernels alone (≈ 1/5 of
        force + tangent). Leaves the evaluation cache as it was: a :meth:`tangent` at this u
        evaluates in full.
        """
        if self._cache is not None and np.array_equal(self._cache[0], u):
            return self._cache[1]
        kernels = _kernels() if self.use_kernels else None
        if kernels is None:
            return self.dof_map.reduce(self.full_response(self.expand(u), tangent=False)[0])
        rows, forces, _ = self._local_responses(kernels, self.expand(u), False, True, None)
        return self._reduced_force(kernels, rows, forces)

    def internal_force_nearby(self, u: np.ndarray) -> np.ndarray:
        """f_int(u) for an iterate within a converged increment of the last evaluated one.

        The force is exactly :meth:`internal_force`'s (the layers' force-only kernels give it
        bit for bit). The tangent :meth:`tangent` then returns at ``u`` keeps the layers' part
        of the last evaluation and re-evaluates the contact law: the last matrix's contact
        terms are taken out of its values in place and this u's put in (no copy of the
        matrix). A step the corrector's increment test has passed moves the state by ≲ 1e-4
        of its increment, by ≈ 1e-7 where the contact pairs settle in the law's knee
        (:mod:`sandwich.solver.newton`): the layers' tangent does not change measurably over
        it, the contact law's stiffness changes by factors of e. Where the last evaluation
        kept no contact terms (the NumPy path, a grown pattern) this is a full evaluation.
        """
        cache = self._cache
        kernels = _kernels() if self.use_kernels else None
        last = cache[3] if cache is not None else None
        if (kernels is None or not isinstance(last, _Assembled) or last.terms is None
                or last.terms[0] is not self.pattern or np.array_equal(cache[0], u)):
            return self._evaluate(u, tangent=False)[0]
        f, assembled = self._compiled_forces(self.expand(u), kernels, nearby=last)
        self._cache = (np.array(u, dtype=float, copy=True), f, assembled.K, assembled)
        return f

    def _evaluate(self, u: np.ndarray, tangent: bool) -> tuple[np.ndarray, sp.csr_matrix | None]:
        cache = self._cache
        if cache is not None and np.array_equal(cache[0], u):
            if not tangent or cache[2] is not None:
                return cache[1], cache[2]
            # The force at this u is known: the tangent reuses its strains and stresses.
            K = self.full_pattern.assemble(self._tangent_blocks(self.expand(u), cache[3]))
            self._cache = (cache[0], cache[1], K, cache[3])
            return cache[1], K
        u_full = self.expand(u)
        kernels = _kernels() if self.use_kernels else None
        if kernels is not None:  # the tangent comes with the force
            f, states = self._compiled_forces(u_full, kernels)
            K = states.K
        else:
            f_full, states = self._forces(u_full)
            f = self.dof_map.reduce(f_full)
            K = (self.full_pattern.assemble(self._tangent_blocks(u_full, states)) if tangent
                 else None)
        self._cache = (np.array(u, dtype=float, copy=True), f, K, states)
        return f, K

    def _families(self) -> list[tuple[LayerOperators, GeometricProducts, np.ndarray, np.ndarray]]:
        """(rows, products, elements, DOFs) of each element block family, in block order."""
        every = np.arange(self.mesh.n_elements)
        out = [(self.layers["top"], self.products["top"], every, self.block_dofs[0])]
        out += [(g.op, g.products, g.elements, g.dofs) for g in self.core]
        out += [(self.layers["bottom"], self.products["bottom"], every,
                 self.block_dofs[len(self.core) + 1])]
        return out

    def _forces(self, u_full: np.ndarray) -> tuple[np.ndarray, list[list[LayerState]]]:
        """Internal force on the full DOFs and the layer states (per family, chunk): NumPy.

        The reference path (:mod:`sandwich.beam.element`). With the compiled kernels the model
        takes :meth:`_compiled_forces` instead, which assembles the reduced tangent in the same
        pass: a Newton iteration asks for the tangent at every u whose residual it evaluates
        (fig. 5: 139 forces, 140 tangents).
        """
        forces, states = [], []
        lengths = self.mesh.lengths
        for op, _, els, dofs in self._families():
            # layer_state reads u_e[:, op.dofs]: hand it the family's DOFs in op.dofs' slots.
            u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
            u_e[:, op.dofs] = u_full[dofs]
            family = [layer_state(op, u_e[s:s + CHUNK], lengths[els[s:s + CHUNK]], self.width)
                      for s in range(0, els.size, CHUNK)]
            states.append(family)
            forces.append(np.concatenate([st.f for st in family]))
        for pairs in self.pairs:
            forces.append(penalty_response(pairs, u_full, self.penalty, self.smoothing)[0])
        return scatter_vector(u_full.size, self.block_dofs, forces), states

    def _compiled_forces(
        self, u_full: np.ndarray, kernels: object, nearby: _Assembled | None = None
    ) -> tuple[np.ndarray, _Assembled]:
        """Force on the free DOFs and reduced tangent in one pass (layers by the kernels).

        Contact compact; each family's force is added into the free DOFs by
        :func:`sandwich.beam.kernels.add_reduced`. A closest-point pair whose chosen segment
        the pattern lacks grows it (:meth:`_grow_pattern`) and the pass is made again on the
        grown pattern (in full).
        With ``nearby`` (the last evaluation, :meth:`internal_force_nearby`) the layers give
        their force only and the tangent is ``nearby``'s values with its contact terms
        replaced by this u's; ``nearby`` is spent (its matrix is this one).
        """
        pattern = self.pattern  # block families: _families(), then the contact pairs
        lengths = self.mesh.lengths
        forces = []
        terms = []
        force_dofs = list(self.block_dofs)  # a closest-point group's force: on its 10 DOFs
        families = self._families()
        if nearby is not None:
            data = nearby.K.data  # taken over: the last contact terms out, the new ones in
            for kind, a, b, c in nearby.terms[1]:
                if kind == "compact":
                    self._scatter_compact(kernels, a, *b, -c, pattern, data)
                else:
                    kernels.scatter_blocks(-c, *pattern.slots_of(a), data)
            nearby.terms = None
            for op, _, els, dofs in families:
                if kernels.supports(op):
                    forces.append(kernels.layer_blocks(op, u_full[dofs], lengths[els],
                                                       self.width, False)[0])
                    continue
                u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
                u_e[:, op.dofs] = u_full[dofs]
                forces.append(layer_state(op, u_e, lengths[els], self.width).f)
            kept, families = len(families), []  # the layers' tangent: nearby's
        else:
            kept = 0
            data = self._zeroed_values(pattern.indices.size)
        for i, (op, products, els, dofs) in enumerate(families):
            if kernels.supports(op):
                forces.append(kernels.layer_assemble(op, u_full[dofs], lengths[els], self.width,
                                                     *pattern.slots_of(i), data))
                continue
            u_e = np.zeros((els.size, int(op.dofs.max()) + 1))  # membrane_average: NumPy path
            u_e[:, op.dofs] = u_full[dofs]
            st = layer_state(op, u_e, lengths[els], self.width)
            forces.append(st.f)
            kernels.scatter_blocks(layer_tangent(op, st, products), *pattern.slots_of(i), data)
        contact = []
        for j, pairs in enumerate(self.pairs, start=len(families) + kept):
            if pairs.search == "closest-point":  # on each pair's chosen segment only
                f10, K10, p, k, cols = compact_response(pairs, u_full, self.penalty,
                                                        self.smoothing)
                dofs10 = np.take_along_axis(pairs.support_dofs, cols, axis=1)
                forces.append(f10)
                force_dofs[j] = dofs10
                contact.append((p, k))
                free = np.ascontiguousarray(self.dof_map.free[dofs10], dtype=np.int64)
                sign = np.where(free >= 0, self.dof_map.sign[dofs10], 0).astype(np.int8)
                K10 = np.ascontiguousarray(K10)
                if self._scatter_compact(kernels, j, free, sign, K10, pattern, data):
                    self._grow_pattern(_segments_around(pairs, cols))
                    return self._compiled_forces(u_full, kernels)
                terms.append(("compact", j, (free, sign), K10))
                continue
            f, K, p, k = penalty_response(pairs, u_full, self.penalty, self.smoothing)
            forces.append(f)
            contact.append((p, k))
            K = np.ascontiguousarray(K)
            kernels.scatter_blocks(K, *pattern.slots_of(j), data)
            terms.append(("blocks", j, None, K))
        n = self.pattern.n
        K = sp.csr_matrix((data, self.pattern.indices, self.pattern.indptr), shape=(n, n))
        assembled = _Assembled(K, contact, (pattern, terms))
        return self._reduced_force(kernels, force_dofs, forces), assembled

    def _scatter_compact(self, kernels: object, group: int, free: np.ndarray, sign: np.ndarray,
                         K: np.ndarray, pattern: ReducedPattern, data: np.ndarray) -> int:
        """Closest-point group ``group``'s blocks into ``data``, its slots remembered.

        :func:`sandwich.beam.kernels.scatter_compact_known` with this group's remembered DOFs
        and slots on ``pattern`` (dropped when the pattern grows). Returns the misses.
        """
        known = self.__dict__.get("_compact_slots")
        if known is None or known[0] is not pattern:
            known = self.__dict__["_compact_slots"] = (pattern, {})
        if group not in known[1] or known[1][group][0].shape != free.shape:
            B, m = free.shape
            known[1][group] = (np.full((B, m), -9, dtype=np.int64),
                               np.empty((B, m, m), dtype=np.int64))
        known_free, known_slots = known[1][group]
        return kernels.scatter_compact_known(free, sign, K, pattern.indptr, pattern.indices,
                                             data, known_free, known_slots)

    def _zeroed_values(self, size: int) -> np.ndarray:
        """A zeroed array for a tangent's CSR values: a spare no one else holds, or a new one.

        :func:`sandwich.solver.spares.free_array` (fresh large arrays cost page faults); the
        model's cached tangent keeps the last one.
        """
        values = free_array(self.__dict__.setdefault("_spare_values", []), size, SPARE_VALUES)
        values.fill(0.0)
        return values

    def _tangent_blocks(
        self, u_full: np.ndarray, states: list[list[LayerState]]
    ) -> list[np.ndarray]:
        """Local tangent blocks (layers, then contact) at the layer states of ``u_full``."""
        blocks = [np.concatenate([layer_tangent(op, st, products) for st in family])
                  for (op, products, _, _), family in zip(self._families(), states, strict=True)]
        for pairs in self.pairs:
            blocks.append(penalty_response(pairs, u_full, self.penalty, self.smoothing)[1])
        return blocks

    def full_response(
        self, u_full: np.ndarray, tangent: bool = True, contact_blocks: bool = True,
        elements: np.ndarray | None = None,
    ) -> tuple[np.ndarray, list[np.ndarray]]:
        """Internal force on the full DOFs and the local tangent blocks (layers, then contact).

        Layers by the compiled kernels (block output) when :attr:`use_kernels` and numba allow,
        else by the NumPy reference path (:mod:`sandwich.beam.element`). Without ``tangent``
        (or with ``contact_blocks`` False: the layer blocks only) no closest-point pair's
        (m, n, n) block is formed. ``elements`` (force only): the layers of these elements
        alone, every contact pair — the force is exact at the DOFs no other element reaches
        (a debond tip's closure, :func:`sandwich.beam.fracture.tip_releases`).
        """
        kernels = _kernels() if self.use_kernels else None
        if elements is not None:
            if tangent:
                raise ValueError("full_response: elements restricts the force only")
            if kernels is None:  # the NumPy path evaluates every element
                return self.full_response(u_full, tangent=False)
        if kernels is None:
            f_full, states = self._forces(u_full)
            return f_full, (self._tangent_blocks(u_full, states) if tangent else [])
        rows, forces, blocks = self._local_responses(kernels, u_full, tangent, contact_blocks,
                                                     elements)
        return scatter_vector(u_full.size, rows, forces), (blocks if tangent else [])

    def _local_responses(
        self, kernels: object, u_full: np.ndarray, tangent: bool, contact_blocks: bool,
        elements: np.ndarray | None,
    ) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """:meth:`full_response`'s local forces with their full DOFs, and its blocks."""
        forces, blocks, rows = [], [], []
        lengths = self.mesh.lengths
        for op, products, els, dofs in self._families():
            if elements is not None:
                keep = np.isin(els, elements)
                if not keep.any():
                    continue
                els, dofs = els[keep], dofs[keep]
            rows.append(dofs)
            if kernels.supports(op):
                f, K = kernels.layer_blocks(op, u_full[dofs], lengths[els], self.width, tangent)
            else:
                u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
                u_e[:, op.dofs] = u_full[dofs]
                st = layer_state(op, u_e, lengths[els], self.width)
                f, K = st.f, (layer_tangent(op, st, products) if tangent else None)
            forces.append(f)
            blocks.append(K)
        for pairs in self.pairs:
            if pairs.search == "closest-point" and not (tangent and contact_blocks):
                f10, _, _, _, cols = compact_response(pairs, u_full, self.penalty,
                                                      self.smoothing)
                f = np.zeros(pairs.support_dofs.shape)
                np.put_along_axis(f, cols, f10, axis=1)
                forces.append(f)
                continue
            f, K, _, _ = penalty_response(pairs, u_full, self.penalty, self.smoothing)
            forces.append(f)
            if contact_blocks:
                blocks.append(K)
        rows += [pairs.block_dofs for pairs in self.pairs]
        return rows, forces, blocks

    def _reduced_force(self, kernels: object, rows: list[np.ndarray],
                       forces: list[np.ndarray]) -> np.ndarray:
        """Σ of the local ``forces`` on full DOFs ``rows``, on the free DOFs (Tᵀ f).

        Family by family in one order, so that every compiled evaluation of a force sums its
        terms alike (:meth:`internal_force_only` equals :meth:`internal_force` bit for bit).
        """
        f = np.zeros(self.size)
        dm = self.dof_map
        for dofs, fe in zip(rows, forces, strict=True):
            kernels.add_reduced(dofs, np.ascontiguousarray(fe, dtype=float), dm.free, dm.sign, f)
        return f

    def contact_summary(self, u: np.ndarray) -> dict[str, ContactSummary]:
        """Penetration, pressure and sliding per interface at free DOFs ``u``."""
        u_full = self.expand(u)
        out: dict[str, ContactSummary] = {}
        cache = self._cache  # the last evaluation's contact, if it was at this u
        known = (cache[3].contact if cache is not None and isinstance(cache[3], _Assembled)
                 and np.array_equal(cache[0], u) else None)
        for i, pairs in enumerate(self.pairs):  # an interface may hold several groups
            if known is not None:
                p, k = known[i]
            else:
                p, k = contact_state(pairs, u_full, self.penalty, self.smoothing)
            active = in_contact(k.gap, self.smoothing)
            c = out.setdefault(pairs.interface, ContactSummary())
            c.max_penetration = max(c.max_penetration, float(np.max(-k.gap, initial=0.0)))
            c.max_pressure = max(c.max_pressure, float(np.max(p, initial=0.0)))
            c.max_sliding = max(c.max_sliding,
                                float(np.max(np.abs(k.sliding[active]), initial=0.0)))
            c.active += int(active.sum())
            if k.outside is not None:
                c.outside_reach += int(np.sum(k.outside & active))
        return out

    def penetration_bound(self) -> float:
        """Allowed penetration (mm): PENETRATION_BOUND × the thinner face."""
        return PENETRATION_BOUND * min(self.face_thickness.values())


def _segments_around(pairs: ContactPairs, cols: np.ndarray) -> np.ndarray:
    """Full DOFs (3m, 10) of each closest-point pair's chosen segment and its two neighbours.

    ``cols`` are the chosen segment's 10 columns in ``support_dofs`` (:func:`compact_response`):
    the face node's two, then core nodes ``seg`` and ``seg + 1``. A projection slides from
    segment to segment, so the pattern grows by the neighbours too: the next slide finds its
    couplings in place instead of rebuilding the pattern, slot maps and factorisation
    structure (fig. 5 with auto levels: 22 rebuilds). A neighbour beyond the searched stretch
    is the segment itself (duplicate rows are dropped by :meth:`BeamModel._grow_pattern`).
    """
    segments = (pairs.support_dofs.shape[1] - 2) // 4 - 1
    seg = (cols[:, 2] - 2) // 4
    out = []
    for shift in (-1, 0, 1):
        step = 4 * (np.clip(seg + shift, 0, segments - 1) - seg)
        out.append(np.take_along_axis(pairs.support_dofs,
                                      np.where(cols >= 2, cols + step[:, None], cols), axis=1))
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


@dataclass(eq=False)
class _Assembled:
    """What the compiled path keeps of a force evaluation at its u.

    The reduced tangent and, per contact group, the pressures and kinematics (reused by
    :meth:`BeamModel.contact_summary`).
    """

    K: sp.csr_matrix
    contact: list = field(default_factory=list)
    # (pattern, contact terms added into K) for BeamModel.internal_force_nearby; None once spent
    terms: tuple | None = None


_KERNELS: list = []


def _kernels() -> object | None:
    """:mod:`sandwich.beam.kernels` (imported on first use), or None without numba."""
    if not _KERNELS:
        try:
            from sandwich.beam import kernels
        except ImportError:
            kernels = None
        _KERNELS.append(kernels)
    return _KERNELS[0]


class _SpluFactorization:
    """Fallback factorisation (SuperLU) used until ``sandwich.solver.sparse`` exists."""

    def __init__(self, K: sp.spmatrix):
        import scipy.sparse.linalg as spla

        self._lu = spla.splu(sp.csc_matrix(K))

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(b, dtype=float))

    @property
    def negative_pivots(self) -> int | None:
        return None


def mesh_stations(scene: object) -> list[float]:
    """X positions that must be nodes: debond ends, supports, loads (patch edges), probes."""
    pts: list[float] = []
    for d in scene.debonds:
        if d.end > d.start:  # a zero-length debond unties no node: not a station
            pts += [d.start, d.end]
    pts += [s.x for s in scene.supports]
    for load in scene.loads:
        pts += [load.x] if load.width == 0 else [*load.span, load.x]
    pts += [p.x for p in scene.probes]
    return pts


def refinement_centres(scene: object) -> list[float]:
    """Where the graded mesh puts its smallest elements: supports, debond tips, load edges."""
    pts: list[float] = [s.x for s in scene.supports]
    for d in scene.debonds:
        if d.end > d.start:
            pts += [d.start, d.end]
    for load in scene.loads:
        pts += [load.x] if load.width == 0 else list(load.span)
    return pts


def refinement_zones(scene: object) -> list[tuple[float, float]]:
    """Intervals the graded mesh fills with its smallest elements: the debonded stretches.

    A debonded face is free to buckle or wrinkle over its whole length; with the paper's face
    interpolation (u linear, w cubic) the buckled face locks in membrane unless its elements are
    short all along the debond, not only at the tips (measured on fig. 5: docs/beam_element.md,
    speed).
    """
    return [(d.start, d.end) for d in scene.debonds if d.end > d.start]


def default_contact_smoothing(scene: object) -> float:
    """The contact law's default regularisation width s (mm).

    ``SMOOTHING_FRACTION`` × the allowed penetration (``PENETRATION_BOUND`` × the thinner face).
    """
    return SMOOTHING_FRACTION * PENETRATION_BOUND * min(float(scene.top.thickness),
                                                        float(scene.bottom.thickness))


def build_model(
    scene: object,
    *,
    elements: int | None = None,
    gauss: dict[str, tuple[int, int]] | None = None,
    contact_penalty: float | None = None,
    contact_smoothing: float | None = None,
    grading: str = "graded",
    growth: float = DEFAULT_GROWTH,
    size_ratio: float = DEFAULT_SIZE_RATIO,
    face_membrane: str | None = None,
    contact_search: str | None = None,
    contact_reach: float = DEFAULT_REACH,
    core_level: int | np.ndarray | None = None,
    core_basis: str = "sublayers",
    face_stretch: bool | None = None,
) -> BeamModel:
    """Discretise ``scene`` (a :class:`sandwich.scene.Scene`) with the beam element.

    Parameters
    ----------
    scene
        The problem.
    elements
        Element count over the length (default ``scene.beam_model.elements``); kept exactly.
    gauss
        Gauss orders (n_η, n_ξ) per layer name; default
        :data:`~sandwich.beam.quadrature.EXACT_ORDER`
        (exact for the polynomial strain energy).
    contact_penalty
        Contact penalty ε (N/mm³); default ``scene.beam_model.contact_penalty`` or
        ``PENALTY_FACTOR · Q_z / h_c``.
    contact_smoothing
        Width s (mm) over which the penalty pressure is regularised
        (:func:`~sandwich.beam.contact.pressure_law`); default ``SMOOTHING_FRACTION`` × the
        penetration bound. 0 gives the plain (kinked) penalty.
    grading, growth, size_ratio
        Mesh along x (:func:`~sandwich.beam.mesh.build_mesh`): ``"graded"`` (default) puts the
        smallest elements at :func:`refinement_centres` and all along :func:`refinement_zones`
        and grows them by ``growth`` per element up to ``size_ratio`` × the smallest;
        ``"tips"`` grades towards the centres only (the default until 2026-11-22);
        ``"uniform"`` keeps one size.
    face_membrane
        ``"paper"``: the faces' ε_x of eq. (15) at every Gauss point. ``"averaged"`` (departs
        from the paper): the faces' ε_x is its element mean along x (assumed membrane strain;
        removes membrane locking, see docs/beam_vs_2d.md). Default: the scene's
        ``[beam_model] face_membrane`` (``"averaged"``).
    contact_search
        Pairing on debonded stretches (:func:`~sandwich.beam.contact.contact_pairs`):
        ``"same-x"`` (the paper's closest-node rule under small sliding): each untied face
        node against the core point of the same x; ``"closest-point"``: the node projected on
        the deformed core boundary curve (node-to-segment, consistent linearisation, continuous
        beyond the search reach, docs/contact_search.md). Default: the scene's
        ``[beam_model] contact_search`` (``"closest-point"``: with the faces' stretch and core
        levels ≥ 3 the same-x pairing stalls on fig. 5, docs/beam_vs_2d.md).
    contact_reach
        Closest-point search: the segments within this distance (mm) on each side of a node, at
        least one per side, are searched (default ``DEFAULT_REACH``).
    core_level
        Level of the core hierarchy (:mod:`sandwich.beam.core_basis`): one integer for every
        element, or one per element of the mesh :func:`beam_mesh` gives (see
        :mod:`sandwich.beam.core_levels`); default 1, the paper's core.
    core_basis
        Enrichment family of levels > 1: ``"sublayers"`` (default) or ``"polynomial"``.
    face_stretch
        ``False`` (the paper's faces): a face's w is constant through its thickness.
        ``True``: each face gets a stretch DOF per node
        (:func:`~sandwich.beam.layer_operators.build_face_operators`), so that a rotated face
        bends as stiffly as an unrotated one; stored first in each node's extra block.
        Default: the scene's ``[beam_model] faces`` (``"stretch"`` unless it says ``"paper"``).
    """
    options = getattr(scene, "beam_model", None)
    if face_membrane is None:
        face_membrane = getattr(options, "face_membrane", BeamModelOptions.face_membrane)
    if contact_search is None:
        contact_search = getattr(options, "contact_search", BeamModelOptions.contact_search)
    if face_membrane not in FACE_MEMBRANES:
        raise ValueError(f"face_membrane must be one of {FACE_MEMBRANES}, got {face_membrane!r}")
    if face_stretch is None:
        face_stretch = getattr(options, "faces", BeamModelOptions.faces) == "stretch"
    if elements is None:
        elements = getattr(options, "elements", BeamModelOptions.elements)
    mesh = beam_mesh(scene, elements, grading=grading, growth=growth, size_ratio=size_ratio)
    if not (np.isfinite(scene.width) and scene.width > 0):
        raise ValueError(f"beam width must be positive, got {scene.width!r}")
    orders = dict(EXACT_ORDER)
    orders.update(gauss or {})
    hc, ht, hb = scene.core.thickness, scene.top.thickness, scene.bottom.thickness
    z_bottom = {"top": hc / 2, "core": -hc / 2, "bottom": -hc / 2 - hb}
    stiffness = {"top": face_stiffness(scene.top.material),
                 "core": core_stiffness(scene.core.material),
                 "bottom": face_stiffness(scene.bottom.material)}
    thickness = {"top": ht, "core": hc, "bottom": hb}
    if face_stretch:  # the face's through-thickness modulus, uncoupled (σ_z = E ε_z)
        for n in ("top", "bottom"):
            stiffness[n] = stiffness[n].copy()
            stiffness[n][1, 1] = stiffness[n][0, 0]
    layers = {"core": build_layer_operators("core", hc, z_bottom["core"], stiffness["core"],
                                            gauss=orders["core"])}
    for n in ("top", "bottom"):
        layers[n] = build_face_operators(n, thickness[n], z_bottom[n], stiffness[n],
                                         gauss=orders[n],
                                         membrane_average=face_membrane == "averaged",
                                         stretch=face_stretch)
    products = {n: geometric_products(op) for n, op in layers.items()}
    levels = np.broadcast_to(np.asarray(1 if core_level is None else core_level, dtype=int),
                             (mesh.n_elements,)).copy()
    if np.any(levels < 1):
        raise ValueError(f"core levels must be >= 1, got {levels.min()}")
    basis = CoreBasis(core_basis, int(levels.max()))
    groups: list[CoreGroup] = []
    m = 4 * basis.count(basis.max_level)
    fs = 2 if face_stretch else 0  # face stretch DOFs per node (top, bottom), first in the block
    e = np.arange(mesh.n_elements)[:, None]
    if basis.max_level > 1:
        groups = core_groups(
            basis, levels, NODE_DOFS * e + np.arange(ELEMENT_DOFS)[None, :], mesh.n_nodes,
            lambda level: build_core_operators(hc, z_bottom["core"], stiffness["core"], basis,
                                               level, gauss=orders["core"]),
            stride=m + fs, offset=fs)
    mode_active = (np.arange(m)[None, :]
                   < 4 * np.array([basis.count(int(k)) for k in node_levels(levels)])[:, None])
    face_dofs = None
    if face_stretch:
        mode_active = np.concatenate([np.ones((mesh.n_nodes, 2), dtype=bool), mode_active], 1)
        paper = NODE_DOFS * e + np.arange(ELEMENT_DOFS)[None, :]
        face_dofs = {}
        for j, n in enumerate(("top", "bottom")):
            ext = NODE_DOFS * mesh.n_nodes + (m + fs) * (e + np.arange(2)[None, :]) + j
            face_dofs[n] = np.concatenate([paper, ext], axis=1)[:, layers[n].dofs]

    tol = 1e-9 * scene.length
    bonded = {i: np.array([scene.is_bonded(i, float(x), tol) for x in mesh.x])
              for i in ("top", "bottom")}
    supports = [NodeSupport(mesh.node_at(s.x, 1e-6 * scene.length), face, s.type)
                for s in scene.supports for face in s.faces]
    if face_stretch:  # a clamp holds the face's whole end section: no thickness change there
        for s in supports:
            if s.type == "clamp":
                mode_active[s.node, ("top", "bottom").index(s.face)] = False
    dof_map = build_dof_map(mesh.n_nodes, bonded, supports, mode_active)

    f_ref = np.zeros(NODE_DOFS * mesh.n_nodes)
    for load in scene.loads:
        if load.width == 0:
            f_ref += point_load(mesh, load.on, load.x, load.force)
        else:
            f_ref += patch_load(mesh, load.on, *load.span, load.force)
    extra = np.zeros(mode_active.shape)  # no load on the core enrichment
    if face_stretch:  # loads act on the faces' outer surfaces: they work on d too
        for load in scene.loads:
            j = ("top", "bottom").index(load.on)
            extra[:, j] += (stretch_point_load(mesh, load.x, load.force) if load.width == 0
                            else stretch_patch_load(mesh, *load.span, load.force))
    f_ref = np.concatenate([f_ref, extra.ravel()])
    probes = {}
    for p in scene.probes:  # w of the face's mid-surface (where the 2D model reads it)
        extra = np.zeros(mode_active.shape)
        if face_stretch:
            nodes, weights = stretch_row(mesh, p.x)
            extra[nodes, ("top", "bottom").index(p.on)] = 0.5 * weights
        probes[p.name] = np.concatenate([probe_row(mesh, p.on, p.x), extra.ravel()])

    pairs = [group for i in ("top", "bottom") if np.any(~bonded[i])
             for group in contact_pair_groups(i, np.flatnonzero(~bonded[i]), mesh.x, scene.width,
                                              search=contact_search, reach=contact_reach)]
    if contact_penalty is None:
        contact_penalty = getattr(options, "contact_penalty", None)
    if contact_penalty is None:
        contact_penalty = PENALTY_FACTOR * stiffness["core"][1, 1] / hc
    if contact_smoothing is None:
        contact_smoothing = default_contact_smoothing(scene)
    model = BeamModel(
        name=scene.name, mesh=mesh, width=float(scene.width), layers=layers, products=products,
        dof_map=dof_map, pairs=pairs, penalty=float(contact_penalty), f_ref_full=f_ref,
        probe_rows=probes, face_thickness={"top": ht, "bottom": hb},
        smoothing=float(contact_smoothing), core=groups, element_levels=levels,
        face_dofs=face_dofs,
    )
    model.fracture_tips = beam_tips(scene, model)
    return model


def beam_mesh(
    scene: object,
    elements: int,
    *,
    grading: str = "graded",
    growth: float = DEFAULT_GROWTH,
    size_ratio: float = DEFAULT_SIZE_RATIO,
) -> BeamMesh:
    """The nodes :func:`build_model` puts on ``scene`` for ``elements`` elements."""
    if grading not in GRADINGS:
        raise ValueError(f"grading must be one of {GRADINGS}, got {grading!r}")
    return build_mesh(scene.length, elements, mesh_stations(scene),
                      centres=refinement_centres(scene),
                      zones=refinement_zones(scene) if grading == "graded" else (),
                      grading="uniform" if grading == "uniform" else "graded", growth=growth,
                      size_ratio=size_ratio)
