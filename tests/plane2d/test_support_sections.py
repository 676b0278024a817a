"""A support holds the nodes of its face's section, never the core's corner at an open mouth.

Reference: the scene semantics (docs/scenes.md, docs/reference2d.md): a support acts on a
face's end section; the core's section is free. Where a debond reaches the supported end (fig7
c2-c4, fig9 d10-d40) the mesh splits the interface node there into a face lip node and a core
corner node at the same point. Before this test the section was selected by coordinates only,
which clamped the core's corner too: on fig7 c3 the corner element was sheared until it
inverted (det F <= 0 at w_tip = -10.8 mm, heavy full-path test) and the cantilever was too
stiff (lambda = 53.57 instead of 39.85 at w_top_tip = -10.7 mm).
"""

from pathlib import Path

import numpy as np
import pytest

from sandwich.meshes import build_mesh
from sandwich.plane2d.mesh import input_node_blocks
from sandwich.plane2d.model import build_model, face_band
from sandwich.plane2d.solve import solve
from sandwich.scene_file import load_scene

pytestmark = pytest.mark.dolfinx

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _model(name):
    scene = load_scene(SCENES / f"{name}.toml")
    mesh = build_mesh(scene, level="coarse")
    return scene, mesh, build_model(scene, mesh)


def test_clamp_at_an_open_mouth_holds_the_face_lip_and_frees_the_core_corner():
    scene, mesh, model = _model("paper-fig7-cantilever-c4")  # debonds 0-40, both interfaces
    system = model.system
    blocks = input_node_blocks(model.disc.V)
    fixed = set(system.bc_dofs.tolist())
    X = system.x_ref
    assert len(mesh.lip_pairs) == 2
    for i, debond in enumerate(scene.debonds):
        assert debond.start == 0.0
        pairs = np.asarray(mesh.lip_pairs[i])
        face_nodes = [blocks[int(n)] for n in pairs[:, 0]]
        core_nodes = [blocks[int(n)] for n in pairs[:, 1]]
        mouth = [k for k, b in enumerate(face_nodes) if abs(X[b, 0]) < 1e-9]
        assert len(mouth) == 1  # one lip node pair at x = 0
        f, c = face_nodes[mouth[0]], core_nodes[mouth[0]]
        assert np.allclose(X[f], X[c])  # coincident, split by the mesh
        assert {2 * f, 2 * f + 1} <= fixed  # the face's lip node belongs to the clamped section
        assert not ({2 * c, 2 * c + 1} & fixed)  # the core's corner is free
    # the whole face sections (5 nodes through each 0.5 mm face at coarse, or more) are held
    for face in ("top", "bottom"):
        band = face_band(scene, face)
        sec = np.flatnonzero((np.abs(X[:, 0]) < 1e-9) & (X[:, 1] > band.z_lo - 1e-9)
                             & (X[:, 1] < band.z_hi + 1e-9))
        held = [b for b in sec if {2 * b, 2 * b + 1} <= fixed]
        assert len(held) == len(sec) - 1 >= 2  # every node but the core's corner


def test_bonded_support_section_keeps_the_interface_node():
    """Bonded fig4: the interface node at the pin belongs to face and core cells: held in w."""
    scene, _mesh, model = _model("paper-fig4-bonded-3pb")
    X = model.system.x_ref
    fixed = set(model.system.bc_dofs.tolist())
    band = face_band(scene, "bottom")
    for x_s in (0.0, scene.length):
        sec = np.flatnonzero((np.abs(X[:, 0] - x_s) < 1e-9) & (X[:, 1] > band.z_lo - 1e-9)
                             & (X[:, 1] < band.z_hi + 1e-9))
        assert len(sec) >= 3 and any(abs(X[b, 1] - band.z_hi) < 1e-9 for b in sec)
        assert all(2 * b + 1 in fixed for b in sec)


@pytest.mark.timeout(300)
def test_cantilever_with_bottom_debond_at_the_clamp_bends_without_inverting(tmp_path):
    """fig7 c3 to w_top_tip = -3 mm: no inverted element, the core corner moves."""
    import dataclasses

    scene = load_scene(SCENES / "paper-fig7-cantilever-c3.toml")
    scene = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                    until_value=-3.0))
    sol = solve(scene, level="coarse", keep_states=True)
    assert sol.converged, sol.message
    model, states = sol.reference2d_states
    u = states[-1][2]
    assert model.system.admissible(u) == ""
    pairs = np.asarray(model.mesh.lip_pairs[0])
    blocks = input_node_blocks(model.disc.V)
    X = model.system.x_ref
    corner = [blocks[int(c)] for c in pairs[:, 1] if abs(X[blocks[int(c)], 0]) < 1e-9][0]
    # the core's corner follows the core (slides along the lip) instead of staying put
    assert np.hypot(*u.reshape(-1, 2)[corner]) > 1e-3
