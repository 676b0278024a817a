"""MUMPS for the 2D model's matrix: one persistent LDLᵀ, its handles, GMRES on a whole tangent.

The system (:mod:`sandwich.plane2d.system`) keeps one PETSc matrix with a fixed pattern, so
MUMPS analyses it once; a factorised tangent reaches the path solver as a
:class:`MumpsFactorization`. Where a cohesive law makes the tangent unsymmetric, the LDLᵀ is of
its symmetric part and :meth:`MumpsSolver.solve_whole` solves with the whole matrix.
"""

from __future__ import annotations

import numpy as np
from petsc4py import PETSc

KRYLOV_RTOL = 1e-10  # GMRES on an unsymmetric tangent: relative residual
KRYLOV_MAX = 200  # and its iterations


class MumpsSolver:
    """One persistent MUMPS LDLᵀ (PETSc KSP "preonly" + PC "cholesky") for the model's matrix.

    Every tangent lives in the same PETSc matrix with the same sparsity pattern, so MUMPS's
    analysis (ordering, symbolic factorisation) is done once and every later tangent only gets a
    numeric factorisation. Inertia from INFOG(12) (ICNTL(13) = 1: no ScaLAPACK root, so every
    negative pivot is counted); null pivots (ICNTL(24)) raise ``ArithmeticError``.
    """

    def __init__(self, comm):
        self.comm = comm
        self.ksp = None
        self.analyses = 0  # symbolic analyses done (1 unless a factorisation failed)
        self._krylov = None  # GMRES on the whole tangent (:meth:`solve_whole`)
        self.krylov_iterations = 0

    def _create(self, K: PETSc.Mat) -> None:
        self.ksp = PETSc.KSP().create(self.comm)
        self.ksp.setOperators(K)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        F = pc.getFactorMatrix()
        F.setMumpsIcntl(13, 1)  # no ScaLAPACK root: INFOG(12) counts every negative pivot
        F.setMumpsIcntl(14, 80)  # working space +80 %
        F.setMumpsIcntl(24, 1)  # detect null pivots (reported in INFOG(28))
        self.analyses += 1

    def factor(self, K: PETSc.Mat) -> int:
        """Numeric factorisation of the current values of ``K``; returns the negative pivots."""
        if self.ksp is None:
            self._create(K)
        else:
            self.ksp.setOperators(K)  # same pattern: PCSetUp does the numeric phase only
        pc = self.ksp.getPC()
        try:
            self.ksp.setUp()
        except PETSc.Error as exc:
            self.reset()
            raise ArithmeticError(f"MUMPS factorisation failed (error {exc.ierr})") from None
        F = pc.getFactorMatrix()
        if F.getMumpsInfog(1) < 0:
            info = F.getMumpsInfog(1)
            self.reset()
            raise ArithmeticError(f"MUMPS factorisation failed, INFOG(1) = {info}")
        if F.getMumpsInfog(28) > 0:
            nulls = F.getMumpsInfog(28)
            self.reset()
            raise ArithmeticError(f"singular tangent: {nulls} null pivot(s)")
        return int(F.getMumpsInfog(12))

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """X = K⁻¹ b with the current factorisation."""
        self.ksp.solve(b, x)

    def solve_whole(self, K: PETSc.Mat, b: PETSc.Vec, x: PETSc.Vec) -> bool:
        """X = K⁻¹ b for the whole (unsymmetric) tangent ``K`` by preconditioned GMRES.

        Right-preconditioned by the current factorisation of K's symmetric part. The two differ by
        the cohesive blocks' skew halves, of rank r at most 8 × the damaging nodes, so that GMRES
        converges within about r + 1 iterations (exactly, in exact arithmetic). Returns whether
        it converged (to ``KRYLOV_RTOL`` of ``b``, within ``KRYLOV_MAX`` iterations); ``x`` is
        its last iterate either way.
        """
        if self._krylov is None:
            k = PETSc.KSP().create(self.comm)
            k.setType("gmres")
            k.setGMRESRestart(KRYLOV_MAX)
            k.setPCSide(PETSc.PC.Side.RIGHT)  # the true residual is the one monitored
            k.setTolerances(rtol=KRYLOV_RTOL, atol=0.0, max_it=KRYLOV_MAX)
            pc = k.getPC()
            pc.setType("python")
            pc.setPythonContext(_Factors(self))
            self._krylov = k
        self._krylov.setOperators(K)
        self._krylov.solve(b, x)
        self.krylov_iterations += self._krylov.getIterationNumber()
        return self._krylov.getConvergedReason() > 0

    def reset(self) -> None:
        """Drop the KSP (after a failure: the next tangent starts with a fresh analysis)."""
        if self.ksp is not None:
            self.ksp.destroy()
            self.ksp = None


class _Factors:
    """The symmetric part's LDLᵀ as a PETSc python preconditioner (of :meth:`solve_whole`)."""

    def __init__(self, solver: MumpsSolver):
        self.solver = solver

    def apply(self, pc, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """Y = S⁻¹ x."""
        self.solver.ksp.solve(x, y)


class MumpsFactorization:
    """A factorised tangent as the path solver sees it: a handle on the model's MUMPS factors.

    The factors are shared by all handles (one MUMPS instance per model); a handle whose tangent
    has since been replaced by a newer one (the path solver keeps the factorisation of a trial
    step while it tries others) recomputes and refactors its tangent at its own state before
    solving, so a stale handle never solves with another state's factors.
    """

    def __init__(self, system: object, u: np.ndarray | None):
        self.system = system
        self.u = None if u is None else np.array(u, dtype=float)
        self._neg = system._factor_current()
        self.generation = system._generation

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return K⁻¹ b."""
        s = self.system
        if self.generation != s._generation:
            if self.u is None:
                raise RuntimeError("stale factorisation of a tangent not built by the model")
            s.counters["refactorizations"] += 1
            s.tangent(self.u)
            self._neg = s._factor_current()
            self.generation = s._generation
        s._rhs.array[:] = b
        if s.A_full is None:
            s._mumps.solve(s._rhs, s._sol)
        elif not s._mumps.solve_whole(s.A_full, s._rhs, s._sol):
            # GMRES minimises the residual: its last iterate is kept (counted)
            s.counters["krylov_unconverged"] += 1
        return s._sol.array.copy()

    @property
    def negative_pivots(self) -> int | None:
        """Number of negative eigenvalues of K (Sylvester's law of inertia)."""
        return self._neg

    def destroy(self) -> None:
        """Nothing to free: the factors belong to the model."""
