"""A minimal XDMF 3 writer (inline XML data, no HDF5 file beside it) that ParaView opens.

One uniform grid per file: ParaView and VTK's XDMF reader open it, and so does ``meshio.read``
(with h5py installed: ``scripts/setup.sh`` installs Debian's). ``pyvista.read`` does not: its
XDMF reader asks every file for time steps, and meshio refuses a file that has them; read it
in pyvista as ``pyvista.from_meshio(meshio.read(path))``. Node orderings of ``Quadrilateral_9`` and
``Edge_3`` (VTK's) are the same as gmsh's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _data(a: np.ndarray, number_type: str, fmt: str) -> str:
    dims = " ".join(str(d) for d in a.shape)
    prec = ' Precision="8"' if number_type == "Float" else ""
    body = "\n".join(" ".join(fmt % v for v in row) for row in np.atleast_2d(a.reshape(len(a), -1)))
    return (f'<DataItem Dimensions="{dims}" NumberType="{number_type}"{prec} Format="XML">\n'
            f"{body}\n</DataItem>")


def _grid(name: str, points: np.ndarray, topology: str, conn: np.ndarray, tag: np.ndarray) -> str:
    return (f'<Grid Name="{name}" GridType="Uniform">\n'
            f'<Topology TopologyType="{topology}" NumberOfElements="{len(conn)}">\n'
            f'{_data(conn, "Int", "%d")}\n</Topology>\n'
            f'<Geometry GeometryType="XY">\n{_data(points, "Float", "%.17g")}\n</Geometry>\n'
            f'<Attribute Name="tag" AttributeType="Scalar" Center="Cell">\n'
            f'{_data(tag.reshape(-1, 1), "Int", "%d")}\n</Attribute>\n</Grid>')


def write_xdmf(path: Path, points: np.ndarray, topology: str, conn: np.ndarray,
               tag: np.ndarray) -> None:
    """Write one grid: cells of one type (``Quadrilateral_9`` or ``Edge_3``) with a field "tag"."""
    text = ('<?xml version="1.0"?>\n<Xdmf Version="3.0">\n<Domain>\n'
            + _grid(Path(path).stem, points, topology, conn, tag) + "\n</Domain>\n</Xdmf>\n")
    Path(path).write_text(text, encoding="utf-8")
