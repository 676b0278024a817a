"""The assembled tangent (UFL derivative + contact Hessian) against finite differences."""

from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc
from r2d_structured import layered_mesh

from sandwich.plane2d.model import build_model
from sandwich.scene_file import load_scene

pytestmark = pytest.mark.dolfinx

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _mult(K, d):
    y = K.createVecLeft()
    K.mult(PETSc.Vec().createWithArray(d.copy()), y)
    return y.array.copy()


def test_jacobian_matches_finite_differences_with_contact_active():
    scene = load_scene(SCENES / "paper-fig5-top-debond-40-load-top.toml")
    mesh = layered_mesh(300, [("bottom", 0.5, 1), ("core", 25, 4), ("top", 0.5, 1)], 60,
                        debonds=[("top", 130, 170)])
    model = build_model(scene, mesh)
    s = model.system
    # the linear solution at λ = 100 pushes the face lip into the core: contact is active
    fac = s.factorize(s.tangent(np.zeros(s.size)))
    u = fac.solve(100.0 * s.f_ref)
    s.commit(u, 100.0)
    active = sum(len(st.rows) for st in s.last_contact)
    assert active >= 5
    rng = np.random.default_rng(0)
    K = s.tangent(u).copy()  # the model reuses its matrix
    for _ in range(3):
        d = rng.standard_normal(s.size)
        d[s.bc_dofs] = 0.0
        eps = 1e-6 * np.linalg.norm(u) / np.linalg.norm(d)
        fd = (s.internal_force(u + eps * d) - s.internal_force(u - eps * d)) / (2 * eps)
        assert np.linalg.norm(fd - _mult(K, d)) <= 1e-6 * np.linalg.norm(fd)
    # and the contact part alone is a real contribution (the check would fail without it)
    s.contacts, saved = [], s.contacts
    K0 = s.tangent(u)
    s.contacts = saved
    d = rng.standard_normal(s.size)
    d[s.bc_dofs] = 0.0
    assert np.linalg.norm(_mult(K, d) - _mult(K0, d)) > 1e-3 * np.linalg.norm(_mult(K, d))
