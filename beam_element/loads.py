"""Consistent nodal loads of dead transverse face loads (eqs. 20-21) and probe functionals.

A face's w is Hermite-cubic in x (w, w,x at the nodes), so a load q(x) on a face does the virtual
work ∫ q (H_n δw_n + Hbar_n δw,x_n) dx: nodal forces and moments. A point load at a node is a
nodal force. A probe is the face's w at x, i.e. the same Hermite interpolation.
"""

from __future__ import annotations

import numpy as np

from beam_element.dofs import FACE_DOFS, global_dof
from beam_element.mesh import BeamMesh
from beam_element.quadrature import gauss_legendre
from beam_element.shape_functions import x_shape

_HERMITE = (("H", 0, "w"), ("Hbar", 0, "w,x"), ("H", 1, "w"), ("Hbar", 1, "w,x"))


def _check_face(face: str) -> None:
    if face not in FACE_DOFS:
        raise ValueError(f"a load or probe acts on 'top' or 'bottom', got {face!r}")


def hermite_w_row(mesh: BeamMesh, face: str, x: float) -> tuple[np.ndarray, np.ndarray]:
    """Full-DOF indices and weights of the face's w at ``x`` (Hermite interpolation, eq. 13b,d)."""
    _check_face(face)
    e, η = mesh.element_at(x)
    l = mesh.lengths[e]
    idx, val = [], []
    for kind, node, role in _HERMITE:
        value, _ = x_shape(kind, node, η)
        scale = 0.5 * l if kind == "Hbar" else 1.0  # Hbar(η; l) = (l/2) Hbar_ref
        idx.append(global_dof(e + node, FACE_DOFS[face][role]))
        val.append(scale * float(value))
    return np.array(idx), np.array(val)


def point_load(mesh: BeamMesh, face: str, x: float, force: float) -> np.ndarray:
    """Full nodal load vector of a transverse force (N, +z) at ``x`` on a face."""
    f = np.zeros(20 * mesh.n_nodes)
    idx, val = hermite_w_row(mesh, face, x)
    np.add.at(f, idx, force * val)
    return f


def patch_load(mesh: BeamMesh, face: str, start: float, end: float, force: float) -> np.ndarray:
    """Consistent nodal loads of a uniform load of total ``force`` (N, +z) over [start, end]."""
    _check_face(face)
    if not end > start:
        raise ValueError(f"a patch load needs end > start, got [{start}, {end}]")
    q = force / (end - start)  # N/mm
    f = np.zeros(20 * mesh.n_nodes)
    s, ws = gauss_legendre(3)  # q Hermite is cubic: exact
    for e in range(mesh.n_elements):
        a, b = max(start, mesh.x[e]), min(end, mesh.x[e + 1])
        if b <= a:
            continue
        xg = 0.5 * (a + b) + 0.5 * (b - a) * s
        for xq, wq in zip(xg, ws, strict=True):
            idx, val = hermite_w_row(mesh, face, float(np.clip(xq, mesh.x[e], mesh.x[e + 1])))
            np.add.at(f, idx, q * 0.5 * (b - a) * wq * val)
    return f


def probe_row(mesh: BeamMesh, face: str, x: float) -> np.ndarray:
    """Full-DOF vector c with c · u_full = w of the face at ``x`` (mm)."""
    c = np.zeros(20 * mesh.n_nodes)
    idx, val = hermite_w_row(mesh, face, x)
    np.add.at(c, idx, val)
    return c
