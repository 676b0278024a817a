"""Where the core needs which level: explicit zones, or the ``"auto"`` error indicator.

The core hierarchy (:mod:`sandwich.beam.core_basis`) is nested: the space of levels ℓ is contained
in that of levels ℓ + 1 everywhere. For a linear problem K u = f, Galerkin orthogonality of the
nested solutions gives the exact identity

    ‖u⁺ − u‖²_K = fᵀu⁺ − fᵀu,

so the relative change of the compliance fᵀu between the current levels and the levels raised by
LOOKAHEAD (saturation assumption: the raised solution is much closer to the limit) estimates the
relative error of the current levels in stiffness — the error of a load at a given deflection,
which is what a user reads off the path. Its element contributions
η_e = Σ_blocks of e (u⁺ − u)ᵀ K_e (u⁺ − u) say where the enrichment pays. :func:`auto_levels`
raises the elements that carry the most of it (Dörfler marking) until the estimate is below the
tolerance or every element is at the highest level allowed.

The indicator is evaluated on the linear (small-displacement) step with unilateral contact,
:func:`sandwich.beam.linear_step.linear_solution`. Along a nonlinear path the levels are
re-checked on the last converged state: :func:`state_shares` says where (a residual indicator, no
solve), and the path is rerun with those elements raised; the change of the end load between the
two runs is the estimate (:mod:`sandwich.beam.core_controller`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from sandwich.beam.cohesive import carry_damage
from sandwich.beam.core_basis import MAX_LEVEL
from sandwich.beam.dofs import NODE_DOFS
from sandwich.beam.mesh import BeamMesh
from sandwich.beam.model import BeamModel

TIE_TOLERANCE = 1e-6  # relative: shares this close to the Dörfler threshold are marked together
DORFLER_KEEP = 0.5  # mark until the unmarked estimate is below this fraction of the tolerance
# The indicator compares with the levels raised by LOOKAHEAD. With one level the saturation
# assumption fails where the level converges slowly (point supports: the error falls by only
# ~2 per level on a coarse x-mesh) and the estimate was half the true error (linear bend,
# 60 elements: 0.27 % for a true 0.53 % at level 2); two levels give 0.40 % there and match the
# truth at level 4 (tests/beam/test_core_auto.py).
LOOKAHEAD = 2
DORFLER_FRACTION = 0.5  # along a path: raise the elements carrying half the state shares


@dataclass
class LevelChoice:
    """The core levels chosen for a scene, and how."""

    levels: np.ndarray  # (E,) level of each element
    how: str  # "explicit" | "auto"
    estimate: float | None = None  # estimated relative stiffness error of these levels
    passes: list[dict] = field(default_factory=list)  # per auto pass: estimate, elements raised

    def zones(self, mesh: BeamMesh) -> list[dict]:
        """Maximal stretches of equal level: ``{"start", "end", "level"}`` in mm."""
        out: list[dict] = []
        for e, level in enumerate(self.levels):
            a, b = float(mesh.x[e]), float(mesh.x[e + 1])
            if out and out[-1]["level"] == int(level):
                out[-1]["end"] = b
            else:
                out.append({"start": a, "end": b, "level": int(level)})
        return out


def zone_levels(mesh: BeamMesh, base: int, zones: tuple) -> np.ndarray:
    """Element levels: ``base``, raised to a zone's level on elements overlapping the zone."""
    levels = np.full(mesh.n_elements, int(base), dtype=int)
    a, b = mesh.x[:-1], mesh.x[1:]
    for z in zones:
        inside = (b > z.start) & (a < z.end)
        levels[inside] = np.maximum(levels[inside], int(z.level))
    return levels


def transfer(u: np.ndarray, src: BeamModel, dst: BeamModel) -> np.ndarray:
    """Free DOFs of ``dst`` holding the field of ``src`` (enrichment amplitudes it lacks: 0).

    Both models discretise the same scene on the same mesh; only the core levels differ. The
    hierarchical order of the enrichment functions is the same for every level, so node i's
    first k amplitudes mean the same in both. A cohesive interface's damage goes with the
    state (:func:`~sandwich.beam.cohesive.carry_damage`).
    """
    n = src.mesh.n_nodes
    full = src.expand(u)
    m_src = (full.size - NODE_DOFS * n) // n
    m_dst = (dst.dof_map.n_full - NODE_DOFS * n) // n
    out = np.zeros(dst.dof_map.n_full)
    out[:NODE_DOFS * n] = full[:NODE_DOFS * n]
    k = min(m_src, m_dst)
    if k:
        modes = out[NODE_DOFS * n:].reshape(n, m_dst)
        modes[:, :k] = full[NODE_DOFS * n:].reshape(n, m_src)[:, :k]
    free = np.zeros(dst.size)
    live = dst.dof_map.free >= 0
    free[dst.dof_map.free[live]] = dst.dof_map.sign[live] * out[live]
    carry_damage(src, dst, u)
    return free


def element_energies(model: BeamModel, blocks: list[np.ndarray], d_full: np.ndarray) -> np.ndarray:
    """Σ over each element's layer blocks of dᵀ K_e d (N·mm), shape ``(E,)``.

    ``blocks`` are :meth:`BeamModel.full_response` tangent blocks (top, core groups, bottom,
    contact); contact blocks are left out (they belong to no element).
    """
    η = np.zeros(model.mesh.n_elements)
    every = np.arange(model.mesh.n_elements)
    families = [every] + [g.elements for g in model.core] + [every]
    for els, dofs, K in zip(families, model.block_dofs, blocks, strict=False):
        d = d_full[dofs]
        η[els] += np.einsum("bi,bij,bj->b", d, K, d)
    return η


def dorfler(η: np.ndarray, excess: float) -> np.ndarray:
    """Smallest set of entries (largest first) whose sum reaches ``excess``: a boolean mask.

    Entries equal to the smallest one taken, to within TIE_TOLERANCE, are taken too, so that
    mirror-image elements of a symmetric scene get the same level.
    """
    order = np.argsort(η)[::-1]
    n = min(int(np.searchsorted(np.cumsum(η[order]), excess) + 1), η.size)
    threshold = η[order[n - 1]] * (1 - TIE_TOLERANCE)
    return η >= max(threshold, np.finfo(float).tiny)


def linear_estimate(
    cur: BeamModel, u: np.ndarray, up: BeamModel, u_up: np.ndarray, probe: str | None
) -> tuple[float, np.ndarray]:
    """Relative error of the linear answer at ``cur``'s levels, and its element shares.

    With a target probe c: |c·u⁺ − c·u| / |c·u⁺| (the relative error of the load at a given
    deflection); without: the compliance change (fᵀu⁺ − fᵀu)/fᵀu⁺ = ‖u⁺ − u‖²_K / fᵀu⁺.
    Shares: :func:`element_energies` of u⁺ − u, scaled to the estimate.
    """
    if probe is not None:
        c_up, c_cur = float(up.probe_vector(probe) @ u_up), float(cur.probe_vector(probe) @ u)
    else:
        c_up, c_cur = float(up.f_ref @ u_up), float(cur.f_ref @ u)
    if not (np.isfinite(c_up) and abs(c_up) > 0):
        raise ValueError("the linear step does not move the target: cannot estimate the core's "
                         "error (are the loads and supports right?)")
    estimate = abs(c_up - c_cur) / abs(c_up)
    d_full = up.expand(u_up - transfer(u, cur, up))
    η = element_energies(up, up.full_response(np.zeros(up.dof_map.n_full),
                                              contact_blocks=False)[1], d_full)
    return estimate, (η * (estimate / η.sum()) if η.sum() > 0 else η)


def state_shares(cur: BeamModel, u: np.ndarray, load_factor: float, up: BeamModel) -> np.ndarray:
    """Where a converged nonlinear state wants more core levels: element shares, shape ``(E,)``.

    The state is carried into the raised model ``up`` (its new enrichment amplitudes zero) and
    the residual r = f_int⁺ − λ f is read on those new amplitudes: r_j² / K_jj is the energy of
    the diagonally scaled correction of DOF j (Jacobi), split half and half between the two
    elements of its node. No solve with K: next to a critical point K is nearly singular and any
    K⁻¹-based magnitude is meaningless there (a bordered Newton step from fig. 5's state at −5 mm
    gave 17 %, and Newton in the raised model from that state diverges), while the residual and
    the diagonal stay well defined. The *magnitude* of the error comes from rerunning the path
    (:mod:`sandwich.beam.core_controller`).
    """
    v = transfer(u, cur, up)
    r = up.internal_force(v) - load_factor * up.f_ref
    diag = up.tangent(v).diagonal()
    n = up.mesh.n_nodes
    m_up = (up.dof_map.n_full - NODE_DOFS * n) // n
    m_cur = (cur.dof_map.n_full - NODE_DOFS * n) // n
    free = up.dof_map.free[NODE_DOFS * n:].reshape(n, m_up)
    held = np.zeros((n, m_up), dtype=bool)  # the amplitudes cur already had at each node
    held[:, :m_cur] = cur.dof_map.free[NODE_DOFS * n:].reshape(n, m_cur) >= 0
    new = (free >= 0) & ~held
    node = np.zeros(n)
    rows, js = np.nonzero(new)
    k = free[rows, js]
    np.add.at(node, rows, r[k] ** 2 / np.maximum(np.abs(diag[k]), np.finfo(float).tiny))
    return 0.5 * (node[:-1] + node[1:])


def raise_levels(
    levels: np.ndarray, shares: np.ndarray, excess: float, max_level: int
) -> np.ndarray:
    """Raise by one the elements carrying ``excess`` of the shares (Dörfler), up to max_level."""
    raisable = levels < max_level
    share = np.where(raisable, shares, 0.0)
    marked = dorfler(share, min(excess, share.sum()))
    return np.where(marked & raisable, levels + 1, levels)


def auto_levels(
    build: Callable[[np.ndarray], BeamModel],
    solve_linear: Callable[[BeamModel], np.ndarray],
    n_elements: int,
    tolerance: float,
    max_level: int,
    probe: str | None = None,
) -> LevelChoice:
    """Choose element levels with the compliance indicator on the linear step.

    Parameters
    ----------
    build
        Model at given element levels.
    solve_linear
        Free DOFs of the linear solution at the reference load (contact active set included).
    n_elements
        Elements of the mesh.
    tolerance
        Target relative error (e.g. 0.01).
    max_level
        Highest level the choice may use (the indicator looks one level higher, up to
        :data:`~sandwich.beam.core_basis.MAX_LEVEL`).
    probe
        The analysis' target probe (see :func:`linear_estimate`), or None.
    """
    levels = np.ones(n_elements, dtype=int)
    passes: list[dict] = []
    cur = build(levels)
    u = solve_linear(cur)
    while True:
        up = build(lookahead_levels(levels))
        estimate, shares = linear_estimate(cur, u, up, solve_linear(up), probe)
        passes.append({"stage": "linear step", "elements_per_level": level_counts(levels),
                       "estimate": estimate})
        if estimate <= tolerance or not np.any(levels < max_level):
            return LevelChoice(levels=levels, how="auto", estimate=estimate, passes=passes)
        levels = raise_levels(levels, shares, estimate - DORFLER_KEEP * tolerance, max_level)
        cur = build(levels)
        u = solve_linear(cur)


def lookahead_levels(levels: np.ndarray) -> np.ndarray:
    """The comparison levels of the indicator: LOOKAHEAD above each element's, capped."""
    return np.minimum(np.asarray(levels) + LOOKAHEAD, MAX_LEVEL)


def level_counts(levels: np.ndarray) -> dict[str, int]:
    """Number of elements at each level present, ``{"1": 221, "2": 19}``."""
    values, counts = np.unique(levels, return_counts=True)
    return {str(int(v)): int(c) for v, c in zip(values, counts, strict=True)}
