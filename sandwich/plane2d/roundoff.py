"""The round-off floor of the 2D residual: how small Newton can make it, at u = 0 and along a path.

A part of :class:`~sandwich.plane2d.system.Reference2DSystem`, apart because it is one idea: the
stiff through-thickness terms of the thin faces turn an ulp of each displacement into residual.
"""

from __future__ import annotations

import numpy as np
from petsc4py import PETSc


class ResidualRoundoff:
    """ε ‖ |K| |u| ‖ of the system it is mixed into (``tangent``, ``factorize``, ``norm``)."""

    def residual_roundoff_bound(self) -> float:
        """Round-off bound of the residual relative to the load: ε ‖ |K(0)| |u₁| ‖ / ‖f_ref‖.

        u₁ = K(0)⁻¹ f_ref; the a-priori bound of the round-off in evaluating the residual, scale-
        free along the linear range.

        The through-thickness stiffness of thin face elements (E b l / h ~ 1e8 N/mm) times the ulp
        of the displacement makes this 1e-8…1e-7 on the paper scenes, at or above the default
        Newton tolerance of 1e-8; measured floors are ~1/10 of the bound.
        """
        K = self.tangent(np.zeros(self.size))
        fac = self.factorize(K)
        u1 = fac.solve(self.f_ref)
        fac.destroy()
        return self._abs_k_abs_u(K, u1) / max(self.norm(self.f_ref), 1e-300)

    def residual_roundoff(self, u: np.ndarray) -> float:
        """Round-off level of the residual at the state ``u`` (N): ε ‖ |K(u)| |u| ‖.

        The state itself is stored to an ulp of each displacement, and the stiff
        through-thickness terms of the thin faces turn that into residual: no Newton iterate can
        go below this. Unlike :meth:`residual_roundoff_bound` (at u = 0, relative to the load)
        it grows with |u| / λ, i.e. when the structure softens along the path.
        """
        return self._abs_k_abs_u(self.tangent(u), u)

    def _abs_k_abs_u(self, K: PETSc.Mat, u: np.ndarray) -> float:
        """ε ‖ |K| |u| ‖ (global norm)."""
        B = K.copy()
        ai, aj, av = B.getValuesCSR()
        B.setValuesCSR(ai, aj, np.abs(av))
        B.assemble()
        x, y = B.createVecs()
        x.array[:] = np.abs(u)
        B.mult(x, y)
        bound = np.finfo(float).eps * y.norm()
        for obj in (B, x, y):
            obj.destroy()
        return float(bound)
