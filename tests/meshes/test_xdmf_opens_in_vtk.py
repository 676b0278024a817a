"""The mesh XDMF opens in VTK's XDMF reader (the one ParaView uses), with every cell."""

from pathlib import Path

import pytest

from sandwich.meshes import build_mesh, write_mesh
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[2]


def test_xdmf_is_read_by_vtk(tmp_path):
    vtk = pytest.importorskip("vtk")
    if not hasattr(vtk, "vtkXdmfReader"):
        pytest.skip("this vtk build has no XDMF reader")
    mesh = build_mesh(load_scene(ROOT / "scenes" / "default.toml"), level="coarse")
    files = write_mesh(mesh, tmp_path, "m")
    reader = vtk.vtkXdmfReader()
    reader.SetFileName(str(files["xdmf"]))
    reader.Update()
    grid = reader.GetOutputDataObject(0)
    assert grid.GetNumberOfCells() == mesh.n_cells
    assert grid.GetNumberOfPoints() == len(mesh.points)
    assert grid.GetCellData().GetArray("tag") is not None
