"""What a study reports: the per-case numbers, the knock-down crossing, the 2D check selection.

Synthetic solutions and tables with hand-computed answers (no model run).
"""

from pathlib import Path

import numpy as np
import pytest

from sandwich.results import LimitPoint, Profile, Solution, StepRecord
from sandwich.scene_file import load_scene
from sandwich.studies.study_check import check_errors, corners, select_checks
from sandwich.studies.study_file import load_study
from sandwich.studies.study_metrics import case_metrics, contact_length
from sandwich.studies.study_report import crossings, rows

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
TINY = HERE / "tiny.toml"  # 3 lengths (0, 30, 60) x 2 centres (130, 150)


def _solution(converged=True, limits=()):
    hist = [StepRecord(0, 0.0, {"w_top_mid": 0.0, "w_bottom_mid": 0.0}, 0),
            StepRecord(1, 50.0, {"w_top_mid": -0.25, "w_bottom_mid": -0.2}, 3),
            StepRecord(2, 400.0, {"w_top_mid": -3.0, "w_bottom_mid": -2.9}, 4)]
    x = np.linspace(0.0, 300.0, 301)
    szz = np.where(np.abs(x - 150) <= 1, -8.0, -1.0)  # a 2-mm spike of -8 on -1
    cols = {"x": x, "w_top": 0 * x, "w_bottom": 0 * x, "sigma_zz_top": szz,
            "sigma_zz_bottom": 0 * x, "tau_core": np.where(x < 150, 0.5, -0.5),
            "p_contact_top": np.where((x >= 100) & (x <= 120), 2.0, 0.0),
            "p_contact_bottom": 0 * x}
    return Solution("beam", "s", hist, [Profile(2, cols)], converged, "reached", list(limits),
                    1.5, 10)


def test_case_numbers_from_a_solution():
    scene = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")  # F = -1 N
    lp = LimitPoint("bifurcation", 2, 400.0, {"w_top_mid": -3.0})
    m = case_metrics(scene, _solution(limits=[lp]))
    assert m["initial_stiffness"] == pytest.approx(50.0 * 1.0 / 0.25)  # λ1 |F| / |w1|
    assert m["first_limit_load"] == 400.0 and m["first_limit_w"] == -3.0
    assert m["capacity"] == 400.0 and m["load_at_until"] == 400.0
    assert m["peak_sigma_zz"] == -8.0
    # 5-mm window [147.5, 152.5] of the piecewise-linear profile: -8 on [149, 151] (2 mm),
    # ramps of mean -4.5 on [148, 149] and [151, 152], -1 on the two 0.5-mm ends:
    # (-0.5 - 4.5 - 16 - 4.5 - 0.5) / 5 = -5.2
    assert m["peak_sigma_zz_5mm"] == pytest.approx(-5.2, abs=1e-9)
    assert abs(m["peak_tau_core"]) == 0.5
    # pressure on the samples x = 100..120 (1-mm spacing): the trapezoid of the contact flag
    # counts [100, 120] and half of each 1-mm transition segment: 20 + 2 x 0.5 = 21 mm
    assert m["contact_length"] == pytest.approx(21.0)


def test_capacity_without_limit_point_is_the_load_at_the_target_and_none_if_stopped():
    scene = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    m = case_metrics(scene, _solution())
    assert m["first_limit_load"] is None and m["capacity"] == 400.0
    m = case_metrics(scene, _solution(converged=False))
    assert m["load_at_until"] is None and m["capacity"] is None


def test_core_crushed_load_is_the_first_state_whose_core_lost_ellipticity():
    """The 2D model's history column ``core_ellipticity`` (≤ 0: crushed); the beam has none."""
    scene = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    sol = _solution()
    assert case_metrics(scene, sol)["core_crushed_load"] is None  # no column: the beam
    for r, q in zip(sol.history, (1.0, 0.3, 0.3), strict=True):
        r.extra["core_ellipticity"] = q
    assert case_metrics(scene, sol)["core_crushed_load"] is None  # never crushed
    sol.history[1].extra["core_ellipticity"] = 0.0  # at 0 the material has lost it
    sol.history[2].extra["core_ellipticity"] = -0.2
    assert case_metrics(scene, sol)["core_crushed_load"] == 50.0
    e = check_errors({"capacity": 110.0}, {"capacity": 100.0, "core_crushed_load": 50.0})
    assert e["2d_core_crushed_load"] == 50.0


def test_contact_length_is_none_for_a_model_without_contact_columns():
    sol = _solution()
    del sol.profiles[0].columns["p_contact_top"], sol.profiles[0].columns["p_contact_bottom"]
    assert contact_length(sol) is None


def test_corners_of_a_3_by_2_grid():
    study = load_study(TINY)
    assert sorted(corners(study)) == [0, 1, 4, 5]  # index = length position x 2 + centre


def test_check_selection_takes_the_largest_indicators_then_the_corners():
    study = load_study(TINY)
    ind = {0: 0.001, 1: 0.002, 2: 0.05, 3: 0.04, 4: 0.01, 5: 0.003}
    recs = {i: {"status": "done", "indicator": v} for i, v in ind.items()}
    assert select_checks(study, recs, 4) == [2, 3, 0, 1]  # 2 by indicator, 2 corners
    assert select_checks(study, recs, 1) == [2]
    recs[2]["status"] = "failed"  # never picked
    assert select_checks(study, recs, 3) == [3, 4, 0]
    assert sorted(select_checks(study, recs, 10)) == [0, 1, 3, 4, 5]  # all that can be


def test_check_errors_are_relative_to_the_2d_value():
    e = check_errors({"capacity": 110.0, "initial_stiffness": 9.0},
                     {"capacity": 100.0, "initial_stiffness": 10.0, "status": "done"})
    assert e["error_capacity"] == pytest.approx(0.10)
    assert e["error_initial_stiffness"] == pytest.approx(-0.10)
    assert e["error_load_at_until"] is None


def test_knockdown_and_its_crossing_by_linear_interpolation():
    study = load_study(TINY)  # reference length = 0, threshold 0.8
    cap = {0: 1000.0, 1: 1000.0, 2: 900.0, 3: 700.0, 4: 500.0, 5: 400.0}
    recs = {i: {"status": "done", "capacity": v} for i, v in cap.items()}
    table = rows(study, recs)
    assert [r["knockdown"] for r in table] == pytest.approx([1, 1, 0.9, 0.7, 0.5, 0.4])
    cross = {c["centre"]: c["at"] for c in crossings(study, table)}
    # centre 130: 0.9 at 30, 0.5 at 60 -> 0.8 at 30 + 30 x 0.1/0.4 = 37.5
    # centre 150: 1.0 at 0, 0.7 at 30 -> 0.8 at 0 + 30 x 0.2/0.3 = 20
    assert cross[130] == pytest.approx(37.5) and cross[150] == pytest.approx(20.0)
