"""The Benzeggagh–Kenane growth criterion on the G columns, and the toughness scene key."""

import dataclasses

import pytest

from benchmarks.cases.fracture_cases import peel_g, peel_loads, scene
from sandwich.beam.solve import run
from sandwich.fracture import bk_toughness, growth_onset
from sandwich.results import StepRecord
from sandwich.scene import Toughness


def test_bk_toughness_limits_and_mix():
    t = Toughness(0.5, 2.0, 2.0)
    assert bk_toughness(t, 1.0, 0.0) == 0.5  # pure mode I
    assert bk_toughness(t, 0.0, 1.0) == 2.0  # pure mode II
    assert bk_toughness(t, 0.0, 0.0) == 0.5  # no load: mode I value
    # G_II/G = 1/4, eta = 2: 0.5 + 1.5 / 16 (by hand)
    assert bk_toughness(t, 0.75, 0.25) == pytest.approx(0.59375, rel=1e-14)


def _rows(values):
    return [StepRecord(k, 0.1 * k, {}, 1, {"G_0_end": gi + gii, "GI_0_end": gi, "GII_0_end": gii})
            for k, (gi, gii) in enumerate(values)]


def test_growth_onset_is_the_first_step_reaching_the_criterion():
    base = scene(peel_loads())
    sc = dataclasses.replace(base, debonds=(dataclasses.replace(
        base.debonds[0], toughness=Toughness(1.0, 4.0, 1.0)),))
    # G_c at G_II/G = 0.5, eta = 1: 2.5; step 2 has G = 2.4 (< 2.5), step 3 G = 2.6
    rows = _rows([(0.0, 0.0), (0.5, 0.5), (1.2, 1.2), (1.3, 1.3), (2.0, 2.0)])
    out = growth_onset(sc, rows)["0_end"]
    assert out["step"] == 3 and out["Gc"] == pytest.approx(2.5)
    assert out["GII_over_G"] == pytest.approx(0.5)
    assert out["max_G_over_Gc"] == pytest.approx(1.6)
    assert out["criterion"] == "Benzeggagh-Kenane" and out["eta"] == 1.0
    never = growth_onset(sc, rows[:3])["0_end"]
    assert never["step"] is None and never["max_G_over_Gc"] == pytest.approx(2.4 / 2.5)
    # no toughness: no entry
    assert growth_onset(base, rows) == {}


def test_beam_summary_reports_the_step_where_the_peel_couple_reaches_gic():
    base = scene(peel_loads(), elements=240)
    g_end = peel_g(base, run(base).states[-1].load_factor)  # closed form at the path's end
    tough = Toughness(0.3 * g_end, 100 * g_end, 2.0)  # nearly pure mode I: reached on the way
    sc = dataclasses.replace(base, debonds=(dataclasses.replace(base.debonds[0],
                                                                toughness=tough),))
    sol = run(sc).solution
    out = sol.extra["debond_growth"]["0_end"]
    k = out["step"]
    assert k is not None and k > 0
    g = [r.extra["G_0_end"] for r in sol.history]
    assert g[k] >= out["Gc"] > g[k - 1]
    # where it is reached, G is the closed form within 2 %
    assert g[k] == pytest.approx(peel_g(sc, sol.history[k].load_factor), rel=0.02)
