"""Result files: the contract columns, atomic writes, and no NaN ever written."""

import csv
import json
import math

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
