"""Round trip: sandwich.results.write_solution → sandwich.results.load_result."""

import numpy as np
import pytest

from sandwich.results import ResultMissing, load_result, write_solution


def test_round_trip_keeps_every_field(tmp_path, synth):
    sol = synth.make_solution("beam", eps=0.01, n_steps=20, n_x=11, profile_steps=(4, -1),
                              wall=2.5, dofs=1234)
    write_solution(sol, tmp_path / "r")
    back = load_result(tmp_path / "r")
    assert (back.model, back.scene, back.converged, back.message, back.dofs) == (
        "beam", "synthetic", True, "reached until probe", 1234)
    assert back.wall_seconds == 2.5
    assert len(back.history) == 20
    for a, b in zip(sol.history, back.history, strict=True):
        assert (a.step, a.load_factor, a.probes, a.iterations, a.extra) == (
            b.step, b.load_factor, b.probes, b.iterations, b.extra)
    assert [p.step for p in back.profiles] == [5, 20]
    for a, b in zip(sol.profiles, back.profiles, strict=True):
        assert set(b.columns) == set(a.columns)  # p_contact_top survives
        for k in a.columns:
            np.testing.assert_array_equal(a.columns[k], b.columns[k])
    assert [(lp.kind, lp.step, lp.load_factor, lp.probes) for lp in back.limit_points] == [
        (lp.kind, lp.step, lp.load_factor, lp.probes) for lp in sol.limit_points]
    assert back.extra == {"level": "medium"}


def test_missing_file_is_named(tmp_path, synth):
    write_solution(synth.make_solution("2d", n_steps=3, n_x=5), tmp_path / "r")
    (tmp_path / "r" / "profiles.csv").unlink()
    with pytest.raises(ResultMissing, match="profiles.csv"):
        load_result(tmp_path / "r")


def test_malformed_history_names_file_and_line(tmp_path, synth):
    write_solution(synth.make_solution("2d", n_steps=3, n_x=5), tmp_path / "r")
    hist = tmp_path / "r" / "history.csv"
    hist.write_text(hist.read_text() + "4,1.0\n")
    with pytest.raises(ValueError, match=r"history.csv:5"):
        load_result(tmp_path / "r")
