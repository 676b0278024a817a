"""Domain J-integral at a debond tip of the 2D model: a cross-check of the VCCT G.

For the St Venant–Kirchhoff law (hyperelastic, W = ½ S : E) in the reference configuration,
with the crack advancing along e (+x at an ``end`` tip, −x at a ``start`` tip),

    J = ∫_A [ (∇u e) · (P ∇q) − W (e · ∇q) ] dA        (Shih, Moran & Nakamura 1986)

with P = F S and q a weight that is 1 at the tip and 0 outside the disc of radius R around it.
J is the energy release rate of a traction-free crack in a body homogeneous along e: the layers
vary with z only, so the face/core interface crack qualifies. Lips in contact carry tractions
the domain form leaves out (the term ∫ t · (∇u e) q ds along the lips): J is then not G. The
disc must hold no load and no support. G, not its split.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from sandwich.plane2d.constitutive import green_lagrange
from sandwich.plane2d.model import Model2D

JIT = {"cffi_extra_compile_args": ["-O2"]}


class JIntegral:
    """J (N/mm) at one tip point for any displacement state of ``model``."""

    def __init__(self, model: Model2D, x_tip: float, z_tip: float, direction: float,
                 radius: float):
        if not radius > 0:
            raise ValueError(f"J-integral radius must be positive, got {radius!r}")
        sys = model.system
        self.system = sys
        Vq = fem.FunctionSpace(sys.V.mesh, ("Lagrange", 2))
        self.q = fem.Function(Vq)

        def weight(x):
            r = np.hypot(x[0] - x_tip, x[1] - z_tip) / radius
            return np.where(r < 1.0, (1.0 - r**2) ** 2, 0.0)  # smooth, 1 at the tip

        self.q.interpolate(weight)
        u = sys.u
        e = ufl.as_vector((float(np.sign(direction)), 0.0))
        E = green_lagrange(u)
        S = model.stiffness.pk2(E)
        P = S + ufl.grad(u) * S  # F S
        W = 0.5 * ufl.inner(S, E)
        grad_q = ufl.grad(self.q)
        density = ufl.dot(ufl.dot(ufl.grad(u), e), ufl.dot(P, grad_q)) - W * ufl.dot(e, grad_q)
        self.form = fem.form(density * ufl.dx, jit_params=JIT)

    def evaluate(self, u: np.ndarray) -> float:
        """J (N/mm) at the owned DOF vector ``u``."""
        self.system._set_u(u)
        local = fem.assemble_scalar(self.form)
        return float(self.system.comm.allreduce(local, op=MPI.SUM))
