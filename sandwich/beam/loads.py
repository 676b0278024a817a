"""Consistent nodal loads of dead transverse face loads (eqs. 20-21) and probe functionals.

A face's w is Hermite-cubic in x (w, w,x at the nodes), so a load q(x) on a face does the virtual
work ∫ q (H_n δw_n + Hbar_n δw,x_n) dx: nodal forces and moments. A point load at a node is a
nodal force. A probe is the face's w at x, i.e. the same Hermite interpolation.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.dofs import FACE_DOFS, global_dof
from sandwich.beam.mesh import BeamMesh
from sandwich.beam.quadrature import gauss_legendre
from sandwich.beam.shape_functions import x_shape

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


def _patch_points(mesh: BeamMesh, start: float, end: float, order: int, q: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points of [start, end] ∩ each element, element by element, for a load q (N/mm).

    Returns each point's q (b − a)/2 w_g (its stretch [a, b], its weight; multiplied in that
    order), element and reference coordinate η (:meth:`BeamMesh.elements_at`).
    """
    s, ws = gauss_legendre(order)
    lo, hi = mesh.x[:-1], mesh.x[1:]
    a, b = np.maximum(start, lo), np.minimum(end, hi)
    hit = b > a
    a, b, lo, hi = a[hit], b[hit], lo[hit], hi[hit]
    xg = np.clip((0.5 * (a + b))[:, None] + (0.5 * (b - a))[:, None] * s, lo[:, None], hi[:, None])
    e, eta = mesh.elements_at(xg.ravel())
    return ((q * 0.5 * (b - a))[:, None] * ws).ravel(), e, eta


def point_load(mesh: BeamMesh, face: str, x: float, force: float) -> np.ndarray:
    """Full nodal load vector of a transverse force (N, +z) at ``x`` on a face."""
    f = np.zeros(20 * mesh.n_nodes)
    idx, val = hermite_w_row(mesh, face, x)
    np.add.at(f, idx, force * val)
    return f


def patch_load(mesh: BeamMesh, face: str, start: float, end: float, force: float) -> np.ndarray:
    """Consistent nodal loads of a uniform load of total ``force`` (N, +z) over [start, end].

    3 Gauss points per element stretch (q × a cubic Hermite function: exact), evaluated at
    once; the terms are added in the order of a loop over elements, points and the four
    functions of eq. (13b,d), as :func:`hermite_w_row` gives them.
    """
    _check_face(face)
    if not end > start:
        raise ValueError(f"a patch load needs end > start, got [{start}, {end}]")
    q = force / (end - start)  # N/mm
    f = np.zeros(20 * mesh.n_nodes)
    coef, e, eta = _patch_points(mesh, start, end, 3, q)
    idx, val = [], []
    for kind, node, role in _HERMITE:
        value, _ = x_shape(kind, node, eta)
        scale = 0.5 * mesh.lengths[e] if kind == "Hbar" else 1.0  # Hbar(η; l) = (l/2) Hbar_ref
        idx.append(global_dof(e + node, FACE_DOFS[face][role]))
        val.append(scale * value)
    idx, val = np.stack(idx, axis=1), np.stack(val, axis=1)  # (points, 4)
    np.add.at(f, idx.ravel(), (coef[:, None] * val).ravel())
    return f


def probe_row(mesh: BeamMesh, face: str, x: float) -> np.ndarray:
    """Full-DOF vector c with c · u_full = w of the face at ``x`` (mm)."""
    c = np.zeros(20 * mesh.n_nodes)
    idx, val = hermite_w_row(mesh, face, x)
    np.add.at(c, idx, val)
    return c


# --- the face stretch DOF (build_model(face_stretch=True)) -----------------------------------
# With the stretch DOF d (w of the outer surface minus w of the inner one, linear along x), a
# face's w is w_inner + d L_outer(z): a load on the face's outer surface also works on d, and the
# face's mid-surface w (where the 2D model reads its probes) is w_inner + d/2.


def stretch_row(mesh: BeamMesh, x: float) -> tuple[np.ndarray, np.ndarray]:
    """Node indices and linear weights of the stretch DOF's value at ``x``."""
    e, η = mesh.element_at(x)
    return np.array([e, e + 1]), np.array([0.5 * (1 - η), 0.5 * (1 + η)])


def stretch_point_load(mesh: BeamMesh, x: float, force: float) -> np.ndarray:
    """Work-conjugate nodal loads (per node) on d of a force on the outer surface at ``x``."""
    f = np.zeros(mesh.n_nodes)
    idx, val = stretch_row(mesh, x)
    np.add.at(f, idx, force * val)
    return f


def stretch_patch_load(mesh: BeamMesh, start: float, end: float, force: float) -> np.ndarray:
    """The same for a uniform load of total ``force`` over [start, end] (per node).

    2 Gauss points per element stretch (q times a linear function: exact), evaluated at once.
    """
    if not end > start:
        raise ValueError(f"a patch load needs end > start, got [{start}, {end}]")
    q = force / (end - start)
    f = np.zeros(mesh.n_nodes)
    coef, e, eta = _patch_points(mesh, start, end, 2, q)
    idx = np.stack([e, e + 1], axis=1)
    val = np.stack([0.5 * (1 - eta), 0.5 * (1 + eta)], axis=1)
    np.add.at(f, idx.ravel(), (coef[:, None] * val).ravel())
    return f
