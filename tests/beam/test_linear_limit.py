"""Linear limit against classical sandwich theory, and mesh refinement.

Reference: classical (antiplane-core) sandwich beam theory, e.g. Zenkert, "An Introduction to
Sandwich Construction", ch. 4: simply supported beam of span L, faces E_f, t, core c, d = c + t,

    D = E_f b t d² / 2,   S = G_c b d² / c,
    uniform load q (N/mm):   w_mid = 5 q L⁴ / (384 D) + q L² / (8 S),
    central point load P:    w_mid = P L³ / (48 D) + P L / (4 S).

Its assumptions are made to hold: thin faces (t/d = 0.02, so the faces' own bending stiffness is
~1e-4 of D), a core rigid through the thickness (E_z = 1e5 MPa) whose axial stiffness is
negligible (E_x = 1 MPa, 3.6e-5 of the faces'), ν_zx = 0, both faces supported in w at the ends.
(E_x is not taken as small as 1e-3: the faces' u is linear in x and the core's boundary u cubic,
tied only at nodes, so a core without axial stiffness gives the interface near-free modes between
nodes and converges only once h ≲ c √(E_x/G_zx); see docs/beam_element.md.)
"""

import numpy as np
import pytest
from beam_scenes import KEVLAR, Load, Support, sandwich_scene

from sandwich.beam import run
from sandwich.scene import Material

L, b, t, c = 300.0, 60.0, 0.5, 25.0
IDEAL_CORE = Material("antiplane", "orthotropic", 1.0, 1e5, 21.0, 0.0)
SUPPORTS = (Support(0.0, "faces", "roller"), Support(0.0, "bottom", "pin"),
            Support(L, "faces", "roller"))
d = c + t
D = KEVLAR.Ex * b * t * d**2 / 2
S = IDEAL_CORE.Gzx * b * d**2 / c


def classical(load, force):
    if load == "uniform":
        q = force / L
        return 5 * q * L**4 / (384 * D) + q * L**2 / (8 * S)
    return force * L**3 / (48 * D) + force * L / (4 * S)


def beam_deflection(load, force, elements, grading="graded"):
    width = L if load == "uniform" else 0.0
    loads = (Load("top", L / 2, width, force),)
    scene = sandwich_scene(core_material=IDEAL_CORE, loads=loads, supports=SUPPORTS,
                           elements=elements)
    probes = run(scene, model_options={"grading": grading}).solution.history[-1].probes
    return probes["w_top_mid"], probes["w_bottom_mid"]


@pytest.mark.parametrize("load", ["uniform", "central"])
def test_linear_limit_matches_classical_sandwich_theory(load):
    w_top, w_bottom = beam_deflection(load, -100.0, 256)
    expected = classical(load, -100.0)
    assert abs(w_bottom / expected - 1) < 0.01
    assert abs(w_top / expected - 1) < 0.01


def test_mesh_refinement_converges_with_observed_order_at_least_two():
    # uniform meshes: the element size halves exactly at each step (a graded mesh changes its
    # shape with the count, so its error sequence is not an h-halving sequence)
    n = np.array([16, 32, 64, 128])
    expected = classical("uniform", -100.0)
    err = np.array([abs(beam_deflection("uniform", -100.0, k, "uniform")[1] - expected)
                    for k in n])
    orders = np.diff(np.log(err)) / np.diff(np.log(1.0 / n))
    assert np.all(np.diff(err) < 0)
    assert np.all(orders > 2.0), orders
    slope = np.polyfit(np.log(1.0 / n), np.log(err), 1)[0]
    assert slope > 2.0
