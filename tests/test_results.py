"""Result files: the contract columns, atomic writes, and no NaN ever written."""

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from sandwich.results import LimitPoint, Profile, Solution, StepRecord, write_solution


def _solution(value=1.0):
    history = [StepRecord(0, 0.0, {"w_top_mid": 0.0}, 0),
               StepRecord(1, 10.0, {"w_top_mid": -0.5 * value}, 3, {"cuts": 0.0})]
    x = np.linspace(0.0, 300.0, 4)
    cols = {"x": x, "w_top": -x * 1e-3, "w_bottom": -x * 1e-3, "sigma_zz_top": 0 * x,
            "sigma_zz_bottom": 0 * x, "tau_core": 0 * x + 0.1}
    return Solution("beam", "s", history, [Profile(1, cols)], True, "reached",
                    [LimitPoint("max", 1, 10.0, {"w_top_mid": -0.5})], 1.25, 42, {"elements": 7})


def test_files_have_the_contract_columns(tmp_path):
    write_solution(_solution(), tmp_path)
    with open(tmp_path / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0])[:4] == ["step", "load_factor", "w_top_mid", "iterations"]
    assert float(rows[1]["w_top_mid"]) == -0.5 and len(rows) == 2
    with open(tmp_path / "profiles.csv") as fh:
        prof = list(csv.DictReader(fh))
    assert set(["step", "x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom",
                "tau_core"]) <= set(prof[0])
    assert len(prof) == 4
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("model", "scene", "converged", "steps", "final_load_factor", "limit_points",
                "wall_seconds", "dofs"):
        assert key in summary
    assert summary["final_load_factor"] == 10.0 and summary["elements"] == 7


def test_nan_is_refused_and_old_files_survive(tmp_path):
    write_solution(_solution(), tmp_path)
    before = (tmp_path / "history.csv").read_text()
    with pytest.raises(ValueError, match="non-finite"):
        write_solution(_solution(value=math.nan), tmp_path)
    assert (tmp_path / "history.csv").read_text() == before
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_field_frames_are_written_as_vtu_that_vtk_reads(tmp_path):
    from sandwich.results import FieldFrame

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.0], [2.0, 1.0]])
    cells = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])
    disp = np.column_stack([0.1 * pts[:, 0], -0.2 * pts[:, 0]])
    sol = _solution()
    sol.fields = [FieldFrame(1, 10.0, pts, cells, disp, {"sigma_x": pts[:, 0]},
                             {"von_mises": np.array([1.0, 2.0])})]
    write_solution(sol, tmp_path)
    assert (tmp_path / "fields.pvd").exists()
    vtk = pytest.importorskip("vtk")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "fields_00001.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    assert grid.GetNumberOfPoints() == 6 and grid.GetNumberOfCells() == 2
    d = grid.GetPointData().GetArray("displacement")
    assert d.GetTuple3(4) == pytest.approx((0.2, -0.4, 0.0))
    assert grid.GetCellData().GetArray("von_mises").GetValue(1) == 2.0
    sol.fields[0].displacement[0, 0] = math.nan
    with pytest.raises(ValueError, match="non-finite"):
        write_solution(sol, tmp_path / "again")


def _frames(steps):
    from sandwich.results import FieldFrame

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.0], [2.0, 1.0]])
    cells = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])
    return [FieldFrame(s, 10.0 * s, pts, cells,
                       np.column_stack([0.1 * s * pts[:, 0], -0.2 * pts[:, 1]]),
                       {"sigma_x": pts[:, 0] + s}, {"von_mises": np.array([1.0, 2.0]) * s,
                                                    "region": np.array([0.0, 1.0])})
            for s in steps]


def test_field_frames_read_back_as_written(tmp_path):
    from sandwich.results import load_result

    sol = _solution()
    sol.fields = _frames([1, 7])
    write_solution(sol, tmp_path / "r")
    back = load_result(tmp_path / "r").fields
    assert [(f.step, f.load_factor) for f in back] == [(1, 10.0), (7, 70.0)]
    for a, b in zip(sol.fields, back, strict=True):
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.cells, b.cells)
        np.testing.assert_array_equal(a.displacement, b.displacement)
        assert set(b.point_data) == {"sigma_x"} and set(b.cell_data) == {"von_mises", "region"}
        np.testing.assert_array_equal(a.cell_data["von_mises"], b.cell_data["von_mises"])
        np.testing.assert_array_equal(a.point_data["sigma_x"], b.point_data["sigma_x"])


def test_a_rerun_replaces_the_whole_set(tmp_path):
    sol = _solution()
    sol.fields = _frames([1, 2, 3])
    write_solution(sol, tmp_path / "r")
    assert (tmp_path / "r" / "fields_00003.vtu").is_file()
    rerun = _solution(value=2.0)
    rerun.fields = _frames([1])
    write_solution(rerun, tmp_path / "r")
    names = sorted(p.name for p in (tmp_path / "r").iterdir())
    assert names == ["fields.pvd", "fields_00001.vtu", "history.csv", "profiles.csv",
                     "summary.json"]  # no frame of the older run is left beside the new set
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]  # no temporary sibling left
    assert (tmp_path / "r" / "history.csv").stat().st_mode & 0o044 == 0o044  # readable as PNGs


def test_a_users_folder_keeps_its_other_files(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    sol = _solution()
    sol.fields = _frames([1, 2])
    write_solution(sol, tmp_path)
    sol.fields = _frames([1])
    write_solution(sol, tmp_path)
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert not (tmp_path / "fields_00002.vtu").exists()


def test_an_output_path_that_is_a_file_is_refused_before_writing(tmp_path):
    from sandwich.results import OutputError, check_output_folder

    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        check_output_folder(tmp_path / "f")
    with pytest.raises(OutputError, match="not a folder"):
        check_output_folder(tmp_path / "f" / "sub")
    with pytest.raises(OutputError):
        write_solution(_solution(), tmp_path / "f")
    assert (tmp_path / "f").read_text() == "x"


def test_the_current_folder_as_output_is_written_in_place(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write_solution(_solution(), Path("."))
    assert (tmp_path / "summary.json").is_file() and Path.cwd() == tmp_path
