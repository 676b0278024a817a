"""Crack-length-controlled growth on a stand-in model whose G is known in closed form.

The stand-in's paths are states at λ = 0, h, 2h, … up to the scene's target, with
G(a, λ) = k (a λ)^n at both tips of debond 0 (a its length) and a fixed mode mix ψ: the onset
at length a is λ_c(a) = (G_c(ψ) / k)^(1/n) / a exactly, which the tests compare with.
n = 2 is a linear response (r = √(G/G_c) linear in λ: interpolation is exact); n = 4 needs the
onset solved for (a path stopped on it).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from sandwich.fracture import bk_toughness
from sandwich.growth import grow, onset_rows
from sandwich.growth.locate import ONSET_RTOL
from sandwich.results import Solution, StepRecord
from sandwich.scene import Growth, Toughness
from sandwich.scene_checks import build_scene

PSI = 0.25  # G_II / G of the stand-in
K = 1e-6


def _scene(kind="linear", step=4.0, max_length=None, start=130.0, end=170.0, until=400.0,
           tough=(0.02, 0.08)):
    data = {
        "name": "growth-check", "description": "stand-in growth",
        "beam": {"length": 300.0, "width": 60.0},
        "layers": {"top": {"thickness": 0.5, "material": "f"},
                   "core": {"thickness": 25.0, "material": "c"},
                   "bottom": {"thickness": 0.5, "material": "f"}},
        "materials": {"f": {"E": 27420.0, "nu": 0.3}, "c": {"E": 52.5, "nu": 0.25}},
        "supports": [{"x": 0.0, "on": "bottom", "type": "pin"},
                     {"x": 300.0, "on": "bottom", "type": "roller"}],
        "loads": [{"on": "top", "x": 150.0, "width": 10.0, "force": -1.0}],
        "debonds": [{"interface": "top", "start": start, "end": end,
                     "toughness": {"GIc": tough[0], "GIIc": tough[1]},
                     "growth": {"step": step,
                                **({} if max_length is None else {"max_length": max_length})}}],
        "probes": [{"name": "w", "on": "top", "x": 150.0}],
        "analysis": {"kind": kind, "control": "load", "until": {"load_factor": until}},
    }
    return build_scene(data, "<growth-check>")


def _stand_in(n: int, calls: list, h: float = 40.0, asymmetric: float = 1.0, k: float = K):
    """solve(scene, progress) of the stand-in; ``asymmetric`` scales the start tip's G."""

    def solve(scene, progress=None):
        calls.append(scene)
        d = scene.debonds[0]
        a = d.length
        top = scene.analysis.until_load_factor
        lams = [min(k * h, top) for k in range(int(math.ceil(top / h)) + 1)]
        rows = []
        for j, lam in enumerate(lams):
            g = k * (a * lam) ** n
            extra = {}
            for tip, s in (("end", 1.0), ("start", asymmetric)):
                extra.update({f"G_0_{tip}": s * g, f"GI_0_{tip}": s * (1 - PSI) * g,
                              f"GII_0_{tip}": s * PSI * g})
            rows.append(StepRecord(j, lam, {"w": -lam / 100.0}, 3, extra))
            if progress is not None:
                progress(rows[-1])
        return Solution("stand-in", scene.name, rows, [], True, "reached", [], 0.0, 10)

    return solve


def _gc(scene):
    t: Toughness = scene.debonds[0].toughness
    return bk_toughness(t, 1 - PSI, PSI)


def test_linear_onsets_are_the_closed_form_at_every_length_and_both_tips_advance():
    sc = _scene(kind="linear", step=4.0, max_length=60.0)
    calls = []
    sol = grow(sc, _stand_in(2, calls))
    onsets = onset_rows(sol.history)
    lengths = [r.extra["tip_0_end"] - r.extra["tip_0_start"] for r in onsets]
    assert lengths == [40.0, 48.0, 56.0]  # both tips reach G_c together: 8 mm per stage
    for r, a in zip(onsets, lengths, strict=True):
        assert r.load_factor == pytest.approx(math.sqrt(_gc(sc) / K) / a, rel=1e-12)
        assert r.extra["G_0_end"] == pytest.approx(_gc(sc), rel=1e-12)
        assert r.extra["GII_0_end"] / r.extra["G_0_end"] == pytest.approx(PSI, rel=1e-12)
    assert len(calls) == 3  # a linear response needs no path stopped on the onset
    summary = sol.extra["debond_growth"]
    assert summary["first_growth_load"] == pytest.approx(onsets[0].load_factor)
    assert summary["residual_strength"] == pytest.approx(onsets[0].load_factor)
    assert summary["unstable_steps"] == 2 and summary["stable_steps"] == 0
    assert summary["arrest_at_first_growth_load"] is None  # λ_c falls: runs through
    assert summary["debonds"]["0"]["to"] == [122.0, 178.0]
    assert "max_length 60" in sol.message


def test_nonlinear_onsets_are_solved_for_within_the_tolerance():
    sc = _scene(kind="nonlinear", step=4.0, max_length=52.0)
    k4 = _gc(sc) / (250.0 * 40.0) ** 4  # λ_c = 250 at 40 mm, inside the step 240-280
    calls = []
    sol = grow(sc, _stand_in(4, calls, k=k4))
    onsets = onset_rows(sol.history)
    assert len(onsets) == 2
    assert not sol.warnings
    for r in onsets:
        a = r.extra["tip_0_end"] - r.extra["tip_0_start"]
        exact = (_gc(sc) / k4) ** 0.25 / a
        # r within ONSET_RTOL of 1 and r ∝ λ²: the load within about half of it
        assert r.load_factor == pytest.approx(exact, rel=0.6 * ONSET_RTOL)
        assert abs(math.sqrt(r.extra["G_0_end"] / r.extra["Gc"]) - 1) <= ONSET_RTOL
    assert len(calls) > 2  # the onsets were solved for by paths stopped on them
    assert any(c.analysis.until_load_factor not in (400.0,) for c in calls)


def test_the_tip_reaching_g_c_first_advances_alone():
    sc = _scene(kind="linear", step=2.0, max_length=46.0)
    sol = grow(sc, _stand_in(2, [], asymmetric=0.5))  # the start tip has half the G
    tips = [(r.extra["tip_0_start"], r.extra["tip_0_end"]) for r in onset_rows(sol.history)]
    assert tips == [(130.0, 170.0), (130.0, 172.0), (130.0, 174.0), (130.0, 176.0)]


def test_growth_stops_a_step_short_of_a_beam_end():
    sc = _scene(kind="linear", step=10.0, start=230.0, end=260.0)
    sol = grow(sc, _stand_in(2, [], asymmetric=0.0))  # only the end tip grows
    ends = [r.extra["tip_0_end"] for r in onset_rows(sol.history)]
    assert ends == [260.0, 270.0, 280.0, 290.0]  # one more step would reach the beam end
    assert "beam end" in sol.message


def test_a_length_that_needs_more_load_than_the_scene_applies_arrests_the_debond():
    # a stand-in whose G falls with the length, G = c λ² / a²: λ_c(a) = a √(G_c / c) rises
    sc = _scene(kind="linear", step=4.0, until=398.0)
    c = 0.1 / 6.25**2  # λ_c = 6.25 a: 250 at 40 mm, … 375 at 60, 400 at 64 (beyond 398)

    def solve(scene, progress=None):
        a = scene.debonds[0].length
        g = [c * lam**2 / a**2 for lam in (0.0, 398.0)]
        rows = [StepRecord(j, lam, {"w": -lam / 100}, 1,
                           {"G_0_end": gj, "GI_0_end": gj, "GII_0_end": 0.0})
                for j, (lam, gj) in enumerate(zip((0.0, 398.0), g, strict=True))]
        return Solution("stand-in", scene.name, rows, [], True, "reached", [], 0.0, 10)

    sc = dataclasses.replace(sc, debonds=(dataclasses.replace(
        sc.debonds[0], toughness=Toughness(0.1, 0.1), growth=Growth(4.0, None)),))
    sol = grow(sc, solve)
    onsets = onset_rows(sol.history)
    assert [r.load_factor for r in onsets] == pytest.approx([6.25 * a for a in range(40, 64, 4)],
                                                            rel=1e-12)
    summary = sol.extra["debond_growth"]
    assert summary["stable_steps"] == len(onsets) - 1 and summary["unstable_steps"] == 0
    assert summary["bounded"] is False  # the path at the arrested length reaches the target
    assert "no tip reaches G_c" in sol.message
    assert sol.history[-1].load_factor == 398.0  # the arrested length's path to its end
    assert sol.history[-1].extra["tip_0_end"] == 194.0
    assert summary["arrest_at_first_growth_load"]["tip_0_end"] == 174.0  # 44 mm: needs 275


def test_a_failing_path_keeps_the_stages_before_it():
    sc = _scene(kind="linear", step=4.0, max_length=80.0)
    ok = _stand_in(2, [])
    count = []

    def solve(scene, progress=None):
        count.append(1)
        if len(count) == 3:
            raise RuntimeError("the corrector diverged")
        return ok(scene, progress)

    sol = grow(sc, solve)
    assert len(onset_rows(sol.history)) == 2
    assert not sol.converged and "the corrector diverged" in sol.message


def test_an_interrupted_growth_run_keeps_its_onsets_and_tip_positions(tmp_path):
    import csv
    import json

    from sandwich.models import run_model

    sc = _scene(kind="linear", step=4.0, max_length=80.0)
    ok = _stand_in(2, [])
    count = []

    def solve(scene, progress=None):
        count.append(1)
        if len(count) == 3:
            raise KeyboardInterrupt
        return ok(scene, progress)

    with pytest.raises(KeyboardInterrupt):
        run_model(sc, "beam", tmp_path / "out", solver=solve)
    rows = list(csv.DictReader((tmp_path / "out" / "history.csv").open()))
    assert [(float(r["tip_0_start"]), float(r["tip_0_end"])) for r in rows] == [
        (130.0, 170.0), (126.0, 174.0)]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["converged"] is False
    growth = summary["debond_growth"]
    assert growth["onsets"] == 2 and growth["debonds"]["0"]["to"] == [126.0, 174.0]
    assert growth["first_growth_load"] == pytest.approx(float(rows[0]["load_factor"]))


def test_a_path_without_g_at_the_tips_stops_the_growth_and_says_why():
    sc = _scene(kind="linear", step=4.0)

    def solve(scene, progress=None):
        rows = [StepRecord(j, lam, {"w": 0.0}, 1, {"G_0_end": None, "GI_0_end": None,
                                                    "GII_0_end": None})
                for j, lam in enumerate((0.0, 400.0))]
        sol = Solution("stand-in", scene.name, rows, [], True, "reached", [], 0.0, 10)
        sol.extra["G_warning"] = "linear analysis: the lips are tied"
        return sol

    sol = grow(sc, solve)
    assert not sol.converged
    assert "gives no G" in sol.message and "lips are tied" in sol.message
    assert sol.extra["debond_growth"]["first_growth_load"] is None


def test_a_load_maximum_before_the_onset_is_the_residual_strength():
    # every length's path rises to λ 300 and falls again while G keeps growing with the
    # probe: the onset lies past the maximum, which the panel must carry first
    sc = _scene(kind="nonlinear", step=4.0, max_length=44.0, until=1000.0)
    sc = dataclasses.replace(sc, analysis=dataclasses.replace(
        sc.analysis, until_load_factor=None, until_probe="w", until_value=-10.0))

    def solve(scene, progress=None):
        target = scene.analysis.until_value
        w = [-0.5 * k for k in range(int(round(-target / 0.5)) + 1)]
        if w[-1] != target:
            w.append(target)
        rows = []
        for j, wj in enumerate(w):
            lam = 300.0 - 30.0 * (wj + 3.0) ** 2 / 2.5  # maximum 300 at w = −3
            g = 0.004 * wj**2 * scene.debonds[0].length / 40.0
            rows.append(StepRecord(j, lam, {"w": wj}, 1,
                                   {"G_0_end": g, "GI_0_end": g, "GII_0_end": 0.0}))
        return Solution("stand-in", scene.name, rows, [], True, "reached", [], 0.0, 10)

    sc = dataclasses.replace(sc, debonds=(dataclasses.replace(
        sc.debonds[0], toughness=Toughness(0.1, 0.1), growth=Growth(4.0, 44.0)),))
    sol = grow(sc, solve)
    onsets = onset_rows(sol.history)
    assert len(onsets) == 2
    # onset where G = 0.1: w² = 25 · 40 / a, w = −5 at 40 mm, −4.77 at 44: past the maximum
    assert onsets[1].probes["w"] == pytest.approx(-math.sqrt(25 * 40 / 44), rel=ONSET_RTOL)
    for r in onsets:
        assert r.load_factor < 0.9 * 300.0  # on the falling branch
        assert r.extra["peak_load_factor"] == pytest.approx(300.0, rel=1e-12)
    summary = sol.extra["debond_growth"]
    assert summary["residual_strength"] == pytest.approx(300.0, rel=1e-12)
    assert summary["first_growth_load"] == pytest.approx(onsets[0].load_factor)


def test_the_envelope_is_found_again_in_a_result_folder_read_back(tmp_path):
    from sandwich.models import run_model
    from sandwich.results import load_result

    sc = _scene(kind="linear", step=4.0, max_length=56.0)
    sol = run_model(sc, "beam", tmp_path / "out", solver=_stand_in(2, []))
    back = load_result(tmp_path / "out")
    assert [r.step for r in onset_rows(back.history)] == [r.step for r in onset_rows(sol.history)]
    assert len(onset_rows(back.history)) == 3 < len(back.history)  # 40, 48, 56 mm
