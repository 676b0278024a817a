"""Plumbing of the sweeps tradeoff and extremes (benchmarks.sweeps), synthetic solvers."""

import dataclasses
import math

import pytest

from benchmarks.sweeps import extremes, tradeoff


def test_tradeoff_errors_front_and_headline(tmp_path, scene, synth):
    # synthetic convergence: the end load misses the exact one by 8/n (beam) and 4/level² (2D)
    exact = synth.make_solution("2d").final_load_factor
    level_err = {"coarse": 0.04, "medium": 0.01, "fine": 0.0025}

    def ref(sc, level, refine):
        return synth.make_solution("2d", eps=level_err[level] * 0.5 ** refine, scene=sc.name)

    def beam(sc):
        return synth.make_solution("beam", eps=8.0 / sc.beam_model.elements, scene=sc.name)

    runs = tradeoff.measure(scene, beam, ref, [20, 100, 1000], ["coarse", "medium", "fine"], [0])
    errs = {(r.model, r.resolution): r.error for r in runs}
    fine = exact * (1 + 0.0025)
    assert errs[("2d", "fine+0")] == 0.0
    assert errs[("2d", "coarse+0")] == pytest.approx(abs(exact * 1.04 - fine) / fine)
    assert errs[("beam", "1000")] == pytest.approx(abs(exact * 1.008 - fine) / fine)
    assert tradeoff.cheapest(runs, "beam").resolution == "1000"  # 100: 7.7 % > 1 %
    assert tradeoff.cheapest(runs, "2d").error <= 0.01
    assert "2D/beam time ratio" in tradeoff.headline(runs, scene.name)
    tradeoff.write(runs, [tradeoff.headline(runs, scene.name)], tmp_path)
    for f in ("tradeoff.csv", "tradeoff.md", "tradeoff.png"):
        assert (tmp_path / f).is_file()
    assert "nan" not in (tmp_path / "tradeoff.csv").read_text().lower()


def test_tradeoff_says_when_beam_never_reaches_one_percent(scene, synth):
    runs = tradeoff.measure(
        scene, lambda sc: synth.make_solution("beam", eps=0.05),
        lambda sc, level, refine: synth.make_solution("2d"), [10], ["coarse"], [0])
    assert "1 % not reached by beam" in tradeoff.headline(runs, scene.name)


def test_extremes_cases_rows_and_map(tmp_path, scene, synth):
    made = {(sw, v): sc for sw, v, sc in extremes.cases(scene, list(extremes.SWEEPS))}
    assert len(made) == sum(len(v) for v in extremes.SWEEPS.values())
    slender = made[("slenderness", 100)]
    assert slender.length == pytest.approx(100 * scene.total_height)
    assert slender.loads[0].x == pytest.approx(slender.length / 2)
    assert made[("stiffness", 1e-4)].core.material.Ez == pytest.approx(
        1e-4 * scene.top.material.Ex)
    assert made[("thickness", 500)].top.thickness == pytest.approx(scene.core.thickness / 500)
    long = made[("debond", 0.9)].debonds[0]
    assert (long.start, long.end) == pytest.approx((0.05 * scene.length, 0.95 * scene.length))

    # the map's rows from outcomes as the study engine stores them (studies/extremes.outcome)
    beam = extremes.Outcome("beam", "converged", synth.make_solution("beam", eps=0.02))
    rows = [extremes.row("load", 1.0, made[("load", 1.0)],
                         {"beam": beam, "2d": extremes.Outcome("2d", "converged",
                                                              synth.make_solution("2d"))}),
            extremes.row("debond", 0.3, made[("debond", 0.3)],
                         {"beam": beam, "2d": extremes.Outcome("2d", "failed", None,
                                                              "RuntimeError: diverged at step 2")}),
            extremes.row("slenderness", 1000, made[("slenderness", 1000)],
                         {"beam": beam, "2d": extremes.Outcome(
                             "2d", "skipped", None, "2D mesh has 99999 cells, above the budget")})]
    assert rows[0]["load_l2"] == pytest.approx(0.02, abs=5e-4)
    assert rows[0]["beam_cuts"] == 0  # Outcome's cuts: as the engine recorded them
    assert rows[0]["2d_status"] == "converged" and rows[0]["common"] == pytest.approx(1.0)
    assert rows[1]["2d_status"] == "failed" and "diverged at step 2" in rows[1]["2d_note"]
    assert rows[1]["load_l2"] is None and "2D has no converged state" in rows[1]["agree_note"]
    assert rows[2]["2d_status"] == "skipped" and "99999 cells" in rows[2]["2d_note"]
    extremes.write(rows, tmp_path)
    text = (tmp_path / "extremes.md").read_text()
    assert "| load | 1 | ✓ | ✓ |" in text and "| debond | 0.3 | ✓ | ✗! |" in text
    assert "| slenderness | 1000 | ✓ | – |" in text and "99999 cells" in text
    assert not any(isinstance(v, float) and math.isnan(v) for r in rows for v in r.values())
    assert (tmp_path / "extremes.png").is_file()
    assert "nan" not in (tmp_path / "extremes.csv").read_text().lower()


def test_extremes_outcome_from_a_study_record(tmp_path, scene, synth):
    """A stored case (record + result set) read back as the map's outcome."""
    from sandwich.results import write_solution

    sol = synth.make_solution("beam")
    write_solution(sol, tmp_path / "case")
    got = extremes.outcome("beam", {"status": "done", "reason": "", "wall_seconds": 2.5},
                           tmp_path / "case")
    assert got.status == "converged" and got.seconds == 2.5
    assert [r.load_factor for r in got.solution.history] == pytest.approx(
        [r.load_factor for r in sol.history])
    stopped = extremes.outcome("2d", {"status": "timeout", "reason": "cap"}, tmp_path / "none")
    assert stopped.status == "timeout" and stopped.solution is None
    assert extremes.outcome("2d", None, tmp_path).status == "missing"


def test_extremes_agreement_over_the_common_range_when_a_model_stops_early(scene, synth):
    full = synth.make_solution("2d")
    beam = synth.make_solution("beam", eps=0.05)
    half = dataclasses.replace(beam, history=beam.history[:75], converged=False)  # to −7.5 mm
    a = extremes.agreement(scene, half, full)
    assert a["common"] == pytest.approx(0.5, abs=1e-9)
    assert a["load_l2"] == pytest.approx(0.05, rel=1e-6)  # exact: beam = 2D × 1.05 at samples
    assert a["end_error"] == pytest.approx(0.05, rel=1e-6)
    assert a["load_l2_lin"] == pytest.approx(0.05, rel=1e-3)
    assert "beam stopped early" in a["agree_note"] and "50 %" in a["agree_note"]


def test_tradeoff_variants_set_the_core_level(scene):
    """``paper``/``averaged`` are the paper's element (level 1, the paper's faces and same-x
    contact; membrane as named), ``L<k>`` level k and ``auto`` auto with the scene defaults."""
    paper = ("paper", "same-x")
    default = ("stretch", "closest-point")
    cases = {"paper": (1, "paper", paper), "averaged": (1, "averaged", paper),
             "L3": (3, "averaged", default), "auto": ("auto", "averaged", default)}
    for variant, (core, membrane, (faces, search)) in cases.items():
        bm = tradeoff.with_beam_elements(scene, 30, variant).beam_model
        assert (bm.core, bm.face_membrane, bm.elements, bm.faces, bm.contact_search) == (
            core, membrane, 30, faces, search), variant


def test_tradeoff_warm_up_solves_each_model_once_at_the_cheapest_setting():
    # the process's first 2D solve pays dolfinx's imports: warm_up runs it (and the beam) once,
    # untimed, at the first level and the smallest element count, with the scene's until
    calls = []

    def beam(sc):
        calls.append(("beam", sc.beam_model.elements, sc.analysis.until_value))

    def ref(sc, level, refine):
        calls.append(("2d", level, refine, sc.analysis.until_value))

    tradeoff.warm_up("paper-fig4-bonded-3pb", "coarse", "L2", [240, 120],
                     {"paper-fig4-bonded-3pb": -12.0}, beam, ref)
    assert calls == [("2d", "coarse", 0, -12.0), ("beam", 120, -12.0)]
