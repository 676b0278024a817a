"""Probes are read where they fall, by the element's interpolation: they never change the mesh.

Reference by invariance: the same scene with one probe and with 300 more (one every mm, most
between nodes) gives the same mesh and, to round-off, the same path.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import run
from sandwich.beam.build import beam_mesh
from sandwich.scene import Analysis, Probe
from sandwich.scene_file import load_scene

FIG5 = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


@pytest.fixture(scope="module")
def scenes():
    base = load_scene(FIG5)
    base = dataclasses.replace(base, analysis=Analysis(kind="linear", control="load",
                                                       until_load_factor=100.0))
    many = dataclasses.replace(base, probes=base.probes + tuple(
        Probe(f"w_top_{i:03d}", "top", float(i) + 0.37) for i in range(300)))
    return base, many


def test_the_mesh_does_not_depend_on_the_probes(scenes):
    base, many = scenes
    a, b = beam_mesh(base, 60), beam_mesh(many, 60)
    assert np.array_equal(a.x, b.x)


def test_many_probes_leave_the_answer_as_it_is(scenes):
    base, many = scenes
    one = run(dataclasses.replace(base, beam_model=dataclasses.replace(
        base.beam_model, elements=60, core=2))).solution
    lots = run(dataclasses.replace(many, beam_model=dataclasses.replace(
        many.beam_model, elements=60, core=2))).solution
    for name, value in one.history[-1].probes.items():
        assert lots.history[-1].probes[name] == pytest.approx(value, rel=1e-12, abs=1e-12)
    w = np.array([lots.history[-1].probes[f"w_top_{i:03d}"] for i in range(300)])
    assert np.all(np.isfinite(w)) and w.min() < 0  # the top face goes down under the load
    # the deflection at mid-span read between nodes is close to the one read at the node
    mid = one.history[-1].probes["w_top_mid"]
    assert lots.history[-1].probes["w_top_149"] == pytest.approx(mid, rel=0.02)
