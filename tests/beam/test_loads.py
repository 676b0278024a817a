"""Consistent nodal loads of a uniform patch load (eqs. 20-21) and of its stretch-DOF share.

References: closed form — a face's w is Hermite-cubic, which reproduces the linear functions
1 and x exactly (1 = Σ H_n, x = Σ x_n H_n + Σ Hbar_n), so the nodal forces and moments of a
patch of total force F centred at x_c have the resultant F and the first moment F x_c whatever
the mesh; the stretch DOF's linear weights reproduce 1 and x likewise. And the definition as a
loop: 3 (2) Gauss points per element stretch, each through :func:`hermite_w_row`
(:meth:`BeamMesh.element_at`), added one by one — the vectorised functions give the same
vector bit for bit (the same terms, added in the same order).
"""

import numpy as np
import pytest

from sandwich.beam.dofs import FACE_DOFS, NODE_DOFS, dof
from sandwich.beam.loads import hermite_w_row, patch_load, stretch_patch_load, stretch_row
from sandwich.beam.mesh import build_mesh
from sandwich.beam.quadrature import gauss_legendre


def _patches(seed=3, count=60):
    """Random meshes and patches: edges anywhere, on nodes, or inside one element."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        mesh = build_mesh(300.0, int(rng.integers(6, 300)), stations=sorted(rng.uniform(0, 300, 3)),
                          grading=("graded", "uniform")[k % 2])
        if k % 3 == 0:
            i, j = sorted(rng.choice(mesh.n_nodes, 2, replace=False))
            start, end = mesh.x[i], mesh.x[j]
        elif k % 3 == 1:
            e = int(rng.integers(mesh.n_elements))
            start, end = sorted(rng.uniform(mesh.x[e], mesh.x[e + 1], 2))
        else:
            start, end = sorted(rng.uniform(0, 300, 2))
        if end > start:
            yield mesh, float(start), float(end), float(rng.normal())


def _looped(mesh, start, end, force, order, row, size):
    q = force / (end - start)
    f = np.zeros(size)
    s, ws = gauss_legendre(order)
    for e in range(mesh.n_elements):
        a, b = max(start, mesh.x[e]), min(end, mesh.x[e + 1])
        if b <= a:
            continue
        for xq, wq in zip(0.5 * (a + b) + 0.5 * (b - a) * s, ws, strict=True):
            idx, val = row(float(np.clip(xq, mesh.x[e], mesh.x[e + 1])))
            np.add.at(f, idx, q * 0.5 * (b - a) * wq * val)
    return f


@pytest.mark.parametrize("face", ["top", "bottom"])
def test_a_patch_loads_resultant_and_first_moment_are_the_patchs(face):
    w, wx = dof(FACE_DOFS[face]["w"]), dof(FACE_DOFS[face]["w,x"])
    for mesh, start, end, force in _patches():
        f = patch_load(mesh, face, start, end, force).reshape(-1, NODE_DOFS)
        assert np.sum(f[:, w]) == pytest.approx(force, rel=1e-12, abs=1e-14)
        moment = np.sum(f[:, w] * mesh.x) + np.sum(f[:, wx])
        assert moment == pytest.approx(force * 0.5 * (start + end), rel=1e-11, abs=1e-12)
        others = np.delete(f, [w, wx], axis=1)
        assert not np.any(others)


def test_the_stretch_share_has_the_patchs_resultant_and_first_moment():
    for mesh, start, end, force in _patches():
        f = stretch_patch_load(mesh, start, end, force)
        assert np.sum(f) == pytest.approx(force, rel=1e-12, abs=1e-14)
        assert np.sum(f * mesh.x) == pytest.approx(force * 0.5 * (start + end), rel=1e-11,
                                                   abs=1e-12)


def test_the_vectorised_loads_are_the_gauss_loop_bit_for_bit():
    for mesh, start, end, force in _patches(seed=5):
        for face in ("top", "bottom"):
            looped = _looped(mesh, start, end, force, 3,
                             lambda x, face=face: hermite_w_row(mesh, face, x),  # noqa: B023
                             NODE_DOFS * mesh.n_nodes)
            assert np.array_equal(patch_load(mesh, face, start, end, force), looped)
        looped = _looped(mesh, start, end, force, 2, lambda x: stretch_row(mesh, x),  # noqa: B023
                         mesh.n_nodes)
        assert np.array_equal(stretch_patch_load(mesh, start, end, force), looped)


def test_an_empty_patch_is_refused():
    mesh = build_mesh(300.0, 12)
    with pytest.raises(ValueError, match="end > start"):
        patch_load(mesh, "top", 10.0, 10.0, 1.0)
    with pytest.raises(ValueError, match="end > start"):
        stretch_patch_load(mesh, 20.0, 10.0, 1.0)
    with pytest.raises(ValueError, match="'top' or 'bottom'"):
        patch_load(mesh, "core", 10.0, 20.0, 1.0)
