"""The gallery agreement table (sandwich.compare.agreement) on gallery folders of known answer.

The synthetic solvers of ``cmp_synthetic`` give a beam path that is the 2D path scaled by
(1 + EPS) in load: the end load, the first maximum and the load-curve errors must read EPS, at
the common end of both paths, also when the beam stops early.
"""

import dataclasses

import pytest

from sandwich.compare import compare
from sandwich.compare.agreement import markdown, scene_row

EPS = 0.03


def _gallery_scene(tmp_path, scene, solvers):
    folder = tmp_path / "gallery" / scene.name
    compare(scene, folder, solvers=solvers)
    return folder


def test_row_reads_the_known_error_at_the_path_end(tmp_path, scene, synth):
    folder = _gallery_scene(tmp_path, scene, synth.fake_solvers(EPS))
    row = scene_row(folder, {scene.name: "yes, by construction"})
    assert row["w_end"] == pytest.approx(abs(synth.W_END))
    assert row["end_load_rel"] == pytest.approx(EPS, abs=1e-9)  # both paths sample w_end
    assert row["beam_load_at_w_end"] == pytest.approx(
        (1 + EPS) * synth.load_of(synth.W_END), rel=1e-9)
    _, lam_max = synth.analytic_limit()
    assert row["2d_first_max"] == pytest.approx(lam_max, rel=1e-3)
    assert row["first_max_rel"] == pytest.approx(EPS, abs=2e-3)
    assert row["load_l2"] == pytest.approx(EPS, abs=5e-4)
    assert row["beam_message"] == "" and row["2d_message"] == ""
    assert row["trust_2d"] == "yes, by construction"
    text = markdown([row], "DIR", "header words")
    assert "+3.00 %" in text and "header words" in text and "yes, by construction" in text
    assert "nan" not in text.lower()


def test_an_early_stop_moves_the_common_end_and_is_reported(tmp_path, scene, synth):
    solvers = synth.fake_solvers(EPS)
    full_beam = solvers["beam"]

    def stopped_beam(sc, progress=None):
        sol = full_beam(sc, progress)
        return dataclasses.replace(sol, history=sol.history[:40], converged=False,
                                   message="step 41: no convergence (synthetic)",
                                   limit_points=[])

    folder = _gallery_scene(tmp_path, scene, {**solvers, "beam": stopped_beam})
    row = scene_row(folder)
    reach = 40 / 97 * abs(synth.W_END)  # the beam's 40th of 97 equal steps to |W_END|
    assert row["beam_reach"] == pytest.approx(reach)
    assert row["2d_reach"] == pytest.approx(abs(synth.W_END))
    assert row["w_end"] == pytest.approx(reach)
    # the 2D load at w_end is interpolated between its 0.1 mm samples of a cubic: ~1e-5 off
    assert row["end_load_rel"] == pytest.approx(EPS, abs=1e-4)
    assert "no convergence (synthetic)" in row["beam_message"]
    assert row["beam_first_max"] is None and row["first_max_rel"] is None
    assert row["trust_2d"] == "not assessed"
    assert "no convergence (synthetic)" in markdown([row], "DIR", "")


def test_fine_check_tells_the_2d_mesh_error_from_the_beams(tmp_path, scene, synth):
    """A "finer" 2D run 2 % below the gallery's 2D: the gallery 2D reads +2 % on it and the
    beam (1 + EPS)/(1 − 0.02) − 1; a finer path that stops short gives None, not a number."""
    from sandwich.compare.agreement import fine_check

    folder = _gallery_scene(tmp_path, scene, synth.fake_solvers(EPS))
    finer = synth.make_solution("2d", eps=-0.02, n_steps=300, scene=scene.name)
    row = fine_check(scene_row(folder), finer)
    assert row["2d_fine_level"] == "medium"  # the synthetic runs' recorded level
    assert row["2d_rel_fine"] == pytest.approx(1 / 0.98 - 1, abs=1e-9)
    assert row["end_load_rel_fine"] == pytest.approx(1.03 / 0.98 - 1, abs=1e-9)
    assert "Against a finer 2D mesh" in markdown([row], "DIR", "")
    short = dataclasses.replace(finer, history=finer.history[:100])
    row = fine_check(scene_row(folder), short)
    assert row["2d_fine_load_at_w_end"] is None and row["end_load_rel_fine"] is None
    assert "nan" not in markdown([row], "DIR", "").lower()
