"""The comparison reports each model's first bifurcation and load maximum, and the beam's error.

Synthetic solutions (``cmp_synthetic``): the beam's path is the 2D one scaled by (1 + EPS), so a
bifurcation each model reports at the same deflection differs by exactly EPS in λ; the load
maximum is the analytic one of λ(w) = K|w| − C|w|³ (exact to the sampling).
"""

import json
import math

import pytest

from sandwich.compare import compare
from sandwich.compare.claims import buckling_load
from sandwich.compare.compare import total_force
from sandwich.compare.metrics import critical_lines
from sandwich.results import LimitPoint

EPS = 0.02
W_BIF = 3.0  # mm: |w_top_mid| where both models report a bifurcation


def _with_bifurcation(synth, solve):
    def wrapped(scene, progress=None):
        sol = solve(scene, progress)
        scale = sol.history[0].load_factor / synth.load_of(sol.history[0].probes["w_top_mid"])
        lam = float(scale * synth.load_of(-W_BIF))
        step = next(h.step for h in sol.history if abs(h.probes["w_top_mid"]) >= W_BIF)
        sol.limit_points.insert(0, LimitPoint("bifurcation", step, lam,
                                              {"w_top_mid": -W_BIF, "w_bottom_mid": -0.9 * W_BIF},
                                              located_at=0.5))
        return sol
    return wrapped


def test_both_models_bifurcation_and_maximum_are_compared(tmp_path, scene, synth):
    solvers = {m: _with_bifurcation(synth, f) for m, f in synth.fake_solvers(EPS).items()}
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", solvers=solvers)
    errors = {e.kind: e for e in cmp.metrics.critical_loads}
    assert set(errors) == {"bifurcation", "max"}
    lam_ref = synth.K * W_BIF - synth.C * W_BIF**3
    assert errors["bifurcation"].load_factor["2d"] == pytest.approx(lam_ref, rel=1e-12)
    assert errors["bifurcation"].relative_error == pytest.approx(EPS, rel=1e-9)
    _, lam_max = synth.analytic_limit()
    assert errors["max"].load_factor["2d"] == pytest.approx(lam_max, rel=1e-3)
    assert errors["max"].relative_error == pytest.approx(EPS, abs=2e-3)
    data = json.loads((tmp_path / "out" / "metrics.json").read_text())
    kinds = [c["kind"] for c in data["critical_loads"]]
    assert kinds == ["bifurcation", "max"]
    assert data["models"]["beam"]["critical_loads"][0]["located"] is True
    # the printed lines: both loads in N and the error with its sign
    lines = critical_lines(cmp.metrics, total_force(scene))
    assert lines[0].startswith("first bifurcation:")
    assert f"{total_force(scene) * lam_ref:.5g} N" in lines[0]
    assert f"{100 * EPS:+.2f} %" in lines[0]
    # the gallery's claims take the bifurcation as the buckling load
    assert buckling_load(cmp, "2d") == (pytest.approx(lam_ref), "bifurcation")


def test_no_bifurcation_in_one_model_gives_no_error_but_a_line(tmp_path, scene, synth):
    solvers = synth.fake_solvers(EPS)
    solvers["beam"] = _with_bifurcation(synth, solvers["beam"])
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", solvers=solvers)
    assert [e.kind for e in cmp.metrics.critical_loads] == ["max"]
    lines = critical_lines(cmp.metrics, total_force(scene))
    assert any("first bifurcation" in ln and "2d none" in ln for ln in lines)
    assert all(math.isfinite(e.relative_error) for e in cmp.metrics.critical_loads)
