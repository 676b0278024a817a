"""Minimal VTK XML writer and reader (ASCII unstructured grid + ParaView collection), NumPy only.

Both models' field frames (:class:`~sandwich.results.types.FieldFrame`) are written with these,
so that ParaView opens a result without FEniCSx being installed, and read back with
:func:`read_vtu` / :func:`read_pvd` (the comparison pictures of a reused result). Quads are VTK
cell type 9, triangles type 5. The reader reads what :func:`vtu_text` writes, not VTK XML in
general (no binary or appended data).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

VTK_TRIANGLE, VTK_QUAD = 5, 9


def _array(name: str, values: np.ndarray, components: int = 1) -> str:
    flat = " ".join(repr(float(v)) for v in np.asarray(values, dtype=float).ravel())
    return (f'<DataArray type="Float64" Name="{name}" NumberOfComponents="{components}" '
            f'format="ascii">{flat}</DataArray>')


def vtu_text(points: np.ndarray, cells: np.ndarray, point_data: dict[str, np.ndarray],
             cell_data: dict[str, np.ndarray]) -> str:
    """Render an unstructured grid of one cell kind (triangles or quads) in 2D (z = 0).

    Vector point data of shape (n, 2) is padded to three components, as ParaView expects.
    """
    points = np.asarray(points, dtype=float)
    cells = np.asarray(cells, dtype=np.int64)
    n, m = len(points), len(cells)
    kind = {3: VTK_TRIANGLE, 4: VTK_QUAD}[cells.shape[1]]
    xyz = np.zeros((n, 3))
    xyz[:, :2] = points[:, :2]
    pd = []
    for name, v in point_data.items():
        v = np.asarray(v, dtype=float)
        if v.ndim == 2:
            v3 = np.zeros((n, 3))
            v3[:, : v.shape[1]] = v
            pd.append(_array(name, v3, 3))
        else:
            pd.append(_array(name, v))
    cd = [_array(name, v) for name, v in cell_data.items()]
    conn = " ".join(str(i) for i in cells.ravel())
    offsets = " ".join(str(i) for i in range(cells.shape[1], cells.shape[1] * m + 1,
                                             cells.shape[1]))
    types = " ".join([str(kind)] * m)
    return (
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" '
        'byte_order="LittleEndian">\n<UnstructuredGrid>\n'
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{m}">\n'
        f"<PointData>{''.join(pd)}</PointData>\n<CellData>{''.join(cd)}</CellData>\n"
        f"<Points>{_array('points', xyz, 3)}</Points>\n"
        f'<Cells><DataArray type="Int64" Name="connectivity" format="ascii">{conn}</DataArray>'
        f'<DataArray type="Int64" Name="offsets" format="ascii">{offsets}</DataArray>'
        f'<DataArray type="UInt8" Name="types" format="ascii">{types}</DataArray></Cells>\n'
        "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
    )


def pvd_text(entries: list[tuple[float, str]]) -> str:
    """Render a ParaView collection: (time value, relative file name) per frame."""
    rows = "".join(f'<DataSet timestep="{t!r}" group="" part="0" file="{f}"/>\n'
                   for t, f in entries)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
            f"<Collection>\n{rows}</Collection>\n</VTKFile>\n")


def _values(node: ET.Element) -> np.ndarray:
    """The numbers of one ASCII ``DataArray`` shaped (n, components) or (n,)."""
    comps = int(node.get("NumberOfComponents", "1"))
    flat = np.array((node.text or "").split(), dtype=float)
    return flat.reshape(-1, comps) if comps > 1 else flat


def read_vtu(path: str | Path) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray],
                                         dict[str, np.ndarray]]:
    """Read a file written by :func:`vtu_text`: points (n, 3), cells (m, k), point and cell data.

    Raises
    ------
    ValueError
        If the file is not such an unstructured grid (the message names the file).
    """
    path = Path(path)
    try:
        piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    except ET.ParseError as exc:
        raise ValueError(f"{path}: not VTK XML ({exc})") from None
    if piece is None:
        raise ValueError(f"{path}: no UnstructuredGrid/Piece")
    points = _values(piece.find("Points/DataArray"))
    cells_node = {a.get("Name"): a for a in piece.findall("Cells/DataArray")}
    conn = _values(cells_node["connectivity"]).astype(np.int64)
    offsets = _values(cells_node["offsets"]).astype(np.int64)
    k = int(offsets[0]) if offsets.size else 4
    if offsets.size and not np.array_equal(offsets, k * np.arange(1, offsets.size + 1)):
        raise ValueError(f"{path}: cells of mixed kinds (only one kind is read)")
    point_data = {a.get("Name"): _values(a) for a in piece.findall("PointData/DataArray")}
    cell_data = {a.get("Name"): _values(a) for a in piece.findall("CellData/DataArray")}
    if len(points) != int(piece.get("NumberOfPoints", len(points))):
        raise ValueError(f"{path}: NumberOfPoints does not match the points")
    return points, conn.reshape(-1, k), point_data, cell_data


def read_pvd(path: str | Path) -> list[tuple[float, str]]:
    """The (time value, file name) entries of a collection written by :func:`pvd_text`."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ValueError(f"{path}: not a ParaView collection ({exc})") from None
    return [(float(d.get("timestep", "0")), str(d.get("file"))) for d in root.iter("DataSet")]
