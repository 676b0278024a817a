"""Fields sampled along the beam at one state: face deflections, core interface stresses, contact.

Stresses are second Piola–Kirchhoff components S = C : E in the reference (x, z) frame, as the beam
element reports them: ``sigma_zz_top``/``sigma_zz_bottom`` is S_zz of the *core* at its top/bottom
boundary (z = ±h_c/2, evaluated in the core cell), ``tau_core`` is S_xz at the core mid-plane,
``tau_top``/``tau_bottom`` S_xz of the core at its top/bottom boundary (interface shear).
Contact on each interface's debonds, from the face-lip nodes: ``p_contact_*`` (MPa), ``gap_*``
and ``sliding_*`` (mm; :mod:`sandwich.plane2d.contact`), zero where bonded. On an interface with
a debond grown by a cohesive law, ``damage_*``: the committed damage (1 on the debond,
:mod:`sandwich.plane2d.cohesive`).
Stations are the x of the mesh nodes on the top interface.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, geometry
from mpi4py import MPI

from sandwich.plane2d.constitutive import green_lagrange
from sandwich.plane2d.mesh import allreduce_array
from sandwich.plane2d.model import Model2D, face_band

GEOM_TOL = 1e-7


class ProfileSampler:
    """Evaluates the profile columns of :data:`sandwich.results.PROFILE_COLUMNS` (and more)."""

    def __init__(self, model: Model2D):
        self.model = model
        scene = model.scene
        msh = model.disc.mesh
        pts = np.asarray(model.mesh.points)[:, :2]
        hc = scene.core.thickness
        on_iface = np.abs(pts[:, 1] - 0.5 * hc) < GEOM_TOL
        self.x = np.unique(np.round(pts[on_iface, 0], 9))
        self.core = [k for k, b in enumerate(_bands(model)) if b == "core"][0]
        # the 2nd PK stress as a DG2 field (exact samples of S at the element's nodes)
        W = fem.VectorFunctionSpace(msh, ("DG", 2), dim=3)
        S = model.stiffness.pk2(green_lagrange(model.system.u))
        self.S_expr = fem.Expression(ufl.as_vector([S[0, 0], S[1, 1], S[0, 1]]),
                                     W.element.interpolation_points())
        self.S = fem.Function(W)
        self.tree = geometry.BoundingBoxTree(msh, msh.topology.dim)
        zt = 0.5 * (face_band(scene, "top").z_lo + face_band(scene, "top").z_hi)
        zb = 0.5 * (face_band(scene, "bottom").z_lo + face_band(scene, "bottom").z_hi)
        self.rows = {
            "w_top": (zt, None), "w_bottom": (zb, None),
            "sigma_zz_top": (0.5 * hc, self.core), "sigma_zz_bottom": (-0.5 * hc, self.core),
            "tau_core": (0.0, self.core),
            # S_xz of the core at its boundaries: the interface shear tractions
            "tau_top": (0.5 * hc, self.core), "tau_bottom": (-0.5 * hc, self.core),
        }
        self.n_owned_cells = msh.topology.index_map(2).size_local
        self.input_cell = np.asarray(msh.topology.original_cell_index, dtype=np.int64)
        self.cells = {k: self._cells(z, layer) for k, (z, layer) in self.rows.items()}
        # under MPI a station on a partition boundary is found on two ranks: the rank holding
        # the lowest input cell samples it (the same cell as in a serial run)
        comm = msh.comm
        big = np.iinfo(np.int64).max
        self.mine = {}
        for k, cells in self.cells.items():
            idx = np.where(cells >= 0, self.input_cell[np.maximum(cells, 0)], big)
            best = allreduce_array(comm, idx, MPI.MIN) if comm.size > 1 else idx
            self.mine[k] = (cells >= 0) & (idx == best)

    def _cells(self, z: float, layer: int | None) -> np.ndarray:
        msh = self.model.disc.mesh
        p = np.column_stack([self.x, np.full_like(self.x, z), np.zeros_like(self.x)])
        coll = geometry.compute_colliding_cells(msh, geometry.compute_collisions(self.tree, p), p)
        out = np.full(len(self.x), -1, dtype=np.int32)
        for i in range(len(self.x)):
            cand = coll.links(i)
            cand = [c for c in cand if c < self.n_owned_cells]  # owned cells (MPI)
            if layer is not None:
                cand = [c for c in cand if self.model.stiffness.layer_index[c] == layer]
            if len(cand):  # S is discontinuous: the lowest input cell, whatever the partition
                out[i] = min(cand, key=lambda c: self.input_cell[c])
        return out

    def sample(self, u: np.ndarray) -> dict[str, np.ndarray]:
        """Profile columns at state ``u`` (this also evaluates the contact state there)."""
        system = self.model.system
        system.commit(u, 0.0)
        self.S.interpolate(self.S_expr)
        cols = {"x": self.x.copy()}
        for name, (z, _layer) in self.rows.items():
            p = np.column_stack([self.x, np.full_like(self.x, z), np.zeros_like(self.x)])
            cells = self.cells[name]
            ok = self.mine[name]
            vals = np.zeros(len(self.x))
            if name.startswith("w_"):
                vals[ok] = system.u.eval(p[ok], cells[ok])[:, 1]
            else:
                comp = {"sigma_zz_top": 1, "sigma_zz_bottom": 1, "tau_core": 2, "tau_top": 2,
                        "tau_bottom": 2}[name]
                vals[ok] = self.S.eval(p[ok], cells[ok])[:, comp]
            comm = self.model.disc.mesh.comm
            cols[name] = allreduce_array(comm, vals, MPI.SUM) if comm.size > 1 else vals
        for iface in ("top", "bottom"):
            lips = {"p_contact": np.zeros(len(self.x)), "gap": np.zeros(len(self.x)),
                    "sliding": np.zeros(len(self.x))}
            for pair, state, where in zip(self.model.contact_pairs, system.last_contact,
                                          self.model.contact_interfaces, strict=True):
                if where != iface:
                    continue
                order = np.argsort(pair.x_ref)
                xs = pair.x_ref[order]
                inside = (self.x >= xs[0] - GEOM_TOL) & (self.x <= xs[-1] + GEOM_TOL)
                for name, values in (("p_contact", state.pressure), ("gap", state.gap),
                                     ("sliding", state.slip)):
                    lips[name][inside] += np.interp(self.x[inside], xs, values[order])
            for name, values in lips.items():
                cols[f"{name}_{iface}"] = values
            damage = self._damage(iface)
            if damage is not None:
                cols[f"damage_{iface}"] = damage
        return cols

    def _damage(self, iface: str) -> np.ndarray | None:
        """The committed damage along a growing interface (1 on its debonds), else None."""
        pairs = [(p, z) for p, where in zip(self.model.contact_pairs,
                                            self.model.contact_interfaces, strict=True)
                 if where == iface for z in p.cohesive]
        if not pairs:
            return None
        d = np.zeros(len(self.x))
        for deb in self.model.scene.debonds_on(iface):  # the debonds themselves
            d[(self.x >= deb.start - GEOM_TOL) & (self.x <= deb.end + GEOM_TOL)] = 1.0
        for _pair, z in pairs:
            order = np.argsort(z.x)
            xs = z.x[order]
            inside = (self.x >= xs[0] - GEOM_TOL) & (self.x <= xs[-1] + GEOM_TOL)
            d[inside] = np.interp(self.x[inside], xs, z.damage[order])
        return d


def _bands(model: Model2D) -> list[str]:
    from sandwich.plane2d.model import layer_bands

    return [b.name for b in layer_bands(model.scene)]
