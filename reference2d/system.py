"""The 2D reference as a :class:`sandwich.solver.DiscreteSystem`: PETSc assembly, MUMPS LDLᵀ.

Unknowns are all displacement DOFs of the vector Q2 space (x then z component per node, dolfinx
block order). Supports are homogeneous and imposed as trivial equations u_i = 0 (row and column
of the tangent replaced by the identity), so the constrained DOFs stay zero along any path and
the solver's vectors need no index juggling. Contact terms are evaluated in NumPy and added to the
PETSc matrix, whose sparsity pattern holds every potential contact block from the start.
Serial: numpy vectors are the rank's owned DOFs (all of them on one rank).
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import cpp, fem
from dolfinx.fem import petsc as fem_petsc
from petsc4py import PETSc

from reference2d import contact as ct

JIT = {"cffi_extra_compile_args": ["-O2"]}


class MumpsFactorization:
    """MUMPS LDLᵀ of a symmetric tangent; inertia from INFOG(12) (negative pivots)."""

    def __init__(self, K: PETSc.Mat, comm):
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOperators(K)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        # the model reuses its matrix for the next tangent: never refactor this one silently
        pc.setReusePreconditioner(True)
        pc.setFactorSetUpSolverType()
        F = pc.getFactorMatrix()
        F.setMumpsIcntl(13, 1)  # no ScaLAPACK root: INFOG(12) counts every negative pivot
        F.setMumpsIcntl(14, 80)  # working space +80 %
        F.setMumpsIcntl(24, 1)  # detect null pivots (reported in INFOG(28))
        try:
            self.ksp.setUp()
        except PETSc.Error as exc:
            raise ArithmeticError(f"MUMPS factorisation failed (error {exc.ierr})") from None
        if F.getMumpsInfog(1) < 0:
            raise ArithmeticError(f"MUMPS factorisation failed, INFOG(1) = {F.getMumpsInfog(1)}")
        if F.getMumpsInfog(28) > 0:
            raise ArithmeticError(f"singular tangent: {F.getMumpsInfog(28)} null pivot(s)")
        self._neg = int(F.getMumpsInfog(12))
        self.x, self.b = K.createVecs()

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return K⁻¹ b."""
        self.b.array[:] = b
        self.ksp.solve(self.b, self.x)
        return self.x.array.copy()

    @property
    def negative_pivots(self) -> int | None:
        """Number of negative eigenvalues of K (Sylvester's law of inertia)."""
        return self._neg

    def destroy(self) -> None:
        """Free PETSc objects."""
        self.ksp.destroy()


class Reference2DSystem:
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
        self.A = self._create_matrix()
        self.b = fem_petsc.create_vector(self.R_form)
        self.last_contact: list[ct.ContactState] = []
        self.counters = {"residuals": 0, "tangents": 0, "factorizations": 0}

    # -- the DiscreteSystem protocol -------------------------------------------------------------
    @property
    def size(self) -> int:
        """Number of unknowns on this rank (constrained ones included, as u_i = 0)."""
        return self.n_owned

    @property
    def f_ref(self) -> np.ndarray:
        """Reference load (λ = 1)."""
        return self._f_ref[: self.n_owned]

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """f_int(u) + f_contact(u); rows of supports return u_i."""
        self._set_u(u)
        with self.b.localForm() as b_local:
            b_local.set(0.0)
            for state, _pair in self._contact_states(want_tangent=False):
                for rows, f in zip(state.rows, state.forces, strict=True):
                    dofs = (self.bs * rows[:, None] + np.arange(self.bs)).ravel()
                    np.add.at(b_local.array, dofs, f)
        fem_petsc.assemble_vector(self.b, self.R_form)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        r = self.b.array.copy()
        own_bc = self.bc_dofs[self.bc_dofs < self.n_owned]
        r[own_bc] = u[own_bc]
        self.counters["residuals"] += 1
        return r

    def tangent(self, u: np.ndarray) -> PETSc.Mat:
        """K = ∂(f_int + f_contact)/∂u from ``ufl.derivative`` plus the contact Hessian."""
        self._set_u(u)
        A = self.A
        A.zeroEntries()
        fem_petsc.assemble_matrix(A, self.J_form)
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        # PETSc drops pattern slots that stay unfilled at a final assembly: touch every
        # potential contact block with zeros, then add the active ones
        for blocks in self._contact_blocks:
            dofs = (self.bs * blocks[:, None] + np.arange(self.bs)).ravel().astype(np.int32)
            A.setValuesLocal(dofs, dofs, np.zeros((len(dofs), len(dofs))),
                             addv=PETSc.InsertMode.ADD_VALUES)
        for state, _pair in self._contact_states(want_tangent=True):
            for rows, k in zip(state.rows, state.tangents, strict=True):
                dofs = (self.bs * rows[:, None] + np.arange(self.bs)).ravel().astype(np.int32)
                A.setValuesLocal(dofs, dofs, k, addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()
        own_bc = self.bc_dofs[self.bc_dofs < self.n_owned]
        glob = (self.V.dofmap.index_map.local_range[0] * self.bs + own_bc).astype(np.int32)
        A.zeroRowsColumns(glob, diag=1.0)
        self.counters["tangents"] += 1
        return A

    def factorize(self, K: PETSc.Mat) -> MumpsFactorization:
        """LDLᵀ with MUMPS (symmetric indefinite), inertia reported."""
        self.counters["factorizations"] += 1
        return MumpsFactorization(K, self.comm)

    def probe_vector(self, name: str) -> np.ndarray:
        """C with probe value c · u."""
        return self.probes[name][: self.n_owned]

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        """Penalty contact keeps no history: store the contact state of the converged ``u``."""
        self._set_u(u)
        self.last_contact = [s for s, _ in self._contact_states(want_tangent=False)]

    # -- helpers ---------------------------------------------------------------------------------
    def _set_u(self, u: np.ndarray) -> None:
        self.u.x.array[: self.n_owned] = u
        self.u.x.scatter_forward()

    def current_positions(self) -> np.ndarray:
        """X = X + u for every local DOF block, (blocks, 2)."""
        return self.x_ref + self.u.x.array.reshape(-1, self.bs)

    def _contact_states(self, want_tangent: bool):
        if not self.contacts:
            return []
        u = self.u.x.array.reshape(-1, self.bs)
        return [(ct.evaluate(p, self.x_ref, u, want_tangent), p) for p in self.contacts]

    def _create_matrix(self) -> PETSc.Mat:
        sp = fem.create_sparsity_pattern(self.J_form)
        self._contact_blocks = []
        for pair in self.contacts:
            for i in range(len(pair.slave)):
                blocks = pair.blocks(i).astype(np.int32)
                sp.insert(blocks, blocks)
                self._contact_blocks.append(blocks)
        sp.assemble()
        A = cpp.la.petsc.create_matrix(self.comm, sp)
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        return A

    def contact_summary(self) -> dict[str, float]:
        """Max penetration (mm) and max pressure (MPa) of the last committed state."""
        pen = max((float(np.max(-s.gap, initial=0.0)) for s in self.last_contact), default=0.0)
        p = max((float(np.max(s.pressure, initial=0.0)) for s in self.last_contact), default=0.0)
        return {"max_penetration": max(pen, 0.0), "max_contact_pressure": p}
