"""Energy release rate at every debond tip of the 2D model: the virtual crack closure technique.

G of a crack extension by the closure length Δ (a physical length, mm, kept fixed while the mesh
changes) is the work needed to close the crack again over Δ:

    G(Δ) = −1/(2 Δ) ∫_0^Δ t(s) · δ(Δ − s) ds

with t the traction (MPa) that the core exerts on the face at the distance s ahead of the tip and
δ(r) = u_face − u_core the opening of the lips at the distance r behind it (t · δ < 0 where the
core holds the face back). Discretely (Raju's VCCT for quadratic elements
generalised to a closure length of several elements): t is represented by the consistent nodal
forces F_k of the interface nodes ahead of the tip within Δ, the forces that the core exerts on
the face there, i.e. the face cells' internal force at those nodes (the face is free of
external load on the interface); the opening at the mirrored distance Δ − s_k behind the tip is
the Q2 interpolation of the lip-pair openings along the lip (zero at the tip). Then

    G = −1/(2 b Δ) Σ_k F_k · δ(Δ − s_k),

which for Δ = one element and a uniform mesh is Raju's formula (the tip force with the opening
of the corner pair behind, the mid-side force ahead with the mid-side pair behind).

Mode split: F and δ are resolved on the deformed interface at the tip (tangent t from the tip
node to its first neighbour ahead, normal n from the core into the face): G_I from the normal
components, G_II from the tangential ones. Lips that interpenetrate (penalty contact) give a
spurious negative G_I: it is reported as 0 (closed crack, pure mode II) and G = G_I + G_II.
On a bimaterial interface the split depends on Δ (the oscillatory near-tip field, ~Δ^(2iε)); G
does not. All in N/mm (= kJ/m²).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from sandwich.plane2d.constitutive import green_lagrange
from sandwich.plane2d.model import GEOM_TOL, Model2D, interface_z
from sandwich.results.fracture import TipRelease, column_names, history_columns  # noqa: F401

LAYER_OF_FACE = {"top": 2, "bottom": 0}  # PlaneStressStiffness.layer_index of the face bands
JIT = {"cffi_extra_compile_args": ["-O2"]}


@dataclass(frozen=True)
class TipGeometry:
    """One debond tip of the mesh: nodes ahead (with their distance) and lip pairs behind."""

    debond: int
    tip: str  # "start" | "end"
    interface: str  # "top" | "bottom"
    x_tip: float  # mm
    ahead: np.ndarray  # (m,) input nodes on the bonded interface, tip first, s < Δ
    s_ahead: np.ndarray  # (m,) distance ahead of the tip (mm)
    behind_face: np.ndarray  # (p,) face-lip input nodes, nearest the tip first
    behind_core: np.ndarray  # (p,) the coincident core-lip input nodes
    r_behind: np.ndarray  # (p,) distance behind the tip (mm)




def default_closure_length(scene) -> float:
    """Δ = the thinner face's thickness (mm): the length scale of the face's near-tip field."""
    return float(min(scene.top.thickness, scene.bottom.thickness))


def tip_geometries(model: Model2D, closure_length: float) -> list[TipGeometry]:
    """Every debond tip present in the mesh (open mouths at beam ends have none).

    Not the tips of a debond grown by a cohesive law: its lips run on over its spans, where
    the law holds them (no crack closure there); the law's tip positions are its columns
    (:mod:`sandwich.plane2d.cohesive`).
    """
    mesh, scene = model.mesh, model.scene
    pts = np.asarray(mesh.points)[:, :2]
    named = getattr(mesh, "point_nodes", {}) or {}
    lip_pairs = getattr(mesh, "lip_pairs", {}) or {}
    out = []
    for i, debond in enumerate(scene.debonds):
        if i not in lip_pairs or len(lip_pairs[i]) == 0:
            continue
        if debond.growth is not None and debond.growth.cohesive:
            continue
        pairs = np.asarray(lip_pairs[i])
        lip = set(map(int, pairs.ravel()))
        z = interface_z(scene, debond.interface)
        on_itf = np.flatnonzero(np.abs(pts[:, 1] - z) < GEOM_TOL)
        on_itf = np.array([n for n in on_itf if int(n) not in lip], dtype=np.int64)
        for tip in ("start", "end"):
            key = f"debond{i}_tip_{tip}"
            if key not in named:
                continue
            node = int(named[key])
            x_tip = float(pts[node, 0])
            ahead_sign = -1.0 if tip == "start" else 1.0  # the bonded side
            s = ahead_sign * (pts[on_itf, 0] - x_tip)
            keep = (s > -GEOM_TOL) & (s < closure_length - GEOM_TOL)
            order = np.argsort(s[keep])
            r = -ahead_sign * (pts[pairs[:, 0], 0] - x_tip)
            near = np.argsort(r)
            out.append(TipGeometry(i, tip, debond.interface, x_tip, on_itf[keep][order],
                                   np.maximum(s[keep][order], 0.0), pairs[near, 0],
                                   pairs[near, 1], r[near]))
    return out


def opening_at(r_nodes: np.ndarray, delta_nodes: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Piecewise-quadratic (Q2 edge) interpolation of the opening along the lip.

    ``r_nodes`` (p,) distances of the lip nodes behind the tip, nearest first, ``delta_nodes``
    (p, 2) their openings; the tip (r = 0, δ = 0) is prepended. Edges are consecutive triplets
    (corner, mid-side, corner) starting at the tip. Points outside the lip get the last edge's
    polynomial (never used for r ≤ the lip length); r ≤ 0 gives 0.
    """
    rr = np.concatenate([[0.0], r_nodes])
    dd = np.vstack([np.zeros((1, 2)), delta_nodes])
    n_edges = (len(rr) - 1) // 2
    out = np.zeros((len(r), 2))
    for j, x in enumerate(r):
        if x <= 0.0 or n_edges == 0:
            continue
        e = min(int(np.searchsorted(rr[2::2], x)), n_edges - 1)  # edge with x ≤ its end corner
        x0, x1, x2 = rr[2 * e: 2 * e + 3]
        l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
        l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
        l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1))
        out[j] = l0 * dd[2 * e] + l1 * dd[2 * e + 1] + l2 * dd[2 * e + 2]
    return out


class VcctEvaluator:
    """G, G_I, G_II at every tip of a 2D model, for any displacement state (serial and MPI)."""

    def __init__(self, model: Model2D, closure_length: float | None = None):
        self.model = model
        self.closure_length = (default_closure_length(model.scene) if closure_length is None
                               else float(closure_length))
        if not (np.isfinite(self.closure_length) and self.closure_length > 0):
            raise ValueError(f"closure length must be positive, got {closure_length!r}")
        self.tips = tip_geometries(model, self.closure_length)
        sys = model.system
        V = sys.V
        self._forms = {}
        self._vecs = {}
        Q0 = fem.FunctionSpace(V.mesh, ("DG", 0))
        v = ufl.TestFunction(V)
        stiff = model.stiffness
        for face in sorted({t.interface for t in self.tips}):
            chi = fem.Function(Q0)  # 1 on the face's cells
            n = len(stiff.layer_index)
            chi.x.array[:n] = (stiff.layer_index == LAYER_OF_FACE[face]).astype(float)
            S = stiff.pk2(green_lagrange(sys.u))
            P = S + ufl.grad(sys.u) * S
            form = fem.form(chi * model.scene.width * ufl.inner(P, ufl.grad(v)) * ufl.dx,
                            jit_params=JIT)
            self._forms[face] = form
            self._vecs[face] = fem_petsc.create_vector(form)
        # every input node the evaluation needs, compact
        needed = [t.ahead for t in self.tips] + [t.behind_face for t in self.tips] + [
            t.behind_core for t in self.tips]
        self._nodes = np.unique(np.concatenate(needed)) if needed else np.zeros(0, np.int64)
        self._index = {int(n): k for k, n in enumerate(self._nodes)}
        n_owned_blocks = V.dofmap.index_map.size_local
        d = model.disc.node_to_block
        own = [(k, d[int(n)]) for k, n in enumerate(self._nodes)
               if int(n) in d and d[int(n)] < n_owned_blocks]
        self._own_k = np.array([k for k, _ in own], dtype=np.int64)
        self._own_blk = np.array([b for _, b in own], dtype=np.int64)

    def supported_tips(self) -> list[str]:
        """Tips with a support on a node within Δ ahead (its reaction enters F): ``["0_end"]``.

        The face cells' internal force at a supported node also holds the support's reaction, so
        G there is not the closure work. Decided over all ranks.
        """
        sys = self.model.system
        fixed = set((sys.bc_dofs // 2).tolist())
        d = self.model.disc.node_to_block
        out = []
        for t in self.tips:
            local = any(int(n) in d and d[int(n)] in fixed for n in t.ahead)
            if sys.comm.allreduce(int(local), op=MPI.MAX):
                out.append(f"{t.debond}_{t.tip}")
        return out

    @property
    def closure_over_element(self) -> float:
        """Smallest Δ / (length of the lip element at a tip): below 1 the estimate is poor.

        Measured on the peel couple (coarse mesh, 1 mm tip elements): G −11 % at Δ = half an
        element, within 0.6 % from one element on (``docs/fracture.md``).
        """
        lengths = [float(t.r_behind[1]) for t in self.tips if len(t.r_behind) > 1]
        return self.closure_length / max(lengths) if lengths else float("inf")

    def _gather(self, local_blocks: np.ndarray) -> np.ndarray:
        """(n_needed, 2) values of the needed nodes from this rank's (owned) block array."""
        out = np.zeros((len(self._nodes), 2))
        if len(self._own_k):
            out[self._own_k] = local_blocks[self._own_blk]
        comm = self.model.system.comm
        if comm.size > 1:
            tot = np.zeros_like(out)
            comm.Allreduce(out, tot, op=MPI.SUM)
            out = tot
        return out

    def evaluate(self, u: np.ndarray) -> list[TipRelease]:
        """G at every tip for the owned DOF vector ``u`` (the path solver's state)."""
        sys = self.model.system
        sys._set_u(u)
        forces = {}
        for face, form in self._forms.items():
            b = self._vecs[face]
            with b.localForm() as loc:
                loc.set(0.0)
            fem_petsc.assemble_vector(b, form)
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            forces[face] = self._gather(b.array.reshape(-1, 2))
        disp = self._gather(sys.u.x.array.reshape(-1, 2))
        X = np.asarray(self.model.mesh.points)[:, :2]
        out = []
        width = self.model.scene.width
        delta_len = self.closure_length
        for t in self.tips:
            idx = [self._index[int(n)] for n in t.ahead]
            F = forces[t.interface][idx]  # core on face, N
            jf = [self._index[int(n)] for n in t.behind_face]
            jc = [self._index[int(n)] for n in t.behind_core]
            delta_nodes = disp[jf] - disp[jc]  # u_face − u_core, mm
            delta = opening_at(t.r_behind, delta_nodes, delta_len - t.s_ahead)
            # deformed interface direction at the tip, towards the bonded side, and the normal
            # from the core into the face
            if len(t.ahead) > 1:
                a, b_ = int(t.ahead[0]), int(t.ahead[1])
                chord = (X[b_] + disp[self._index[b_]]) - (X[a] + disp[self._index[a]])
            else:
                chord = np.array([1.0, 0.0])
            tang = chord / np.linalg.norm(chord)
            tang = tang if tang[0] >= 0 else -tang
            normal = np.array([-tang[1], tang[0]])
            if t.interface == "bottom":
                normal = -normal
            scale = -1.0 / (2.0 * width * delta_len)
            gi = scale * float(np.sum((F @ normal) * (delta @ normal)))
            gii = scale * float(np.sum((F @ tang) * (delta @ tang)))
            gi = max(gi, 0.0)
            out.append(TipRelease(t.debond, t.tip, gi + gii, gi, gii, delta_len))
        return out

