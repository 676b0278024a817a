"""A small structured layered Q2 mesh in the array layout of ``meshes.LayeredMesh`` (test helper).

Lets the 2D reference be tested on rectangles and simple debonded strips without gmsh.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

LAYER_IDS = {"bottom": 1, "core": 2, "top": 3}


def layered_mesh(length, layers, nx, debonds=(), x0=0.0):
    """Structured 9-node quads.

    layers: list of (name, thickness, elements through thickness), bottom first.
    debonds: list of (interface "top"|"bottom", start, end) on element boundaries. A debond
    reaching a beam end (start <= x0 or end >= x0 + length) has an open mouth there: the end
    node is a lip pair too, as in ``sandwich.meshes.build_mesh``.
    """
    z = [0.0]
    z_layer = []
    for name, h, n in layers:
        z_layer += [LAYER_IDS[name]] * n
        z += list(z[-1] + h * np.arange(1, 2 * n + 1) / (2 * n))
    z = np.array(z) - 0.5 * sum(h for name, h, n in layers if name == "core") - sum(
        h for name, h, n in layers if name == "bottom")
    xs = x0 + length * np.arange(2 * nx + 1) / (2 * nx)
    nxn, nzn = len(xs), len(z)
    X, Z = np.meshgrid(xs, z, indexing="ij")
    points = np.column_stack([X.ravel(), Z.ravel()])
    idx = np.arange(nxn * nzn).reshape(nxn, nzn)
    # interface node rows
    bounds = np.cumsum([0] + [2 * n for _, _, n in layers])
    names = [name for name, _, _ in layers]
    lip_pairs = {}
    dup = {}  # (row iz, which side) -> array of duplicated node ids over ix
    for k, (iface, a, b) in enumerate(debonds):
        ci = names.index("core")
        iz = bounds[ci + 1] if iface == "top" else bounds[ci]
        lo = a - 1e-9 if a <= x0 + 1e-9 else a + 1e-9  # open mouth: the end node splits too
        hi = b + 1e-9 if b >= x0 + length - 1e-9 else b - 1e-9
        inside = [ix for ix in range(nxn) if lo < xs[ix] < hi]
        new = np.arange(len(points), len(points) + len(inside))
        points = np.vstack([points, points[idx[inside, iz]]])
        face_map = dict(zip(inside, new, strict=True))
        dup[(iz, iface)] = face_map
        lip_pairs[k] = np.column_stack([new, idx[inside, iz]])
    cells, cell_layer = [], []
    for ex in range(nx):
        for ez in range(len(z_layer)):
            i, j = 2 * ex, 2 * ez
            c = [idx[i + a, j + b] for a, b in ((0, 0), (2, 0), (2, 2), (0, 2), (1, 0), (2, 1),
                                                (1, 2), (0, 1), (1, 1))]
            lay = z_layer[ez]
            # face cells adjacent to a debonded interface use the duplicated (face-lip) nodes
            for (iz, iface), fmap in dup.items():
                if iface == "top" and lay == 3 and j == iz:
                    rows = (0, 1, 4)  # bottom edge nodes of this cell
                    cols = (i, i + 2, i + 1)
                elif iface == "bottom" and lay == 1 and j + 2 == iz:
                    rows = (3, 2, 6)
                    cols = (i, i + 2, i + 1)
                else:
                    continue
                for r, ix in zip(rows, cols, strict=True):
                    if ix in fmap:
                        c[r] = fmap[ix]
            cells.append(c)
            cell_layer.append(lay)
    return SimpleNamespace(points=points, cells=np.array(cells, dtype=np.int64),
                           cell_layer=np.array(cell_layer, dtype=np.int32), lip_pairs=lip_pairs)
