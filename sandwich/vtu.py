"""Minimal VTK XML writers (unstructured grid + ParaView collection), NumPy only.

Used for the beam model's reconstructed 2D fields, so that ParaView can open a beam result
without FEniCSx being installed. Quads are VTK cell type 9, triangles type 5.
"""

from __future__ import annotations

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
