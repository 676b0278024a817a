"""The mesh XDMF files open in VTK's XDMF reader (the one ParaView uses), meshio and pyvista."""

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


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    mesh = build_mesh(load_scene(ROOT / "scenes" / "default.toml"), level="coarse")
    return mesh, write_mesh(mesh, tmp_path_factory.mktemp("xdmf"), "m")


def test_xdmf_is_read_by_meshio_with_every_cell_and_its_tag(written):
    meshio = pytest.importorskip("meshio")
    mesh, files = written
    got = meshio.read(files["xdmf"])
    assert sum(len(block.data) for block in got.cells) == mesh.n_cells
    assert len(got.points) == len(mesh.points)
    assert "tag" in got.cell_data
    facets = meshio.read(files["facets_xdmf"])
    assert sum(len(block.data) for block in facets.cells) > 0


def test_xdmf_opens_in_pyvista_through_meshio(written):
    pyvista = pytest.importorskip("pyvista")
    meshio = pytest.importorskip("meshio")
    mesh, files = written
    grid = pyvista.from_meshio(meshio.read(files["xdmf"]))
    assert grid.n_cells == mesh.n_cells
    assert grid.n_points == len(mesh.points)
