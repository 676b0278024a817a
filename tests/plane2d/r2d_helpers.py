"""Shared builders for the 2D reference tests: homogeneous strips with hand-placed supports."""

from __future__ import annotations

import numpy as np
from r2d_structured import layered_mesh

from sandwich.plane2d.constitutive import LayerBand, PlaneStressStiffness, internal_work
from sandwich.plane2d.loads import edge_facets, edge_load_vector
from sandwich.plane2d.mesh import build_discretisation
from sandwich.plane2d.model import probe_vector
from sandwich.plane2d.system import Reference2DSystem
from sandwich.scene import Material

TOL = 1e-7


def isotropic(E, nu):
    return Material("iso", "isotropic", E, E, E / (2 * (1 + nu)), nu)


def cantilever(length, height, nx, nz, E=1000.0, nu=0.3, width=1.0, load=1.0):
    """Homogeneous cantilever clamped (u = w = 0) on x = 0, uniform shear traction on x = L
    carrying ``load`` N downwards; probe ``w_tip`` at the tip mid-height."""
    mesh = layered_mesh(length, [("core", height, nz)], nx)
    disc = build_discretisation(mesh.points, mesh.cells)
    band = LayerBand("core", -height / 2, height / 2, isotropic(E, nu))
    stiff = PlaneStressStiffness(disc.mesh, [band])
    V = disc.V
    n_local = (V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts) * 2
    X = V.tabulate_dof_coordinates()
    root = np.where(np.abs(X[:, 0]) < TOL)[0]
    bc = np.concatenate([2 * root, 2 * root + 1])
    facets = edge_facets(disc.mesh, lambda x: np.abs(x[0] - length) < TOL)
    f = edge_load_vector(V, facets, (0.0, -load / (height * width)), width, n_local)
    probes = {"w_tip": probe_vector(V, length, band, n_local),
              "u_tip": np.roll(probe_vector(V, length, band, n_local), -1)}
    system = Reference2DSystem(V, lambda u, v: internal_work(u, v, stiff, width), f, bc, [], probes)
    return system


def strip_scene(debonds, E=100.0, nu=0.3, t_face=0.5, t_core=4.0, length=20.0, width=1.0):
    """A three-layer strip, every layer of the same material (so a cut changes nothing in pure
    transverse compression), as a Scene carrying geometry only."""
    from sandwich.scene import Analysis, Debond, Layer, Scene

    m = isotropic(E, nu)
    return Scene("strip", "test strip", length, width, Layer(t_face, m), Layer(t_core, m),
                 Layer(t_face, m), tuple(Debond("top", a, b) for a, b in debonds), (), (), (),
                 Analysis(kind="linear", until_load_factor=1.0))


def pressed_strip(debonded: bool, pressure: float, nx=20, penalty=None, span=(5.0, 15.0),
                  empty_windows=False):
    """The strip on a frictionless floor (w = 0 on z = bottom, u = 0 at one bottom node), uniform
    pressure ``pressure`` (MPa, positive pushes down) on the whole top edge. Debond: top
    interface, x in ``span`` (reaching x = 0 or 20: open mouth). ``empty_windows``: every
    slave's window starts as its coincident node alone, so that the first tangent widens them.
    Returns (system, pairs)."""
    from sandwich.plane2d.model import contact_pairs, default_penalty, layer_bands

    scene = strip_scene([span] if debonded else [])
    layers = [("bottom", 0.5, 1), ("core", 4.0, 4), ("top", 0.5, 1)]
    mesh = layered_mesh(20.0, layers, nx, debonds=[("top", *span)] if debonded else [])
    disc = build_discretisation(mesh.points, mesh.cells)
    V = disc.V
    stiff = PlaneStressStiffness(disc.mesh, layer_bands(scene))
    n_local = (V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts) * 2
    X = V.tabulate_dof_coordinates()
    z_bot, z_top = -2.5, 2.5
    floor = np.where(np.abs(X[:, 1] - z_bot) < TOL)[0]
    pin = floor[np.argmin(np.abs(X[floor, 0] - 10.0))]
    bc = np.concatenate([2 * floor + 1, [2 * pin]])
    facets = edge_facets(disc.mesh, lambda x: np.abs(x[1] - z_top) < TOL)
    f = edge_load_vector(V, facets, (0.0, -pressure), scene.width, n_local)
    k = penalty if penalty is not None else default_penalty(scene)
    pairs, _ = contact_pairs(scene, mesh, disc, k)
    for p in pairs if empty_windows else ():
        p.window[:] = p.anchor[:, None]
    from sandwich.plane2d.model import face_band

    probes = {"w_top_mid": probe_vector(V, 10.0, face_band(scene, "top"), n_local)}
    system = Reference2DSystem(V, lambda u, v: internal_work(u, v, stiff, scene.width), f, bc,
                               pairs, probes)
    return system, pairs
