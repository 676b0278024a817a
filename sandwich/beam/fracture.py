"""Energy release rate at every debond tip of the beam model, from the interface ties.

At a bonded node the core's boundary DOFs follow the face's (section 2.3, imposed by
elimination): u_c = u_f, w_c = w_f, w_c,x = w_f,x (top: u_ct = u_tb, w_ct = w_t, w_ct,x = w_t,x;
bottom: u_cb = u_bt, w_cb = w_b, w_cb,x = w_b,x). The tie reaction R_k at a bonded node k is
the force (N) or moment (N·mm) that the face exerts on the core's tied DOF j ∈ {u, w, w,x},
i.e. the core layer's internal force on that DOF (eq. 19, the core elements on both sides of
the node; the tie itself carries no stiffness of its own); the jump δ = face DOF − core DOF
of a tie pair at an untied node is the sliding, the opening (mm) and the rotation jump (rad).

The virtual crack closure estimate of G, per unit crack area, over a closure length Δ of
n tip elements (the mesh fills a debond with its smallest elements):

    G = 1/(2 b Δ) Σ_k R_k · δ(Δ − s_k)

over the bonded nodes at the distance s_k < Δ ahead of the tip (the tip node included), δ
interpolated linearly at the mirrored distance Δ − s_k behind it: the closure integral
∫₀^Δ t(s) δ(Δ − s) ds / (2Δ) with the ties' force representation, as in 2D. The history
columns use n = round(t / h) ≥ 1 elements of length h at the tip, t the thinner face's
thickness (:func:`closure_elements`): Δ ≈ t, the 2D model's default closure length, so both
models close the crack over the same physical length whatever the mesh or the core level.

Measured (``benchmarks/results/fracture/core_levels.md``, docs/fracture.md): on the closed-form
cases, Δ ≈ t is within 1.1 % of closed form for core levels 1-4 and 240-960 elements, its
split (G_II/G 0.96-0.98 sliding) independent of both. One element (R at the tip node × δ at
the first node behind, the estimate until 2026-12-01) was +0.6 % (level 1) to +2.7 % (level 4)
high and did not converge with the mesh at levels > 1 (a richer core concentrates the tie
forces at the tip node); 8 elements were within 0.3 % there, but once a debonded face peels
at a large rotation (fig. 5 past its buckling) G falls with Δ beyond about two face
thicknesses in both models (beam: −18 % at 8 elements = 2.3 mm; 2D: −11 % at 2 mm, while
Δ ≤ 1 mm agree with its J-integral within 2 %): the opening behind the tip is no longer
self-similar over Δ. Δ ≈ t is inside that range.

Mode split (the beam-theory, "global" partition): G_II from the tangential forces × sliding,
G_I from the normal forces × opening plus the interface moments × the rotation jumps (a moment
is a couple of normal interface tractions). Forces and displacements are resolved on the core
boundary at the tip, rotated by atan(w_c,x / (1 + u_c,x)) (eq. 15 kinematics), so the split
stays meaningful when the section rotates. A negative G_I (the lips pressed into each other
by the penalty contact, a closed crack) is reported as 0. All in N/mm (= kJ/m²).

A core level that changes near a tip biases G whatever the estimate (the discrete model's
own energy release changes: the level patch is a local inhomogeneity at the tip); the summary
warns (:func:`level_warning`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from sandwich.beam.dofs import TIES, global_dof
from sandwich.results.fracture import TipRelease, column_names, history_columns  # noqa: F401

# A sandwich.beam.model.BeamModel: not imported, the model imports this module (it holds its
# tips and gives their G to every accepted path state).
BeamModel = Any

TIE_ROLES = ("u", "w", "w,x")  # order of the pairs in dofs.TIES
# A core level (sandwich.beam.core_levels) that changes near a tip biases G (measured on the
# closed-form cases, core 10 mm; benchmarks/results/fracture/core_levels.md): level patches of
# 2-6 elements each side of the tip −6 … +4 % with the Δ ≈ t closure (one element −19 … +4 %),
# a patch reaching 5 mm (half the core) behind the tip ≤ 1 %. Warned within the larger of
# this many elements and LEVEL_ZONE core thicknesses of a tip.
LEVEL_NEIGHBOURHOOD = 8
LEVEL_ZONE = 0.5


@dataclass(frozen=True)
class BeamTip:
    """A debond tip of the beam mesh: its node, the first untied node behind it and Δ (mm)."""

    debond: int
    tip: str  # "start" | "end"
    interface: str  # "top" | "bottom"
    node: int
    behind: int
    closure_length: float  # mm, the element between node and behind
    ahead_length: float  # mm, the element on the bonded side



def beam_tips(scene: object, model: BeamModel) -> list[BeamTip]:
    """Every debond tip inside the beam (an end reaching a beam end is an open mouth).

    Not the tips of a debond grown by a cohesive law: its interface ahead is untied (no
    crack closure there); the law's tip positions are its columns (:mod:`.cohesive`).
    """
    x = model.mesh.x
    tol = 1e-9 * scene.length
    out = []
    for i, d in enumerate(scene.debonds):
        if d.end - d.start <= tol or (d.growth is not None and d.growth.cohesive):
            continue
        for tip, xt, step in (("start", d.start, -1), ("end", d.end, 1)):
            if xt <= tol or xt >= scene.length - tol:
                continue
            node = model.mesh.node_at(xt, 1e-6 * scene.length)
            behind, ahead = node - step, node + step
            out.append(BeamTip(i, tip, d.interface, node, behind, float(abs(x[node] - x[behind])),
                               float(abs(x[ahead] - x[node])) if 0 <= ahead < len(x) else 0.0))
    return out


def tip_zones(model: BeamModel, tips: list[BeamTip]) -> list[np.ndarray]:
    """Per tip, the elements where the core level should not change (a boolean mask).

    Those within :data:`LEVEL_NEIGHBOURHOOD` elements or :data:`LEVEL_ZONE` core thicknesses
    of the tip, whichever reaches farther.
    """
    n = model.mesh.n_elements
    x = model.mesh.x
    centres = 0.5 * (x[:-1] + x[1:])
    reach = LEVEL_ZONE * float(model.layers["core"].thickness)
    out = []
    for t in tips:
        near = np.zeros(n, dtype=bool)
        near[max(min(t.node, t.behind) - LEVEL_NEIGHBOURHOOD, 0):
             min(max(t.node, t.behind) + LEVEL_NEIGHBOURHOOD, n)] = True
        near |= np.abs(centres - x[t.node]) < reach
        out.append(near)
    return out


def uniform_tip_levels(model: BeamModel, tips: list[BeamTip], levels: np.ndarray) -> np.ndarray:
    """``levels`` with every tip zone (:func:`tip_zones`) raised to the highest level in it.

    Applied after the automatic level choice and each of its raises
    (:mod:`sandwich.beam.core_choice`, :func:`~sandwich.beam.core_controller.raised_levels`), so
    that no level transition falls next to a tip (docs/fracture.md).
    """
    out = np.array(levels, dtype=int, copy=True)
    for near in tip_zones(model, tips):
        out[near] = out[near].max()
    return out


def level_warning(model: BeamModel, tips: list[BeamTip]) -> str:
    """A warning naming the tips whose neighbourhood has mixed core levels, or ``""``.

    The neighbourhood: :data:`LEVEL_NEIGHBOURHOOD` elements, or :data:`LEVEL_ZONE` core
    thicknesses if longer, on each side of the tip.
    """
    levels = getattr(model, "element_levels", None)
    if levels is None:
        return ""
    bad = [f"{t.debond}_{t.tip}" for t, near in zip(tips, tip_zones(model, tips), strict=True)
           if len(np.unique(levels[near])) > 1]
    if not bad:
        return ""
    return (f"the core level changes within {LEVEL_ZONE:g} core thickness (or "
            f"{LEVEL_NEIGHBOURHOOD} elements) of debond tip(s) {', '.join(bad)}: G there is "
            "biased (measured −6 … +4 % on closed-form cases; set a uniform [beam_model] "
            "core level or a core_zones entry over the tip; docs/fracture.md)")


def tie_dofs(interface: str, node: int | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global (core, face) DOF indices of the three tie pairs of ``interface`` at ``node``."""
    core = np.array([global_dof(node, c) for c, _ in TIES[interface]])
    face = np.array([global_dof(node, f) for _, f in TIES[interface]])
    return core, face


def closure_elements(model: BeamModel, t: BeamTip) -> int:
    """Tip elements of the history's closure: round(t_face / h_tip) ≥ 1 (Δ ≈ t_face)."""
    face = min(float(v) for v in model.face_thickness.values())
    return max(1, int(round(face / t.closure_length)))


def tip_releases(model: BeamModel, u: np.ndarray, tips: list[BeamTip],
                 elements: int | None = None) -> list[TipRelease]:
    """G, G_I, G_II at ``tips`` for the free DOF vector ``u``: :func:`closure_release`.

    ``elements`` tip elements of closure; default :func:`closure_elements` (Δ ≈ the thinner
    face's thickness, as in 2D). The :class:`TipRelease` records the Δ used (mm).
    """
    if not tips:
        return []
    u_full = model.expand(u)
    counts = [closure_elements(model, t) if elements is None else elements for t in tips]
    near = np.unique(np.concatenate([closure_support(model, t, n)
                                     for t, n in zip(tips, counts, strict=True)]))
    f_full = model.full_response(u_full, tangent=False, elements=near)[0]
    return [closure_from_force(model, u_full, f_full, t, n)
            for t, n in zip(tips, counts, strict=True)]


def release_columns(model: BeamModel, u: np.ndarray, tips: list[BeamTip]
                    ) -> dict[str, float | None]:
    """The history columns of :func:`tip_releases`; ``None`` (an empty cell) where not finite.

    Never raises for a state the path accepted: a tip whose G cannot be evaluated gets empty
    cells (the writer leaves them blank, ``summary.json`` ``G_warning`` says so) instead of a
    NaN or a lost history.
    """
    if not tips:
        return {}
    try:
        cols: dict[str, float | None] = dict(history_columns(tip_releases(model, u, tips)))
    except (ValueError, FloatingPointError, np.linalg.LinAlgError):
        cols = {}
    for t in tips:
        for name in column_names(t.debond, t.tip):
            v = cols.get(name)
            cols[name] = v if v is not None and np.isfinite(v) else None
    return cols


def _frame(model: BeamModel, u_full: np.ndarray, t: BeamTip) -> tuple[float, float]:
    """(cos φ, sin φ) of the core boundary at the tip, φ = atan(w_c,x / (1 + u_c,x))."""
    core, _ = tie_dofs(t.interface, t.node)
    u_x = u_full[global_dof(t.node, TIES[t.interface][0][0] + ",x")]
    φ = np.arctan2(u_full[core[2]], 1.0 + u_x)
    return float(np.cos(φ)), float(np.sin(φ))


def closure_release(model: BeamModel, u: np.ndarray, t: BeamTip, elements: int) -> TipRelease:
    """G over a closure length of ``elements`` tip elements (see the module docstring).

    Δ = the distance from the tip node to the ``elements``-th untied node behind it (fewer if
    the debond has fewer). The tie reactions R_k of the bonded nodes ahead of the tip at
    s_k < Δ (tip node included) close the jumps δ found at the mirrored distance Δ − s_k
    behind (linear interpolation between the untied nodes): G = Σ_k R_k · δ(Δ − s_k) / (2 b Δ),
    the discrete closure integral ∫₀^Δ t(s) δ(Δ − s) ds / (2Δ) with the ties' force
    representation, as in 2D (sandwich/plane2d/fracture.py).
    """
    u_full = model.expand(u)
    f_full = model.full_response(u_full, tangent=False)[0]
    return closure_from_force(model, u_full, f_full, t, elements)


def _tied(model: BeamModel, interface: str, node: int) -> bool:
    """Whether the tie pairs of ``interface`` at ``node`` are eliminated (bonded or clamped)."""
    core, face = tie_dofs(interface, node)
    free = model.dof_map.free
    return bool(np.all(free[core] == free[face]))


def _behind_nodes(model: BeamModel, t: BeamTip, elements: int) -> list[int]:
    """The tip node and up to ``elements`` untied nodes behind it (into the debond)."""
    back = int(np.sign(t.behind - t.node))
    nodes = [t.node]
    k = t.node + back
    while len(nodes) <= elements and 0 <= k < len(model.mesh.x) \
            and not _tied(model, t.interface, k):
        nodes.append(k)
        k += back
    return nodes


def _ahead_nodes(model: BeamModel, t: BeamTip, delta: float) -> list[int]:
    """The tip node and the bonded nodes ahead of it closer than ``delta``: the R_k read."""
    x = model.mesh.x
    back = int(np.sign(t.behind - t.node))
    nodes = []
    k = t.node
    while 0 <= k < len(x) and abs(x[k] - x[t.node]) < delta * (1.0 - 1e-9):
        nodes.append(k)
        k -= back
    return nodes


def closure_support(model: BeamModel, t: BeamTip, elements: int) -> np.ndarray:
    """The elements whose layers' forces reach the tie reactions :func:`closure_from_force` reads.

    Node k's DOFs belong to elements k − 1 and k only: the force there from these elements
    (and every contact pair) is the whole internal force (tested against the full one).
    """
    behind = _behind_nodes(model, t, elements)
    if len(behind) < 2:
        return np.zeros(0, dtype=int)
    x = model.mesh.x
    nodes = np.asarray(_ahead_nodes(model, t, float(abs(x[behind[-1]] - x[t.node]))))
    els = np.concatenate([nodes - 1, nodes])
    return els[(els >= 0) & (els < model.mesh.n_elements)]


def closure_from_force(model: BeamModel, u_full: np.ndarray, f_full: np.ndarray, t: BeamTip,
                       elements: int) -> TipRelease:
    """:func:`closure_release` from the full DOF state ``u_full`` and internal force ``f_full``.

    ``f_full`` need be exact only at the tie DOFs the closure reads (:func:`closure_support`).
    """
    x = model.mesh.x
    behind_nodes = _behind_nodes(model, t, elements)
    if len(behind_nodes) < 2:
        return TipRelease(t.debond, t.tip, 0.0, 0.0, 0.0, 0.0)
    delta = float(abs(x[behind_nodes[-1]] - x[t.node]))
    r_b = np.abs(x[behind_nodes] - x[t.node])  # distance behind the tip of each node
    jumps = np.array([u_full[tie_dofs(t.interface, k)[1]] - u_full[tie_dofs(t.interface, k)[0]]
                      for k in behind_nodes])  # sliding, opening (mm), rotation jump (rad)
    jumps[0] = 0.0  # the tip node is tied
    c, s = _frame(model, u_full, t)
    work_n = work_t = 0.0
    for k in _ahead_nodes(model, t, delta):
        s_k = abs(x[k] - x[t.node])
        R = f_full[tie_dofs(t.interface, k)[0]]  # face on core: N, N, N·mm
        d = np.array([np.interp(delta - s_k, r_b, jumps[:, j]) for j in range(3)])
        R_t, R_n = c * R[0] + s * R[1], -s * R[0] + c * R[1]
        d_t, d_n = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        work_n += R_n * d_n + R[2] * d[2]
        work_t += R_t * d_t
    scale = 1.0 / (2.0 * model.width * delta)
    gi = max(scale * work_n, 0.0)
    gii = scale * work_t
    return TipRelease(t.debond, t.tip, gi + gii, gi, gii, delta)
