"""XDMF time series for ParaView: displacement (Q2 on the Q2 mesh) and DG0 Cauchy stresses."""

from __future__ import annotations

from pathlib import Path

import ufl
from dolfinx import fem
from dolfinx.io import XDMFFile

from reference2d.constitutive import deformation_gradient, green_lagrange


def write_fields(solution, path: str | Path, every: int = 1) -> Path:
    """Write the states kept by ``solve(..., keep_states=True)`` to ``path`` (.xdmf + .h5).

    Written per step (time = step number): ``displacement`` (mm), and cell averages (DG0, at the
    cell centre) of the Cauchy stress σ = F S Fᵀ / det F: ``sigma_x``, ``sigma_z``, ``tau``
    and the plane-stress ``von_mises`` (MPa). The file is written collectively over the mesh's
    communicator (one file, as dolfinx does).
    """
    if not hasattr(solution, "reference2d_states"):
        raise ValueError("write_fields needs the solution of solve(..., keep_states=True)")
    model, states = solution.reference2d_states
    path = Path(path).with_suffix(".xdmf")
    if model.disc.mesh.comm.rank == 0:
        path.parent.mkdir(parents=True, exist_ok=True)
    msh = model.disc.mesh
    u = model.system.u
    F = deformation_gradient(u)
    S = model.stiffness.pk2(green_lagrange(u))
    sigma = F * S * F.T / ufl.det(F)
    Q0 = fem.FunctionSpace(msh, ("DG", 0))
    pts = Q0.element.interpolation_points()
    vm = ufl.sqrt(sigma[0, 0] ** 2 - sigma[0, 0] * sigma[1, 1] + sigma[1, 1] ** 2
                  + 3 * sigma[0, 1] ** 2)
    outs = {}
    for name, expr in (("sigma_x", sigma[0, 0]), ("sigma_z", sigma[1, 1]),
                       ("tau", sigma[0, 1]), ("von_mises", vm)):
        f = fem.Function(Q0, name=name)
        outs[name] = (f, fem.Expression(expr, pts))
    u.name = "displacement"
    with XDMFFile(msh.comm, str(path), "w") as xdmf:
        xdmf.write_mesh(msh)
        for step, _lam, state in states:
            if every > 1 and step % every and step != states[-1][0]:
                continue
            model.system._set_u(state)
            xdmf.write_function(u, float(step))
            for f, expr in outs.values():
                f.interpolate(expr)
                xdmf.write_function(f, float(step))
    return path
