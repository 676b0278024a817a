"""compare() end to end with synthetic solvers: metrics, files, progress, reuse, missing models."""

import json
import os

import numpy as np
import pytest

from comparisons import FieldSnapshot, compare, load_result, save_snapshot
from comparisons import runs as runs_module

EPS = 0.03


def _strict_json(path):
    def refuse(name):
        raise AssertionError(f"{path} holds {name}")

    return json.loads(path.read_text(), parse_constant=refuse)


def test_metrics_recover_known_error(tmp_path, scene, synth):
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res",
                  solvers=synth.fake_solvers(EPS))
    m = cmp.metrics
    assert m.complete and cmp.missing == {}
    assert m.abscissa == "w_top_mid"
    load = m.curve("load_factor")
    assert load.l2_relative == pytest.approx(EPS, abs=5e-4)
    assert load.max_relative == pytest.approx(EPS, abs=5e-4)
    assert m.curve("w_bottom_mid").l2_relative == pytest.approx(EPS, abs=5e-4)
    # profiles are scaled by (1 + EPS) at the same end deflection
    for col in ("w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom", "tau_core"):
        assert m.profile(col).l2_relative == pytest.approx(EPS, abs=2e-3), col
    peaks = {p.column: p for p in m.peaks}
    assert peaks["sigma_zz_top"].relative_error == pytest.approx(EPS, abs=1e-9)
    assert peaks["sigma_zz_top"].peak_x in synth.TIPS and peaks["sigma_zz_top"].shift == 0.0
    assert peaks["sigma_zz_top"].same_sign
    _, lam_max = synth.analytic_limit()
    assert m.models["2d"].limit_loads[0].load_factor == pytest.approx(lam_max, rel=1e-3)
    assert m.models["beam"].limit_loads[0].load_factor == pytest.approx(
        (1 + EPS) * lam_max, rel=1e-3)
    assert m.first_limit_load_error == pytest.approx(EPS, abs=2e-3)
    assert m.wall_ratio == pytest.approx(20.0 / 0.5)
    assert m.dofs_ratio == pytest.approx(96000 / 2400)
    data = _strict_json(tmp_path / "out" / "metrics.json")
    assert data["complete"] is True
    assert data["curves"][0]["l2_relative"] == pytest.approx(EPS, abs=5e-4)


def test_figures_and_their_csvs_are_written(tmp_path, scene, synth):
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res",
                  solvers=synth.fake_solvers(EPS))
    out = tmp_path / "out"
    for stem in ("load_w_top_mid", "load_w_bottom_mid", "face_deflections", "interface_stress",
                 "core_shear"):
        png, csv = out / f"{stem}.png", out / f"{stem}.csv"
        assert png in cmp.figures and csv in cmp.tables
        assert png.stat().st_size > 5000, stem
    assert (out / "deformed_faces.png").is_file()
    # the CSV behind the load curve holds exactly the 2D path: load P = λ·1 N vs w_top_mid
    rows = [r.split(",") for r in (out / "load_w_top_mid.csv").read_text().splitlines()[1:]]
    two_d = np.array([[float(r[2]), float(r[3])] for r in rows if r[1] == "2d"])
    sol = load_result(tmp_path / "res" / scene.name / "2d")
    np.testing.assert_allclose(two_d[:, 0], [r.probes["w_top_mid"] for r in sol.history])
    np.testing.assert_allclose(two_d[:, 1], [r.load_factor for r in sol.history])
    assert "nan" not in (out / "interface_stress.csv").read_text().lower()


def test_progress_reports_model_and_step(tmp_path, scene, synth):
    events = []
    compare(scene, tmp_path / "out", results_root=tmp_path / "res",
            solvers=synth.fake_solvers(EPS), progress=events.append)
    beam_steps = [e.step for e in events if e.model == "beam" and e.phase == "step"]
    assert beam_steps == list(range(1, 98))
    phases = [(e.model, e.phase) for e in events if e.phase != "step"]
    assert phases == [("beam", "start"), ("beam", "done"), ("2d", "start"), ("2d", "done")]


def test_fresh_results_are_reused_and_stale_ones_rerun(tmp_path, scene_file, scene, synth):
    calls = []
    solvers = synth.fake_solvers(EPS, calls=calls)
    compare(scene, tmp_path / "a", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d"]
    old = os.path.getmtime(scene_file) - 100  # the results are now clearly newer than the scene
    os.utime(scene_file, (old, old))
    cmp = compare(scene_file, tmp_path / "b", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d"]
    assert {r.origin for r in cmp.runs.values()} == {"reused"}
    assert cmp.metrics.curve("load_factor").l2_relative == pytest.approx(EPS, abs=5e-4)
    future = os.path.getmtime(tmp_path / "res" / scene.name / "beam" / "summary.json") + 100
    os.utime(scene_file, (future, future))  # the scene was edited after the results
    cmp = compare(scene_file, tmp_path / "c", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d", "beam", "2d"]
    assert {r.origin for r in cmp.runs.values()} == {"run"}
    compare(scene_file, tmp_path / "d", results_root=tmp_path / "res", solvers=solvers,
            reuse=False)
    assert len(calls) == 6


def test_missing_model_is_reported_in_words(tmp_path, scene, synth, monkeypatch):
    monkeypatch.setitem(runs_module.MODEL_SOURCES, "beam",
                        ("no_such_beam_module_xyz", ("beam_element",)))
    solvers = synth.fake_solvers(EPS)
    del solvers["beam"]
    events = []
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", solvers=solvers,
                  progress=events.append)
    assert set(cmp.missing) == {"beam"}
    assert "no_such_beam_module_xyz" in cmp.missing["beam"]
    assert ("beam", "missing") in [(e.model, e.phase) for e in events]
    data = _strict_json(tmp_path / "out" / "metrics.json")
    assert data["complete"] is False
    assert data["models"]["beam"]["origin"] == "missing"
    assert "cannot import no_such_beam_module_xyz" in data["models"]["beam"]["reason"]
    assert data["curves"] == [] and data["wall_ratio"] is None
    assert any("beam" in n for n in data["notes"])
    assert (tmp_path / "out" / "load_w_top_mid.png").is_file()  # the 2D path is still drawn


def test_failing_model_is_reported_and_comparison_goes_on(tmp_path, scene, synth):
    solvers = synth.fake_solvers(EPS)

    def broken(scene, progress=None):
        raise RuntimeError("tangent singular at step 3")

    solvers["2d"] = broken
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", solvers=solvers)
    assert cmp.runs["2d"].origin == "failed"
    assert "tangent singular at step 3" in cmp.missing["2d"]
    assert cmp.runs["beam"].origin == "run"


def _strip_snapshot(model, nx=31, nz=5):
    x, z = np.meshgrid(np.linspace(0, 300, nx), np.linspace(0, 26, nz))
    pts = np.column_stack([x.ravel(), z.ravel()])
    cells = [[j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i]
             for j in range(nz - 1) for i in range(nx - 1)]
    disp = np.column_stack([np.zeros(len(pts)), -10 * np.sin(np.pi * pts[:, 0] / 300)])
    vm = np.abs(np.cos(np.pi * pts[:, 0] / 300))
    region = np.zeros(len(cells), dtype=int)
    region[-(nx - 1):] = 1  # the top row of cells is the top face (drawn grey)
    return FieldSnapshot(model, 150, 1.0, pts, disp, np.array(cells), vm, region)


def test_field_snapshot_is_rendered_when_a_model_provides_it(tmp_path, scene, synth):
    solvers = synth.fake_solvers(EPS)
    inner = solvers["2d"]

    def with_fields(scene, progress=None):
        sol = inner(scene, progress)
        sol.extra["field_snapshot"] = _strip_snapshot("2d")  # noqa: B023
        return sol

    solvers["2d"] = with_fields
    # the in-memory snapshot goes to fields.npz (summary.json cannot hold arrays)
    cmp = compare(scene, tmp_path / "o0", results_root=tmp_path / "r0", solvers=solvers)
    assert (tmp_path / "r0" / scene.name / "2d" / "fields.npz").is_file()
    assert "field_snapshot" not in (tmp_path / "r0" / scene.name / "2d" / "summary.json"
                                    ).read_text()
    assert tmp_path / "o0" / "deformed_2d.png" in cmp.figures
    # a snapshot saved next to a result (as a model would) is used too
    save_snapshot(_strip_snapshot("beam"), tmp_path / "res" / scene.name / "beam")
    plain = synth.fake_solvers(EPS)
    compare(scene, tmp_path / "x", results_root=tmp_path / "res", solvers=plain)
    # ... but a rerun that gives no snapshot removes the stale one
    assert not (tmp_path / "res" / scene.name / "beam" / "fields.npz").exists()
    save_snapshot(_strip_snapshot("beam"), tmp_path / "res" / scene.name / "beam")
    old = (tmp_path / "res" / scene.name / "beam" / "summary.json").stat().st_mtime - 100
    import os

    os.utime(scene.source, (old, old))
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", solvers=plain)
    assert cmp.runs["beam"].origin == "reused"
    assert tmp_path / "out" / "deformed_beam.png" in cmp.figures
    assert (tmp_path / "out" / "deformed_beam.png").stat().st_size > 5000
    assert (tmp_path / "out" / "deformed_faces.png").is_file()  # 2D still from its profiles


def test_field_snapshot_refuses_inconsistent_arrays():
    snap = _strip_snapshot("2d")
    with pytest.raises(ValueError, match="von_mises"):
        FieldSnapshot("2d", 1, 1.0, snap.points, snap.displacement, snap.cells,
                      snap.von_mises[:7])
    with pytest.raises(ValueError, match="outside"):
        FieldSnapshot("2d", 1, 1.0, snap.points, snap.displacement, snap.cells + 10_000,
                      snap.von_mises)
