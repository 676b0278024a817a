"""Where the Green-strain core crushes as a material: stretch and loss of ellipticity.

The St Venant–Kirchhoff law of eq. (27) (S = C : E, E = (FᵀF − I)/2) is not a foam's: in
uniaxial compression its nominal stress P = E λ (λ² − 1)/2 has dP/dλ = E (3λ² − 1)/2, which
vanishes at the stretch λ = 1/√3 ≈ 0.577 and is negative below it — the material softens, then
turns inside out. In a general plane state the same material limit is the loss of strong
ellipticity of the first elasticity tensor A = ∂P/∂F,

    A_iJkL = δ_ik S_JL + F_iM C_MJNL F_kN,      q(F) = min over unit a, N of a_i N_J A_iJkL a_k N_L,

(q > 0: the material is stable against every localised mode a ⊗ N). In uniaxial compression
of the isotropic core (ν = 0.25) q vanishes at λ = 0.601, in an oblique mode (N ≈ 64° from the
axis), before dP/dλ = 0 at 1/√3: a localised mode cannot relax sideways (the axial mode
a = N = e_z, S_zz + λ² Q_z = 0, would come only at λ = 0.565; tests/reference2d). A 2D path whose
load turns where some core point has q ≤ 0 has met this material limit, not a buckling of the
structure (fig. 4 under the patch, the knock-down study's 75-80-mm debonds at their inner tip,
fig. 7 c2 at the clamp; not fig. 6, whose maximum is the debonded face's snap;
docs/reference2d.md).
The beam's core, a through-thickness polynomial, smooths such a local compression out.

:class:`CoreCrushing` evaluates F at the 3×3 Gauss points of every core cell (material points;
not at the nodes, where a crack tip is singular, nor only at the cell centre, a quarter of a
cell from where a tip's crushing lives) and returns the smallest principal stretch and the
smallest q / q(I) over the core.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem

SVK_LIMIT_STRETCH = 1.0 / np.sqrt(3.0)  # where dP/dλ = 0 in uniaxial compression (above)
DIRECTIONS = 180  # unit normals N at 1° over the half circle for the minimum over N
GAUSS_DEGREE = 5  # the 3×3 Gauss points of each cell: the material points sampled


@dataclass(frozen=True)
class CoreState:
    """The core's worst material point at one state (its Gauss points; x, z in mm)."""

    min_stretch: float  # smallest principal stretch √(eig C)
    ellipticity: float  # smallest q(F) / q(I): 1 at rest, ≤ 0 where the material is unstable
    x: float  # where the ellipticity is smallest
    z: float


def plane_stress_tensor(Qx: float, Qz: float, Q: float, G: float) -> np.ndarray:
    """C_MJNL of eq. (27) as a 2×2×2×2 array (index 0 = x, 1 = z)."""
    C = np.zeros((2, 2, 2, 2))
    C[0, 0, 0, 0], C[1, 1, 1, 1] = Qx, Qz  # σ_x = Q_x ε_x + Q ε_z, σ_z = Q_z ε_z + Q ε_x
    C[0, 0, 1, 1] = C[1, 1, 0, 0] = Q
    for M, J in ((0, 1), (1, 0)):
        for N, L in ((0, 1), (1, 0)):
            C[M, J, N, L] = G  # τ = G_zx γ, γ = 2 E_xz
    return C


def ellipticity(F: np.ndarray, C: np.ndarray) -> np.ndarray:
    """q(F) = min over unit a, N of (a ⊗ N) : A : (a ⊗ N), for each F of shape (m, 2, 2).

    For each direction N the acoustic tensor is Q(N) = F D(N) Fᵀ + (N · S N) I with
    D_MN = C_MJNL N_J N_L (symmetric, C has the major symmetry); q is the smallest eigenvalue of
    Q(N) over DIRECTIONS normals, formed entry by entry on (m, DIRECTIONS) arrays.
    """
    E = 0.5 * (np.einsum("cki,ckj->cij", F, F) - np.eye(2))  # E = (FᵀF − I)/2
    S = np.einsum("MJNL,cNL->cMJ", C, E)  # S = C : E
    theta = np.linspace(0.0, np.pi, DIRECTIONS, endpoint=False)
    N = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    D = np.einsum("MJNL,tJ,tL->tMN", C, N, N)  # (t, 2, 2)
    d00, d01, d11 = D[None, :, 0, 0], D[None, :, 0, 1], D[None, :, 1, 1]
    f00, f01, f10, f11 = (F[:, i, j, None] for i, j in ((0, 0), (0, 1), (1, 0), (1, 1)))
    g = (S[:, 0, 0, None] * N[None, :, 0] ** 2 + 2.0 * S[:, 0, 1, None] * N[None, :, 0]
         * N[None, :, 1] + S[:, 1, 1, None] * N[None, :, 1] ** 2)  # N · S N
    q00 = f00 * f00 * d00 + 2.0 * f00 * f01 * d01 + f01 * f01 * d11 + g
    q11 = f10 * f10 * d00 + 2.0 * f10 * f11 * d01 + f11 * f11 * d11 + g
    q01 = f00 * f10 * d00 + (f00 * f11 + f01 * f10) * d01 + f01 * f11 * d11
    smallest = 0.5 * (q00 + q11) - np.sqrt(0.25 * (q00 - q11) ** 2 + q01**2)  # 2×2 eigenvalue
    return smallest.min(axis=1)


def smallest_ellipticity(F: np.ndarray, C: np.ndarray, first: int = 64,
                         stretch: np.ndarray | None = None) -> tuple[int, float]:
    """The index and value of the smallest :func:`ellipticity` over the points F, (m, 2, 2).

    q is evaluated only where its lower bound can beat the smallest value found:
    q(F) ≥ λ_min(FᵀF) · min_N λ_min(D(N)) + λ_min(S) (F D Fᵀ ≥ λ_min(D) F Fᵀ, N · S N ≥
    λ_min(S)); first on the ``first`` points of smallest bound, then on every point whose bound
    lies below their minimum. The same answer as evaluating every point. ``stretch``: the
    points' :func:`principal_stretch`, where the caller has it.
    """
    E = 0.5 * (np.einsum("cki,ckj->cij", F, F) - np.eye(2))
    S = np.einsum("MJNL,cNL->cMJ", C, E)
    theta = np.linspace(0.0, np.pi, DIRECTIONS, endpoint=False)
    N = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    d_min = np.linalg.eigvalsh(np.einsum("MJNL,tJ,tL->tMN", C, N, N))[:, 0].min()
    stretch = principal_stretch(F) if stretch is None else stretch
    bound = (stretch**2 * d_min
             + np.linalg.eigvalsh(S)[:, 0])  # λ_min(FᵀF) = (smallest principal stretch)²
    order = np.argsort(bound)
    head = order[:first]
    q_head = ellipticity(F[head], C)
    best = float(q_head.min())
    rest = order[first:][bound[order[first:]] < best]
    if len(rest):
        q_rest = ellipticity(F[rest], C)
        if q_rest.min() < best:
            return int(rest[np.argmin(q_rest)]), float(q_rest.min())
    return int(head[np.argmin(q_head)]), best


def principal_stretch(F: np.ndarray) -> np.ndarray:
    """Smallest principal stretch √(smallest eigenvalue of FᵀF) for each F, (m, 2, 2)."""
    C = np.einsum("cki,ckj->cij", F, F)
    half_trace = 0.5 * (C[:, 0, 0] + C[:, 1, 1])
    radius = np.sqrt(0.25 * (C[:, 0, 0] - C[:, 1, 1]) ** 2 + C[:, 0, 1] ** 2)
    return np.sqrt(np.maximum(half_trace - radius, 0.0))


class CoreCrushing:
    """The core's smallest stretch and ellipticity at a 2D model's states."""

    def __init__(self, model):
        """The expressions of ∇u and x at the core cells' Gauss points of ``model`` (Model2D)."""
        import basix

        from sandwich.plane2d.model import layer_bands

        self._system = model.system
        msh = model.disc.mesh
        points, _ = basix.make_quadrature(basix.QuadratureType.gauss_jacobi,
                                          basix.CellType.quadrilateral, GAUSS_DEGREE)
        self._grad = fem.Expression(ufl.grad(self._system.u), points)
        bands = layer_bands(model.scene)
        core = [b.name for b in bands].index("core")
        n_cells = msh.topology.index_map(2).size_local
        self._cells = np.flatnonzero(
            model.stiffness.layer_index[:n_cells] == core).astype(np.int32)
        where = fem.Expression(ufl.SpatialCoordinate(msh), points)
        self._points = (where.eval(self._cells).reshape(-1, 2) if len(self._cells)
                        else np.empty((0, 2)))
        m = bands[core].material
        self._C = plane_stress_tensor(m.Qx, m.Qz, m.Q, m.Gzx)
        self._q0 = float(ellipticity(np.eye(2)[None], self._C)[0])
        self._comm = msh.comm

    def at(self, u: np.ndarray) -> CoreState:
        """The worst core Gauss point at state ``u`` (owned DOFs), over every rank."""
        self._system._set_u(u)
        if len(self._cells):
            F = np.eye(2) + self._grad.eval(self._cells).reshape(-1, 2, 2)  # F = I + ∇u
            stretch = principal_stretch(F)
            i, q = smallest_ellipticity(F, self._C, stretch=stretch)
            local = (q / self._q0, float(stretch.min()), *map(float, self._points[i]))
        else:
            local = (np.inf, np.inf, 0.0, 0.0)
        everywhere = self._comm.allgather(local)
        q, _, x, z = min(everywhere, key=lambda t: t[0])
        stretch = min(t[1] for t in everywhere)
        if not np.isfinite(q):
            raise ValueError("the 2D model has no core cells: nothing to evaluate")
        return CoreState(stretch, q, x, z)


def crushing_warning(first: CoreState, step: int, load_factor: float,
                     before: tuple[int, float] | None = None) -> str:
    """What a run is told from the first state whose core lost ellipticity (else ``""``).

    ``before`` is the (step, λ) of the state before it: the loss lies in that step.
    """
    if first.ellipticity > 0.0:
        return ""
    when = (f"in step {step} (λ {before[1]:.6g} → {load_factor:.6g})" if before is not None
            else f"at step {step} (λ = {load_factor:.6g})")
    return (f"the core crushed as a material {when} at x = {first.x:.4g}, "
            f"z = {first.z:.4g} mm (the Green-strain law lost ellipticity there, smallest "
            f"principal stretch {first.min_stretch:.3g}); a load maximum "
            "in or after that step may be this material limit of the St Venant-Kirchhoff core "
            "rather than the structure's: compare with the beam, whose core does not localise "
            "(docs/reference2d.md)")
