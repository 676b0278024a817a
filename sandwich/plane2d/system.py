"""The 2D reference as a :class:`sandwich.solver.DiscreteSystem`: PETSc assembly, MUMPS LDLᵀ.

Unknowns are all displacement DOFs of the vector Q2 space (x then z component per node, dolfinx
block order). Supports are homogeneous and imposed as trivial equations u_i = 0 (row and column
of the tangent replaced by the identity), so the constrained DOFs stay zero along any path and
the solver's vectors need no index juggling. Contact terms are evaluated in NumPy and added to the
PETSc matrix, whose sparsity pattern holds each slave's couplings with a window of master nodes
around it; a slave in contact that slides out of its window widens it, and the matrix is rebuilt
(and MUMPS analyses it afresh).

MPI: numpy vectors are the rank's owned DOFs. The two lips of a debond share no cell, so a
slave's master nodes are often on another rank: the displacements of all contact nodes
(a few hundred) are gathered to every rank, every rank evaluates all the contact, and each adds
only the rows it owns. The matrix is created here (not by dolfinx) from the form's sparsity
pattern plus the contact couplings in global numbering, so off-rank contact columns have slots.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from sandwich.plane2d import cohesive as cz
from sandwich.plane2d import contact as ct
from sandwich.plane2d.mesh import allreduce_array, block_input_coordinates, input_node_blocks
from sandwich.plane2d.mumps import MumpsFactorization, MumpsSolver
from sandwich.plane2d.roundoff import ResidualRoundoff

JIT = {"cffi_extra_compile_args": ["-O2"]}
#: a cohesive skew half below this × the blocks' size is round-off (the tangent is symmetric)
SKEW_FLOOR = 1e-12


class Reference2DSystem(ResidualRoundoff):
    """Equilibrium R(u, λ) = f_int(u) + f_contact(u) − λ f_ref of the 2D plane-stress model."""

    def __init__(self, V, internal, f_ref: np.ndarray, bc_dofs: np.ndarray,
                 contacts: list[ct.ContactPair], probes: dict[str, np.ndarray]):
        """Build the forms, the matrix with the contact pattern, and the reference load.

        ``internal(u, v)`` returns the UFL internal virtual work; ``f_ref`` the reference load
        on the local DOFs; ``probes`` maps names to coefficient vectors c (value c · u).
        """
        self.V = V
        self.comm = V.mesh.comm
        self.u = fem.Function(V)
        v = ufl.TestFunction(V)
        du = ufl.TrialFunction(V)
        R = internal(self.u, v)
        self.R_form = fem.form(R, jit_params=JIT)
        # det F at the nodes of a DG2 (Q2) field, for admissible(): one value per node per cell
        self._detF = fem.Function(fem.FunctionSpace(V.mesh, ("DG", 2)))
        self._detF_expr = fem.Expression(
            ufl.det(ufl.Identity(2) + ufl.grad(self.u)),
            self._detF.function_space.element.interpolation_points())
        self.J_form = fem.form(ufl.derivative(R, self.u, du), jit_params=JIT)
        self.bs = V.dofmap.index_map_bs
        im = V.dofmap.index_map
        self.n_owned = im.size_local * self.bs
        self.n_local = (im.size_local + im.num_ghosts) * self.bs
        self.bc_dofs = np.unique(np.asarray(bc_dofs, dtype=np.int32))
        self.contacts = contacts
        self._f_ref = np.asarray(f_ref, dtype=np.float64).copy()
        self._f_ref[self.bc_dofs[self.bc_dofs < self.n_owned]] = 0.0
        self.probes = probes
        self.x_ref = V.tabulate_dof_coordinates()[:, :2].copy()  # per block
        self._setup_contact_nodes()
        self.A = self._create_matrix()
        self.b = fem_petsc.create_vector(self.R_form)
        self.last_contact: list[ct.ContactState] = []  # of the committed state
        self._evaluated_contact: list[ct.ContactState] = []  # of the last internal_force
        self.counters = {"residuals": 0, "tangents": 0, "factorizations": 0,
                         "refactorizations": 0, "pattern_growths": 0, "unsymmetric_tangents": 0,
                         "krylov_unconverged": 0}
        self.A_full: PETSc.Mat | None = None  # the whole tangent, where not symmetric
        # (u, per growing tip its damage) of every committed state (a cohesive law's history)
        self.damage_history: list[tuple[np.ndarray, list[np.ndarray]]] = []
        self._mumps = MumpsSolver(self.comm)
        self._rhs, self._sol = self.A.createVecs()
        self._generation = 0
        self._tangent_u: np.ndarray | None = None

    # -- the DiscreteSystem protocol -------------------------------------------------------------
    @property
    def size(self) -> int:
        """Number of unknowns on this rank (constrained ones included, as u_i = 0)."""
        return self.n_owned

    @property
    def global_size(self) -> int:
        """Number of unknowns over all ranks."""
        return self.V.dofmap.index_map.size_global * self.bs

    @property
    def f_ref(self) -> np.ndarray:
        """Reference load (λ = 1)."""
        return self._f_ref[: self.n_owned]

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """f_int(u) + f_contact(u); rows of supports return u_i."""
        self._set_u(u)
        with self.b.localForm() as b_local:
            b_local.set(0.0)
            states = self._contact_states(want_tangent=False)
            self._evaluated_contact = [state for state, _pair in states]
            if states:
                f = np.zeros((self._nc, 2))
                for state, _pair in states:
                    f += state.nodal_forces(self._nc)
                for state in self._cohesive_states(want_tangent=False):
                    f += state.nodal_forces(self._nc)
                # owned contact nodes only (ghost entries would be summed twice)
                b_local.array.reshape(-1, self.bs)[self._c_own_blk] += f[self._c_own]
        fem_petsc.assemble_vector(self.b, self.R_form)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        r = self.b.array.copy()
        own_bc = self.bc_dofs[self.bc_dofs < self.n_owned]
        r[own_bc] = u[own_bc]
        self.counters["residuals"] += 1
        return r

    def contact_set(self) -> np.ndarray:
        """Active flags of every slave (all pairs) at the last :meth:`internal_force` (every rank).

        The Newton corrector lets an iteration whose set is still changing go on past its
        iteration limit (``sandwich/solver/newton.py``, "Contact-set settling").
        """
        flags = [np.zeros(len(state.gap), dtype=bool) for state in self._evaluated_contact]
        for f, state in zip(flags, self._evaluated_contact, strict=True):
            f[state.active] = True
        return np.concatenate(flags) if flags else np.zeros(0, dtype=bool)

    def tangent(self, u: np.ndarray) -> PETSc.Mat:
        """K = ∂(f_int + f_contact)/∂u from ``ufl.derivative`` plus the contact Hessian."""
        self._set_u(u)
        states = self._contact_states(want_tangent=True)
        if any(len(state.outside) for state, _pair in states):
            self._widen_windows(states)
        A = self.A
        A.zeroEntries()
        fem_petsc.assemble_matrix(A, self.J_form)
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        skew = None
        if self._c_nnz:
            # every contact slot of the pattern (zeros where open), summed over the active
            # slaves' 10×10 blocks with one bincount, inserted row by row (owned rows only);
            # the cohesive blocks' symmetric halves with them, their skew halves apart
            data = np.zeros(self._c_nnz)
            for state, _pair in states:
                slots, found = self._contact_slots(state.rows)
                data += np.bincount(slots[found], weights=state.tangents.ravel()[found],
                                    minlength=self._c_nnz)
            cohesive = self._cohesive_states(want_tangent=True)
            if cohesive:
                skew = np.zeros(self._c_nnz)
            for state in cohesive:
                slots, found = self._contact_slots(state.rows)
                K = state.tangents
                data += np.bincount(slots[found], minlength=self._c_nnz,
                                    weights=(0.5 * (K + K.transpose(0, 2, 1))).ravel()[found])
                skew += np.bincount(slots[found], minlength=self._c_nnz,
                                    weights=(0.5 * (K - K.transpose(0, 2, 1))).ravel()[found])
            add = PETSc.InsertMode.ADD_VALUES
            for row, lo, hi in self._c_rows:
                A.setValues(row, self._c_cols[lo:hi], data[lo:hi], addv=add)
        A.assemble()
        own_bc = self.bc_dofs[self.bc_dofs < self.n_owned]
        glob = (self.V.dofmap.index_map.local_range[0] * self.bs + own_bc).astype(np.int32)
        A.zeroRowsColumns(glob, diag=1.0)
        self._set_skew(skew, glob)
        self.counters["tangents"] += 1
        self._tangent_u = np.array(u, dtype=float)
        return A

    def _set_skew(self, skew: np.ndarray | None, bc_rows: np.ndarray) -> None:
        """The whole tangent where the cohesive blocks are not symmetric, else none.

        ``A`` holds the symmetric part (MUMPS's LDLᵀ factorises it, and gives the inertia the
        path follower reads); ``A_full`` = A + the skew half, which Krylov iterations
        preconditioned by that LDLᵀ solve with (:class:`MumpsFactorization`). A skew half below
        ``SKEW_FLOOR`` × the largest entry of the blocks is left out (round-off of symmetric
        blocks).
        """
        if self.A_full is not None:
            self.A_full.destroy()
            self.A_full = None
        size = 0.0 if skew is None or not skew.size else float(np.max(np.abs(skew)))
        if self.comm.size > 1:
            size = self.comm.allreduce(size, op=MPI.MAX)
        if size <= SKEW_FLOOR * self._cohesive_scale():
            return
        full = self.A.duplicate(copy=True)
        add = PETSc.InsertMode.ADD_VALUES
        for row, lo, hi in self._c_rows:
            full.setValues(row, self._c_cols[lo:hi], skew[lo:hi], addv=add)
        full.assemble()
        full.setOption(PETSc.Mat.Option.SYMMETRIC, False)
        full.zeroRowsColumns(bc_rows, diag=1.0)
        self.A_full = full
        self.counters["unsymmetric_tangents"] += 1

    def _cohesive_scale(self) -> float:
        """A size of the cohesive blocks: the largest law stiffness × area (N/mm)."""
        return max((lips.law.stiffness * p.width * float(np.max(lips.weight, initial=0.0))
                    for p in self.contacts for lips in p.cohesive), default=0.0)

    def factorize(self, K: PETSc.Mat) -> MumpsFactorization:
        """LDLᵀ with MUMPS (symmetric indefinite), inertia reported.

        ``K`` is the model's matrix as returned by :meth:`tangent` (its values are factorised now).
        """
        if K is not self.A:
            raise ValueError("factorize expects the matrix returned by tangent()")
        return MumpsFactorization(self, self._tangent_u)

    def _factor_current(self) -> int:
        self.counters["factorizations"] += 1
        self._generation += 1
        return self._mumps.factor(self.A)

    def probe_vector(self, name: str) -> np.ndarray:
        """C with probe value c · u."""
        return self.probes[name][: self.n_owned]

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        """Store the contact state of the converged ``u`` and commit its cohesive damage.

        The damage committed at every state is kept: a state committed again (the profiles
        sample the path's states after the run) takes back its own damage.
        """
        self._set_u(u)
        self.last_contact = [s for s, _ in self._contact_states(want_tangent=False)]
        lips = self.cohesive_lips
        if not lips:
            return
        for at, damage in reversed(self.damage_history):
            if at.shape == np.shape(u) and np.array_equal(at, u):
                for z, d in zip(lips, damage, strict=True):
                    z.damage[:] = d
                return
        for z, state in zip(lips, self._cohesive_states(want_tangent=False), strict=True):
            z.damage[:] = state.damage
        self.damage_history.append((np.array(u, dtype=float, copy=True),
                                    [z.damage.copy() for z in lips]))

    @property
    def cohesive_lips(self) -> list:
        """Every growing tip's :class:`~sandwich.plane2d.cohesive.CohesiveLips`, pair by pair."""
        return [z for p in self.contacts for z in p.cohesive]

    @property
    def path_dependent(self) -> bool:
        """Whether the model has history (cohesive damage): its state is not (u, λ) alone."""
        return bool(self.cohesive_lips)

    def admissible(self, u: np.ndarray) -> str:
        """``""`` if det F > 0 at every node of every cell, else where it is not.

        The Green-strain (St. Venant–Kirchhoff) law has equilibrium states with elements turned
        inside out (det F ≤ 0): a core crushed past its material limit point (stretch 1/√3)
        continues through det F = 0 into them. The path solver rejects such states.
        """
        self._set_u(u)
        self._detF.interpolate(self._detF_expr)
        d = self._detF.x.array
        dm = self._detF.function_space.dofmap
        n = dm.index_map.size_local * dm.bs  # owned nodes
        i = int(np.argmin(d[:n])) if n else -1
        local = (float(d[i]), i) if n else (np.inf, -1)
        dmin = self.comm.allreduce(local[0], op=MPI.MIN)
        if dmin > 0.0:
            return ""
        where = ""
        if local[0] == dmin and i >= 0:
            x = self._detF.function_space.tabulate_dof_coordinates()[i]
            where = f" at x = {x[0]:.4g}, z = {x[1]:.4g}"
        where = max(self.comm.allgather(where), key=len)
        return f"element inverted, det F = {dmin:.3g} <= 0{where}"

    # -- helpers ---------------------------------------------------------------------------------
    def _set_u(self, u: np.ndarray) -> None:
        self.u.x.array[: self.n_owned] = u
        self.u.x.scatter_forward()

    def current_positions(self) -> np.ndarray:
        """X = X + u for every local DOF block, (blocks, 2)."""
        return self.x_ref + self.u.x.array.reshape(-1, self.bs)

    def _setup_contact_nodes(self) -> None:
        """The contact nodes (input indices) as a compact list, the same on every rank.

        Their global DOF blocks and reference positions, the owned ones' local blocks, and the
        contact part of the matrix pattern (:meth:`_contact_pattern`).
        """
        im = self.V.dofmap.index_map
        pairs = self.contacts
        nodes = (np.unique(np.concatenate([p.nodes for p in pairs]))
                 if pairs else np.zeros(0, dtype=np.int64))
        self._nc = nc = len(nodes)
        index = {int(n): k for k, n in enumerate(nodes)}
        self._compact = {id(p): p.renumbered(index) for p in pairs}
        to_block = input_node_blocks(self.V) if nc else {}
        local = np.array([to_block.get(int(n), -1) for n in nodes], dtype=np.int64)
        owned = (local >= 0) & (local < im.size_local)
        self._c_own = np.flatnonzero(owned)
        self._c_own_blk = local[owned]
        gblock = np.full(nc, -1, dtype=np.int64)
        gblock[owned] = im.local_range[0] + local[owned]
        xref = np.zeros((nc, 2))
        # exact input coordinates (not tabulate_dof_coordinates, which may put the two nodes of
        # a closed lip a few ulps apart and so start every lip node open or shut at random)
        xref[owned] = block_input_coordinates(self.V)[local[owned]] if nc else xref[owned]
        if self.comm.size > 1:
            gblock = allreduce_array(self.comm, gblock, MPI.MAX)
            xref = allreduce_array(self.comm, xref, MPI.SUM)
        if np.any(gblock < 0):
            raise ValueError("a contact node is owned by no rank")
        self._c_gblock, self._c_xref, self._c_owned = gblock, xref, owned
        self._contact_pattern()

    def _contact_pattern(self) -> None:
        """The contact part of the matrix pattern, in compact DOFs (2 node + component).

        Each slave couples with every master node of its window (and those with each other):
        one sorted list of keys row · 2n_c + column, the global column of each and, per owned
        row, its range in the list.
        """
        nc, gblock = self._nc, self._c_gblock
        keys = []
        for p in self._compact.values():
            for i in range(len(p.slave)):
                dofs = (2 * p.window_nodes(i)[:, None] + np.arange(2)).ravel()
                keys.append((dofs[:, None] * (2 * nc) + dofs[None, :]).ravel())
        uniq = np.unique(np.concatenate(keys)) if keys else np.zeros(0, dtype=np.int64)
        self._c_keys, self._c_nnz = uniq, len(uniq)
        rows, cols = (uniq // (2 * nc), uniq % (2 * nc)) if nc else (uniq, uniq)
        self._c_pattern_nodes = (rows // 2, cols // 2)  # compact node pairs, for the matrix
        self._c_cols = (2 * gblock[cols // 2] + cols % 2).astype(np.int32)  # global columns
        bounds = np.flatnonzero(np.diff(rows, prepend=-1, append=-1))
        self._c_rows = [(int(2 * gblock[rows[lo] // 2] + rows[lo] % 2), int(lo), int(hi))
                        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
                        if self._c_owned[rows[lo] // 2]]

    def _contact_slots(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Contact-pattern slots of every entry of the (k, 5)-node blocks ``rows``, raveled.

        Returns the slots and whether each entry is in the pattern (every entry of a slave in its
        window is; a slave deeper than its pair's ``widen_depth`` may be outside it).
        """
        dofs = (2 * rows[:, :, None] + np.arange(2)).reshape(len(rows), 2 * rows.shape[1])
        keys = (dofs[:, :, None] * (2 * self._nc) + dofs[:, None, :]).ravel()
        slots = np.minimum(np.searchsorted(self._c_keys, keys), max(self._c_nnz - 1, 0))
        return slots, self._c_keys[slots] == keys if self._c_nnz else np.zeros(0, dtype=bool)

    def _widen_windows(self, states) -> None:
        """Widen the windows slaves in contact slid out of; rebuild the matrix with them.

        Every rank evaluates the same contact, so every rank rebuilds. MUMPS analyses the new
        pattern at the next factorisation.
        """
        for state, pair in states:
            if len(state.outside):
                self._compact[id(pair)].widen(state)
        self._contact_pattern()
        self.A.destroy()
        self.A = self._create_matrix()
        self._mumps.reset()
        self.counters["pattern_growths"] += 1

    def _contact_displacements(self) -> np.ndarray:
        """The displacements (n_c, 2) of the contact nodes, gathered from all ranks."""
        u = self.u.x.array.reshape(-1, self.bs)
        uc = np.zeros((self._nc, 2))
        uc[self._c_own] = u[self._c_own_blk]
        if self.comm.size > 1:
            uc = allreduce_array(self.comm, uc, MPI.SUM)
        return uc

    def _contact_states(self, want_tangent: bool):
        """[(state, pair)] of every pair, from the contact-node displacements of all ranks."""
        if not self.contacts:
            return []
        uc = self._contact_displacements()
        return [(ct.evaluate(self._compact[id(p)], self._c_xref, uc, want_tangent), p)
                for p in self.contacts]

    def _cohesive_states(self, want_tangent: bool) -> list[cz.CohesiveState]:
        """The cohesive law of every growing tip at the current ``u`` (the committed damage)."""
        if not self.cohesive_lips:
            return []
        uc = self._contact_displacements()
        return [cz.evaluate(self._compact[id(p)], lips, self._c_xref, uc, want_tangent)
                for p in self.contacts for lips in p.cohesive]

    def _create_matrix(self) -> PETSc.Mat:
        """AIJ matrix (block size 2) with the form's pattern plus every contact coupling.

        Built from global indices so that contact columns owned by other ranks get slots;
        the local-to-global map is V's (owned + ghost blocks), as dolfinx's assembler needs.
        Preallocation by CSR inserts explicit zeros in every slot, so no slot is ever dropped.
        """
        im = self.V.dofmap.index_map
        bs = self.bs
        sp = fem.create_sparsity_pattern(self.J_form)
        sp.assemble()
        graph = sp.graph
        cmap = sp.column_index_map()
        n_rows = im.size_local
        offsets = np.asarray(graph.offsets)
        rows = np.repeat(np.arange(n_rows, dtype=np.int64), np.diff(offsets)[:n_rows])
        cols = np.asarray(cmap.local_to_global(
            np.asarray(graph.array[: offsets[n_rows]], dtype=np.int32)), dtype=np.int64)
        r_node, c_node = self._c_pattern_nodes
        if len(r_node):
            own_local = np.full(self._nc, -1, dtype=np.int64)
            own_local[self._c_own] = self._c_own_blk
            keep = own_local[r_node] >= 0
            rows = np.concatenate([rows, own_local[r_node[keep]]])
            cols = np.concatenate([cols, self._c_gblock[c_node[keep]]])
        n_glob = im.size_global
        key = np.unique(rows * n_glob + cols)
        brow, bcol = key // n_glob, key % n_glob
        counts = np.bincount(brow, minlength=n_rows)
        bptr = np.concatenate([[0], np.cumsum(counts)])
        # scalar CSR: block row r gives rows bs r + c, each with columns bs c' + d of its blocks
        scol = (bs * bcol[:, None] + np.arange(bs)).ravel()
        indptr = np.concatenate([[0], np.cumsum(np.repeat(bs * counts, bs))]).astype(np.int32)
        indices = np.concatenate(
            [scol[bs * bptr[r]: bs * bptr[r + 1]] for r in range(n_rows) for _ in range(bs)]
        ).astype(np.int32) if n_rows else np.zeros(0, dtype=np.int32)
        n = n_rows * bs
        A = PETSc.Mat().create(self.comm)
        A.setSizes(((n, n_glob * bs), (n, n_glob * bs)), bsize=bs)
        A.setType(PETSc.Mat.Type.AIJ)
        A.setPreallocationCSR((indptr, indices))
        glob = im.local_to_global(np.arange(im.size_local + im.num_ghosts, dtype=np.int32))
        lgmap = PETSc.LGMap().create(np.asarray(glob, dtype=np.int32), bsize=bs, comm=self.comm)
        A.setLGMap(lgmap, lgmap)
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        return A

    def dot(self, a: np.ndarray, b: np.ndarray) -> float:
        """Global inner product of two owned-DOF vectors (sum over ranks)."""
        return float(self.comm.allreduce(float(np.dot(a, b))))

    def norm(self, a: np.ndarray) -> float:
        """Global Euclidean norm."""
        return float(np.sqrt(self.dot(a, a)))

    def contact_summary(self) -> dict[str, float]:
        """Max penetration (mm), pressure (MPa) and sliding of the lips in contact (mm).

        Of the last committed state; the sliding is the largest |slip| of a slave in contact.
        """
        pen = max((float(np.max(-s.gap, initial=0.0)) for s in self.last_contact), default=0.0)
        p = max((float(np.max(s.pressure, initial=0.0)) for s in self.last_contact), default=0.0)
        slide = max((float(np.max(np.abs(s.slip[s.active]), initial=0.0))
                     for s in self.last_contact), default=0.0)
        return {"max_penetration": max(pen, 0.0), "max_contact_pressure": p, "max_sliding": slide}
