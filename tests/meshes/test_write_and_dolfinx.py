"""Files written by write_mesh: .msh into dolfinx 0.5 via gmshio, XDMF and JSON read back."""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from sandwich.meshes import quality_report, write_mesh


@pytest.fixture(scope="module")
def written(fig5_mesh, tmp_path_factory):
    return write_mesh(fig5_mesh, tmp_path_factory.mktemp("mesh"), "fig5")


def test_xdmf_holds_cells_points_and_tags(fig5_mesh, written):
    for key, conn, tag in (("xdmf", fig5_mesh.cells, fig5_mesh.cell_layer),
                           ("facets_xdmf", fig5_mesh.facets, fig5_mesh.facet_tag)):
        grid = ET.parse(written[key]).getroot().find("Domain/Grid")
        items = {el.tag: el.find("DataItem") for el in grid}
        got_conn = np.array(items["Topology"].text.split(), dtype=int).reshape(conn.shape)
        got_pts = np.array(items["Geometry"].text.split(), dtype=float).reshape(-1, 2)
        got_tag = np.array(items["Attribute"].text.split(), dtype=int)
        assert np.array_equal(got_conn, conn)
        assert np.array_equal(got_pts, fig5_mesh.points)
        assert np.array_equal(got_tag, tag)


def test_lip_pairs_json(fig5_mesh, written):
    data = json.loads(written["lip_pairs"].read_text())
    assert np.array_equal(np.array(data["debonds"]["0"]["pairs"]), fig5_mesh.lip_pairs[0])
    assert data["point_nodes"] == fig5_mesh.point_nodes


def test_quality_report(fig5_mesh):
    q = quality_report(fig5_mesh)
    assert q.n_cells == fig5_mesh.n_cells and q.lip_pairs == {0: len(fig5_mesh.lip_pairs[0])}
    assert 1.0 <= q.min_aspect_ratio <= q.max_aspect_ratio <= 25.0
    assert q.min_angle == pytest.approx(90.0)  # structured rectangles
    assert "lip pairs: debond0" in str(q)


@pytest.mark.dolfinx
def test_msh_loads_into_dolfinx(fig5, fig5_mesh, written):
    pytest.importorskip("dolfinx")
    import gmsh
    import ufl
    from dolfinx import fem
    from dolfinx.io import gmshio
    from mpi4py import MPI

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.merge(str(written["msh"]))
        msh, cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, MPI.COMM_WORLD, 0, gdim=2)
    finally:
        gmsh.finalize()
    assert msh.topology.index_map(2).size_global == fig5_mesh.n_cells
    area = fem.assemble_scalar(fem.form(fem.Constant(msh, 1.0) * ufl.dx))
    assert area == pytest.approx(fig5.length * fig5.total_height, rel=1e-12)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)
    core = fem.assemble_scalar(fem.form(fem.Constant(msh, 1.0) * dx(2)))
    assert core == pytest.approx(fig5.length * fig5.core.thickness, rel=1e-12)
    lip = fig5_mesh.groups["debond0_face_lip"][1]
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
    d = fig5.debonds[0]
    assert fem.assemble_scalar(fem.form(fem.Constant(msh, 1.0) * ds(lip))) == pytest.approx(
        d.end - d.start, rel=1e-12)
