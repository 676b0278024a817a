"""The discretised sandwich beam, the ``DiscreteSystem`` (``sandwich.solver.system``) to solve.

:class:`BeamModel` holds what :func:`~sandwich.beam.build.build_model` makes of a scene (mesh,
layer rules, core level groups, the elimination of ties and supports, loads, probes and contact
pairs) and evaluates the internal force and tangent on the free DOFs: by the compiled kernels
(:mod:`~sandwich.beam.compiled_assembly`, force and reduced tangent in one pass) where numba is,
else by the NumPy reference path (:mod:`~sandwich.beam.local_responses`). Its tangents are
factorised by :mod:`~sandwich.beam.factorisation`; its contact state is summarised by
:mod:`~sandwich.beam.contact_summary`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from sandwich.beam.assembly import ReducedPattern, compiled_kernels, reduced_pattern, scatter_vector
from sandwich.beam.cohesive import commit_damage, growth_columns
from sandwich.beam.compiled_assembly import Assembled, CompiledAssembly
from sandwich.beam.constraints import DofMap
from sandwich.beam.contact_projection import forget_kinematics
from sandwich.beam.contact_search import ContactPairs
from sandwich.beam.contact_summary import (
    ContactSummary,
    contact_columns,
    contact_correction_limit,
    summarise_contact,
)
from sandwich.beam.core_groups import CoreGroup
from sandwich.beam.dofs import ELEMENT_DOFS, NODE_DOFS
from sandwich.beam.element import GeometricProducts
from sandwich.beam.factorisation import TangentFactorisations
from sandwich.beam.fracture import release_columns
from sandwich.beam.layer_operators import LayerOperators
from sandwich.beam.local_responses import (
    compiled_local_responses,
    reference_forces,
    reference_rows,
    reference_tangent_blocks,
)
from sandwich.beam.mesh import BeamMesh
from sandwich.beam.unsymmetric import SKEW_RTOL, UnsymmetricFactorization, skew_split

PENETRATION_BOUND = 1e-3  # allowed penetration / face thickness


@dataclass(eq=False)
class Evaluation:
    """The model's last evaluation at ``u``, reused by the next call at (or near) it.

    The tangent at the last force's u reuses its layer states (NumPy path); the compiled path
    gives the tangent with the force and keeps its contact (:class:`Assembled`).
    """

    u: np.ndarray  # free DOFs
    force: np.ndarray  # f_int(u) on the free DOFs
    tangent: sp.csr_matrix | None  # None until asked (NumPy path)
    states: list | None = None  # NumPy path: the layer states of u, per family and chunk
    assembled: Assembled | None = None  # compiled path


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
    smoothing: float = 0.0  # contact regularisation width s (mm), see sandwich.beam.contact_law
    core: list[CoreGroup] = field(default_factory=list)  # core elements grouped by level
    element_levels: np.ndarray | None = None  # core level of every element
    # debond tips (sandwich.beam.fracture.BeamTip) whose G every accepted path state carries
    fracture_tips: list = field(default_factory=list)
    # full DOFs of each face's element family when the faces carry their stretch DOF
    face_dofs: dict | None = None
    committed: dict[str, ContactSummary] = field(default_factory=dict)
    max_penetration_seen: float = 0.0
    max_sliding_seen: float = 0.0
    # the state whose contact ``committed`` summarises, and the last evaluation: not copied by
    # dataclasses.replace (a model with other DOFs starts without them)
    committed_u: np.ndarray | None = field(default=None, init=False, repr=False)
    # (u, per contact group the cohesive damage or None) of every committed state (cohesive)
    damage_history: list = field(default_factory=list, init=False, repr=False)
    last_evaluation: Evaluation | None = field(default=None, init=False, repr=False)
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
        # segments next to its node (it grows by the segments its projections meet); the NumPy
        # path assembles on every searched segment (full_pattern).
        self.compiled = CompiledAssembly(self)
        self.factorisations = TangentFactorisations()
        self.f_ref_free = self.dof_map.reduce(self.f_ref_full)

    @property
    def pattern(self) -> ReducedPattern:
        """The compiled path's reduced pattern (it grows with the contact segments met)."""
        return self.compiled.pattern

    @property
    def pattern_growths(self) -> int:
        """How many times the compiled path's pattern grew."""
        return self.compiled.growths

    @cached_property
    def full_pattern(self) -> ReducedPattern:
        """The pattern of every block family on its whole DOF list (the NumPy path's, at rest).

        For closest-point pairs: all searched segments of the windows at rest. Built on first
        use.
        """
        return (self.pattern if not any(p.search == "closest-point" for p in self.pairs)
                else reduced_pattern(self.block_dofs, self.dof_map))

    def reference_pattern(self, u_full: np.ndarray) -> ReducedPattern:
        """The NumPy path's pattern at ``u_full``: the closest-point windows located there.

        :attr:`full_pattern` where every window is at rest; else built for the located
        windows (the last one kept).
        """
        rows = reference_rows(self, u_full)
        if all(r is b for r, b in zip(rows, self.block_dofs, strict=True)):
            return self.full_pattern
        kept = self.__dict__.get("_located_pattern")
        if kept is not None and all(np.array_equal(a, b) for a, b in zip(kept[0], rows,
                                                                          strict=True)):
            return kept[1]
        pattern = reduced_pattern(rows, self.dof_map)
        self.__dict__["_located_pattern"] = (rows, pattern)
        return pattern

    @property
    def face_extra(self) -> int:
        """Face stretch DOFs per node at the head of each node's extra block (0 or 2)."""
        return 0 if self.face_dofs is None else 2

    def face_family_dofs(self, face: str) -> np.ndarray:
        """Full DOF indices of ``face``'s element family, shape ``(E, n)`` in its rows' order."""
        return self.block_dofs[0 if face == "top" else len(self.core) + 1]

    def element_families(
        self,
    ) -> list[tuple[LayerOperators, GeometricProducts, np.ndarray, np.ndarray]]:
        """(rows, products, elements, DOFs) of each element block family, in block order."""
        every = np.arange(self.mesh.n_elements)
        out = [(self.layers["top"], self.products["top"], every, self.block_dofs[0])]
        out += [(g.op, g.products, g.elements, g.dofs) for g in self.core]
        out += [(self.layers["bottom"], self.products["bottom"], every,
                 self.block_dofs[len(self.core) + 1])]
        return out

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
        kernels = compiled_kernels()
        if kernels is None:
            product = abs(K) @ np.abs(u)
        else:  # the same sums without copying K
            product = kernels.abs_matvec(K.indptr, K.indices, K.data, np.asarray(u, dtype=float))
        return float(np.finfo(float).eps * np.linalg.norm(product))

    def factorize(self, K: sp.spmatrix) -> object:
        """Envelope LDLᵀ of the tangent with its inertia (:mod:`sandwich.beam.factorisation`).

        A tangent that is not symmetric (cohesive pairs damaging under a changing mode mix) is
        solved by its LU, with the inertia of its symmetric part
        (:mod:`sandwich.beam.unsymmetric`).
        """
        if any(p.cohesive is not None for p in self.pairs):
            K = K if sp.isspmatrix_csr(K) else sp.csr_matrix(K)
            sym = self._symmetric_part(K)
            if sym is not None:
                return UnsymmetricFactorization(K, self.factorisations.factorize(sym,
                                                                                 self.pattern))
        return self.factorisations.factorize(K, self.pattern)

    def _symmetric_part(self, K: sp.csr_matrix) -> sp.csr_matrix | None:
        """The symmetric part of ``K``, or None where it is symmetric.

        For the compiled path's last tangent, from the cohesive groups' blocks added into it
        (only they can be unsymmetric): their skew halves taken out of a copy of its values,
        without transposing the matrix. Any other matrix: :func:`skew_split`.
        """
        last = self.last_evaluation
        kept = last.assembled if last is not None else None
        kernels = compiled_kernels() if self.use_kernels else None
        pattern = self.pattern
        if (kept is None or kept.K is not K or kernels is None
                or K.indices.size != pattern.indices.size):
            return skew_split(K)
        first = len(self.block_dofs) - len(self.pairs)  # the contact groups' first family
        skews = []
        for term in kept.terms:
            if term.compact is None and self.pairs[term.group - first].cohesive is not None:
                skew = 0.5 * (term.values - np.swapaxes(term.values, 1, 2))
                if np.max(np.abs(skew), initial=0.0) > SKEW_RTOL * np.max(np.abs(term.values)):
                    skews.append((term.group, skew))
        if not skews:
            return None
        data = K.data.copy()
        for group, skew in skews:
            kernels.scatter_blocks(np.ascontiguousarray(-skew), *pattern.slots_of(group), data)
        return sp.csr_matrix((data, K.indices, K.indptr), shape=K.shape)

    def probe_vector(self, name: str) -> np.ndarray:
        """C on the free DOFs with probe value c · u (mm)."""
        if name not in self.probe_rows:
            raise ValueError(f"unknown probe {name!r}; known: {sorted(self.probe_rows)}")
        return self.dof_map.reduce(self.probe_rows[name])

    def state_columns(self, u: np.ndarray) -> dict[str, float | None]:
        """History columns of a converged state: contact and G at the debond tips.

        Contact: :func:`~sandwich.beam.contact_summary.contact_columns`; G, G_I, G_II at every
        debond tip (N/mm); each cohesive tip's position and process zone
        (:func:`~sandwich.beam.cohesive.growth_columns`, of the committed damage). Called by
        the path follower on every accepted state (after :meth:`commit`, whose contact summary
        and damage at the same ``u`` it takes), so that a run
        interrupted mid-path still writes them (:mod:`sandwich.beam.fracture`) and the
        solution's history does not evaluate them again.
        """
        at = self.committed_u
        summary = (self.committed if at is not None and np.array_equal(at, u)
                   else self.contact_summary(u))
        return {**contact_columns(summary), **release_columns(self, u, self.fracture_tips),
                **growth_columns(self)}

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        """Record the contact state of a converged step and commit the cohesive damage."""
        self.committed = self.contact_summary(u)
        self.committed_u = np.array(u, dtype=float, copy=True)
        if any(p.cohesive is not None for p in self.pairs):
            commit_damage(self.pairs, self.expand(u))
            self.damage_history.append((self.committed_u, [
                None if p.cohesive is None else p.cohesive.damage.copy() for p in self.pairs]))
        for s in self.committed.values():
            self.max_penetration_seen = max(self.max_penetration_seen, s.max_penetration)
            self.max_sliding_seen = max(self.max_sliding_seen, s.max_sliding)

    @property
    def path_dependent(self) -> bool:
        """Whether the model has history (cohesive damage): its state is not (u, λ) alone."""
        return any(p.cohesive is not None for p in self.pairs)

    def committed_damage(self, u: np.ndarray) -> list | None:
        """Per contact group the cohesive damage committed at the state ``u`` (None: not one)."""
        for at, damage in reversed(self.damage_history):
            if at.shape == np.shape(u) and np.array_equal(at, u):
                return damage
        return None

    def correction_limit(self, u: np.ndarray, du: np.ndarray) -> float:
        """Largest fraction α ≤ 1 of the correction ``du`` from ``u`` this model trusts.

        The contact pairs the correction's tangent holds no stiffness of may not penetrate
        deeper than :meth:`penetration_bound` on their linearised gaps
        (:func:`~sandwich.beam.contact_summary.contact_correction_limit`). Used by the
        corrector when the path follower asks for it (:mod:`sandwich.solver.newton`,
        contact-limited corrections).
        """
        bound = self.penetration_bound()
        return contact_correction_limit(self.pairs, self.expand(u), self.expand(du), bound,
                                        self.smoothing)

    # --- evaluation -----------------------------------------------------------------------
    def forget_evaluations(self, contact_kinematics: bool = True) -> None:
        """Drop what the last evaluation left for the next one at the same ``u``.

        The model's cached force and tangent and (``contact_kinematics``) each contact
        interface's closest-point kinematics
        (:func:`sandwich.beam.contact_projection.forget_kinematics`): the next call evaluates
        in full, as a Newton iteration at a new iterate does. For benchmarks that time one
        evaluation repeatedly at one state.
        """
        self.last_evaluation = None
        if contact_kinematics:
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
        last = self.last_evaluation
        if last is not None and np.array_equal(last.u, u):
            return last.force
        kernels = compiled_kernels() if self.use_kernels else None
        if kernels is None:
            return self.dof_map.reduce(self.full_response(self.expand(u), tangent=False)[0])
        rows, forces, _ = compiled_local_responses(self, kernels, self.expand(u), False, True,
                                                   None)
        return self.compiled.reduced_force(kernels, rows, forces)

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
        last = self.last_evaluation
        kernels = compiled_kernels() if self.use_kernels else None
        kept = last.assembled if last is not None else None
        if (kernels is None or kept is None or kept.pattern is not self.pattern
                or np.array_equal(last.u, u)):
            return self._evaluate(u, tangent=False)[0]
        f, assembled = self.compiled.evaluate(self.expand(u), kernels, nearby=kept)
        self.last_evaluation = Evaluation(np.array(u, dtype=float, copy=True), f, assembled.K,
                                          assembled=assembled)
        return f

    def _evaluate(self, u: np.ndarray, tangent: bool) -> tuple[np.ndarray, sp.csr_matrix | None]:
        last = self.last_evaluation
        if last is not None and np.array_equal(last.u, u):
            if not tangent or last.tangent is not None:
                return last.force, last.tangent
            # The force at this u is known: the tangent reuses its strains and stresses.
            u_full = self.expand(u)
            last.tangent = self.reference_pattern(u_full).assemble(
                reference_tangent_blocks(self, u_full, last.states))
            return last.force, last.tangent
        u_full = self.expand(u)
        u_kept = np.array(u, dtype=float, copy=True)
        kernels = compiled_kernels() if self.use_kernels else None
        if kernels is not None:  # the tangent comes with the force
            f, assembled = self.compiled.evaluate(u_full, kernels)
            self.last_evaluation = Evaluation(u_kept, f, assembled.K, assembled=assembled)
            return f, assembled.K
        f_full, states = reference_forces(self, u_full)
        f = self.dof_map.reduce(f_full)
        K = (self.reference_pattern(u_full).assemble(reference_tangent_blocks(self, u_full, states))
             if tangent else None)
        self.last_evaluation = Evaluation(u_kept, f, K, states=states)
        return f, K

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
        kernels = compiled_kernels() if self.use_kernels else None
        if elements is not None:
            if tangent:
                raise ValueError("full_response: elements restricts the force only")
            if kernels is None:  # the NumPy path evaluates every element
                return self.full_response(u_full, tangent=False)
        if kernels is None:
            f_full, states = reference_forces(self, u_full)
            return f_full, (reference_tangent_blocks(self, u_full, states) if tangent else [])
        rows, forces, blocks = compiled_local_responses(self, kernels, u_full, tangent,
                                                        contact_blocks, elements)
        return scatter_vector(u_full.size, rows, forces), (blocks if tangent else [])

    def contact_summary(self, u: np.ndarray) -> dict[str, ContactSummary]:
        """Penetration, pressure and sliding per interface at free DOFs ``u``."""
        u_full = self.expand(u)
        last = self.last_evaluation  # the last evaluation's contact, if it was at this u
        known = (last.assembled.contact if last is not None and last.assembled is not None
                 and np.array_equal(last.u, u) else None)
        return summarise_contact(self.pairs, u_full, self.penalty, self.smoothing, known)

    def penetration_bound(self) -> float:
        """Allowed penetration (mm): PENETRATION_BOUND × the thinner face."""
        return PENETRATION_BOUND * min(self.face_thickness.values())
