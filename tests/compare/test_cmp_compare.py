"""compare() end to end with synthetic solvers: metrics, files, progress, reuse, missing models."""

import json
import os

import numpy as np
import pytest

from sandwich.compare import compare
from sandwich.compare.deformed import picture_of
from sandwich.results import FieldFrame, load_result

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


def test_results_are_reused_only_for_the_same_identity(tmp_path, scene_file, scene, synth):
    calls = []
    solvers = synth.fake_solvers(EPS, calls=calls)
    compare(scene, tmp_path / "a", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d"]
    future = os.path.getmtime(tmp_path / "res" / scene.name / "beam" / "summary.json") + 100
    os.utime(scene_file, (future, future))  # a newer file date alone changes nothing
    cmp = compare(scene_file, tmp_path / "b", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d"]
    assert {r.origin for r in cmp.runs.values()} == {"reused"}
    assert cmp.metrics.curve("load_factor").l2_relative == pytest.approx(EPS, abs=5e-4)
    # the 2D mesh asked by the scene changes: only the 2D result is stale, and it says why
    text = scene_file.read_text()
    scene_file.write_text(text + '\n[reference2d]\nlevel = "fine"\n')
    cmp = compare(scene_file, tmp_path / "c", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d", "2d"]
    assert (cmp.runs["beam"].origin, cmp.runs["2d"].origin) == ("reused", "run")
    assert "solved at level=medium, the scene asks level=fine" in cmp.runs["2d"].stale
    # another scene of the same name (a mechanical change): both are solved again
    scene_file.write_text(text.replace("thickness = 0.5", "thickness = 0.6", 1))
    cmp = compare(scene_file, tmp_path / "d", results_root=tmp_path / "res", solvers=solvers)
    assert calls == ["beam", "2d", "2d", "beam", "2d"]
    assert all("the scene's content differs" in r.stale for r in cmp.runs.values())
    compare(scene_file, tmp_path / "e", results_root=tmp_path / "res", solvers=solvers,
            reuse=False)
    assert len(calls) == 7


def test_without_a_results_root_everything_stays_in_the_output_folder(tmp_path, scene, synth):
    cmp = compare(scene, tmp_path / "out", solvers=synth.fake_solvers(EPS))
    assert {r.folder for r in cmp.runs.values()} == {tmp_path / "out" / "beam",
                                                     tmp_path / "out" / "2d"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "scene.toml"]


def test_missing_model_is_reported_in_words(tmp_path, scene, synth, monkeypatch):
    import dataclasses

    from sandwich.models import registry

    def unimportable(scene, progress=None):
        raise ModuleNotFoundError("No module named 'no_such_beam_module_xyz'")

    monkeypatch.setitem(registry.MODELS, "beam",
                        dataclasses.replace(registry.MODELS["beam"], solve=unimportable))
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
    assert "cannot import" in data["models"]["beam"]["reason"]
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


def _strip_frame(step=150, nx=31, nz=5, per_cell=True):
    x, z = np.meshgrid(np.linspace(0, 300, nx), np.linspace(0, 26, nz))
    pts = np.column_stack([x.ravel(), z.ravel()])
    cells = np.array([[j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i]
                      for j in range(nz - 1) for i in range(nx - 1)])
    disp = np.column_stack([np.zeros(len(pts)), -10 * np.sin(np.pi * pts[:, 0] / 300)])
    region = np.zeros(len(cells))
    region[-(nx - 1):] = 1  # the top row of cells is the top face (drawn grey)
    vm = np.abs(np.cos(np.pi * pts[:, 0] / 300))
    if per_cell:
        return FieldFrame(step, 1.0, pts, cells, disp, {},
                          {"von_mises": vm[cells].mean(axis=1), "region": region})
    return FieldFrame(step, 1.0, pts, cells, disp, {"von_mises": vm}, {"region": region})


def test_deformed_pictures_come_from_each_models_field_frames(tmp_path, scene, synth):
    solvers = synth.fake_solvers(EPS)
    inner = dict(solvers)

    def with_frames(model, per_cell):
        def solve(scene, progress=None):
            sol = inner[model](scene, progress)
            sol.fields = [_strip_frame(1, per_cell=per_cell), _strip_frame(per_cell=per_cell)]
            return sol
        return solve

    solvers = {"2d": with_frames("2d", True), "beam": with_frames("beam", False)}
    cmp = compare(scene, tmp_path / "o0", results_root=tmp_path / "res", solvers=solvers)
    for model in ("2d", "beam"):
        png = tmp_path / "o0" / f"deformed_{model}.png"
        assert png in cmp.figures and png.stat().st_size > 5000
        assert (tmp_path / "res" / scene.name / model / "fields_00150.vtu").is_file()
    assert not (tmp_path / "o0" / "deformed_faces.png").exists()  # no profile fallback needed
    # reused: the pictures come from the frames read back from the result folders
    cmp = compare(scene, tmp_path / "o1", results_root=tmp_path / "res", solvers=solvers)
    assert {r.origin for r in cmp.runs.values()} == {"reused"}
    assert [f.step for f in cmp.runs["2d"].solution.fields] == [1, 150]
    assert (tmp_path / "o1" / "deformed_2d.png").stat().st_size > 5000
    # a model without frames is drawn from its profiles
    plain = synth.fake_solvers(EPS)
    cmp = compare(scene, tmp_path / "o2", results_root=tmp_path / "res2", solvers=plain)
    assert (tmp_path / "o2" / "deformed_faces.png").is_file()
    assert not (tmp_path / "o2" / "deformed_2d.png").exists()


def test_a_frame_without_stress_is_refused_in_words():
    frame = _strip_frame()
    frame.cell_data.pop("von_mises")
    with pytest.raises(ValueError, match="no von_mises"):
        picture_of("2d", frame)


def test_a_crushed_2d_core_is_noted_and_survives_reuse(tmp_path, scene, synth):
    """The 2D history's core_ellipticity ≤ 0 from step 40 on: the comparison says where the
    2D core crushed (reference: the synthetic column), also from reused result files; without
    the column, no note."""
    solvers = synth.fake_solvers(EPS)
    solve_2d = solvers["2d"]

    def crushing_2d(sc, progress=None):
        sol = solve_2d(sc, progress)
        for r in sol.history:
            r.extra["core_ellipticity"] = 1.0 - r.step / 40.0
        return sol

    plain = compare(scene, tmp_path / "a", results_root=tmp_path / "r0", solvers=solvers)
    assert not any("crushed" in n for n in plain.metrics.notes)
    solvers["2d"] = crushing_2d
    for out in ("b", "c"):  # solved, then reused from the written files
        cmp = compare(scene, tmp_path / out, results_root=tmp_path / "r1", solvers=solvers)
        notes = [n for n in cmp.metrics.notes if "crushed" in n]
        assert len(notes) == 1 and notes[0].startswith("2d: its core crushed as a material at "
                                                      "step 40 "), notes
    assert cmp.runs["2d"].origin == "reused"
