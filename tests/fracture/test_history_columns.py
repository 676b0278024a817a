"""The G columns survive an interrupted run, are never NaN, and are empty where not evaluated.

References: an interrupted run must write, for the steps it kept, the same G columns as the
complete run of the same scene writes for those steps (the same states; the complete run's
columns are checked against closed form in test_beam_release / test_vcct_2d). An empty cell
means "not evaluated" and must come with a ``G_warning``.
"""

import csv
import json

import pytest

from benchmarks.cases.fracture_cases import peel_g, peel_loads, scene
from sandwich.fracture import growth_onset, missing_releases
from sandwich.models import run_model
from sandwich.results import Solution, StepRecord, load_result, write_solution

COLS = ("G_0_end", "GI_0_end", "GII_0_end")


def _interrupting(solve, after):
    """``solve`` that raises KeyboardInterrupt once ``after`` path states were reported."""
    def run(sc, progress=None):
        seen = []

        def on_state(state):
            if progress is not None:
                progress(state)
            if getattr(state, "probes", None) is not None:
                seen.append(state.step)
                if len(seen) > after:
                    raise KeyboardInterrupt("test")
        return solve(sc, on_state)
    return run


def _rows(folder):
    with open(folder / "history.csv") as fh:
        return list(csv.DictReader(fh))


def _check_interrupted_against_complete(model, sc, tmp_path, after=3):
    full = run_model(sc, model, tmp_path / "full")
    from sandwich.models.registry import get_model

    with pytest.raises(KeyboardInterrupt):
        run_model(sc, model, tmp_path / "cut", solver=_interrupting(get_model(model).solve, after))
    cut, whole = _rows(tmp_path / "cut"), _rows(tmp_path / "full")
    assert len(cut) == after + 1 and len(whole) > len(cut)
    summary = json.loads((tmp_path / "cut" / "summary.json").read_text())
    assert summary["converged"] is False and "interrupted" in summary["message"]
    assert "G_warning" not in summary  # every kept step has its G
    for a, b in zip(cut, whole, strict=False):
        assert a["step"] == b["step"]
        for c in COLS:
            assert a[c] != "" and float(a[c]) == pytest.approx(float(b[c]), rel=1e-9, abs=1e-15)
    last = cut[-1]
    lam = float(last["load_factor"])
    assert float(last["G_0_end"]) == pytest.approx(peel_g(sc, lam), rel=0.02)  # closed form
    return full


def test_interrupted_beam_run_keeps_the_g_columns(tmp_path):
    sc = scene(peel_loads(), elements=120)
    _check_interrupted_against_complete("beam", sc, tmp_path)


@pytest.mark.dolfinx
def test_interrupted_2d_run_keeps_the_g_columns(tmp_path):
    sc = scene(peel_loads())
    _check_interrupted_against_complete("2d", sc, tmp_path)


def test_empty_g_cell_is_written_blank_read_as_none_and_skipped_by_the_criterion(tmp_path):
    """A G that could not be evaluated: blank cell, None in memory, never NaN, never 0."""
    import dataclasses

    from sandwich.scene import Toughness

    base = scene(peel_loads())
    sc = dataclasses.replace(base, debonds=(dataclasses.replace(
        base.debonds[0], toughness=Toughness(GIc=0.1, GIIc=0.4, eta=2.0)),))
    hist = [StepRecord(0, 0.0, {"w0": 0.0}, 0, {"G_0_end": 0.0, "GI_0_end": 0.0,
                                                 "GII_0_end": 0.0, "cuts": 0.0}),
            StepRecord(1, 1.0, {"w0": 0.1}, 3, {"G_0_end": None, "GI_0_end": None,
                                                 "GII_0_end": None}),
            StepRecord(2, 2.0, {"w0": 0.2}, 3, {"G_0_end": 0.5, "GI_0_end": 0.5,
                                                 "GII_0_end": 0.0, "cuts": 1.0})]
    sol = Solution("beam", sc.name, hist, [], False, "test", [], 0.0, 0)
    write_solution(sol, tmp_path / "r")
    rows = _rows(tmp_path / "r")
    assert [r["G_0_end"] for r in rows] == ["0.0", "", "0.5"]
    assert rows[1]["cuts"] == "0.0"  # other columns keep their 0 default
    back = load_result(tmp_path / "r").history
    assert back[1].extra["G_0_end"] is None and back[2].extra["G_0_end"] == 0.5
    onset = growth_onset(sc, back)["0_end"]
    assert onset["step"] == 2 and onset["max_G_over_Gc"] == pytest.approx(5.0)
    assert missing_releases(back).startswith("G_0_end at step(s) 1")


@pytest.mark.dolfinx
def test_linear_2d_run_leaves_g_empty_and_says_why():
    """The linear 2D solve ties the lips (contact linearised at closed lips): no G then.

    Measured on the peel couple: the linear run's G (as it was written before) was 0.07 of the
    closed form at a 12x larger load factor for the same probe value; the nonlinear run is
    within 0.2 %.
    """
    import dataclasses

    from sandwich.plane2d import solve

    sc = scene(peel_loads())
    lin = dataclasses.replace(sc, analysis=dataclasses.replace(sc.analysis, kind="linear"))
    sol = solve(lin)
    assert all(r.extra[c] is None for r in sol.history for c in COLS)
    assert "ties the debond lips" in sol.extra["G_warning"]
    nonlinear = solve(sc)
    assert sol.history[-1].load_factor > 5 * nonlinear.history[-1].load_factor  # tied: stiff
