"""Energy release rate at every debond tip of the beam model, from the interface ties.

At a bonded node the core's boundary DOFs follow the face's (section 2.3, imposed by
elimination): u_c = u_f, w_c = w_f, w_c,x = w_f,x (top: u_ct = u_tb, w_ct = w_t, w_ct,x = w_t,x;
bottom: u_cb = u_bt, w_cb = w_b, w_cb,x = w_b,x). Untying the tip node extends the debond by
one element, Δ = the length of the element behind the tip (the mesh fills a debond and its tips
with its smallest elements, so the element ahead has the same length). The virtual crack
closure estimate of the energy released, per unit crack area, is

    G = 1/(2 b Δ) Σ_j R_j δ_j,   j ∈ {u, w, w,x}

with R_j the tie reaction at the tip node, the force (N) or moment (N·mm) that the face exerts on
the core's tied DOF j, i.e. the core layer's internal force on that DOF (eq. 19, the core
elements on both sides of the node; the tie itself carries no stiffness of its own), and
δ_j = face DOF − core DOF of the tie pair at the first untied node behind the tip: the opening
(mm), sliding (mm) and the rotation jump (rad) that node shows now.

Mode split (the beam-theory, "global" partition): G_II from the tangential force × sliding,
G_I from the normal force × opening plus the interface moment × the rotation jump (the moment is
a couple of normal interface tractions). Forces and displacements are resolved on the core
boundary at the tip, rotated by atan(w_c,x / (1 + u_c,x)) (eq. 15 kinematics), so the split
stays meaningful when the section rotates. A negative G_I (the lips pressed into each other
by the penalty contact, a closed crack) is reported as 0. All in N/mm (= kJ/m²).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from beam_element.dofs import TIES, global_dof
from sandwich.results.fracture import TipRelease, column_names, history_columns  # noqa: F401

# A beam_element.model.BeamModel: not imported, the model imports this module (it holds its
# tips and gives their G to every accepted path state).
BeamModel = Any

TIE_ROLES = ("u", "w", "w,x")  # order of the pairs in dofs.TIES
# Core levels (beam_element.core_levels) that change within this many elements of a tip bias G:
# measured on the sliding couples, an "auto" level-2 patch of 5 elements around the tip gave
# G +4.6 % and the cantilever slope d√G/da −10 %, while uniform levels 1-4 stay within 2.4 %
# (docs/fracture.md).
LEVEL_NEIGHBOURHOOD = 8


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
    """Every debond tip inside the beam (an end reaching a beam end is an open mouth)."""
    x = model.mesh.x
    tol = 1e-9 * scene.length
    out = []
    for i, d in enumerate(scene.debonds):
        if d.end - d.start <= tol:
            continue
        for tip, xt, step in (("start", d.start, -1), ("end", d.end, 1)):
            if xt <= tol or xt >= scene.length - tol:
                continue
            node = model.mesh.node_at(xt, 1e-6 * scene.length)
            behind, ahead = node - step, node + step
            out.append(BeamTip(i, tip, d.interface, node, behind, float(abs(x[node] - x[behind])),
                               float(abs(x[ahead] - x[node])) if 0 <= ahead < len(x) else 0.0))
    return out


def level_warning(model: BeamModel, tips: list[BeamTip]) -> str:
    """A warning naming the tips whose neighbourhood has mixed core levels, or ``""``."""
    levels = getattr(model, "element_levels", None)
    if levels is None:
        return ""
    bad = []
    for t in tips:
        lo = max(min(t.node, t.behind) - LEVEL_NEIGHBOURHOOD, 0)
        hi = min(max(t.node, t.behind) + LEVEL_NEIGHBOURHOOD, len(levels))
        if len(np.unique(levels[lo:hi])) > 1:
            bad.append(f"{t.debond}_{t.tip}")
    if not bad:
        return ""
    return (f"the core level changes within {LEVEL_NEIGHBOURHOOD} elements of debond "
            f"tip(s) {', '.join(bad)}: G there is biased by up to ~10 % (set a uniform "
            "[beam_model] core level or a core_zones entry over the tip; docs/fracture.md)")


def tie_dofs(interface: str, node: int | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global (core, face) DOF indices of the three tie pairs of ``interface`` at ``node``."""
    core = np.array([global_dof(node, c) for c, _ in TIES[interface]])
    face = np.array([global_dof(node, f) for _, f in TIES[interface]])
    return core, face


def tip_releases(model: BeamModel, u: np.ndarray, tips: list[BeamTip]) -> list[TipRelease]:
    """G, G_I, G_II at ``tips`` for the free DOF vector ``u``."""
    if not tips:
        return []
    u_full = model.expand(u)
    f_full = model.full_response(u_full, tangent=False)[0]
    out = []
    for t in tips:
        core, face = tie_dofs(t.interface, t.node)
        R = f_full[core]  # (R_u, R_w, R_θ): face on core at the tip, N and N·mm
        core_b, face_b = tie_dofs(t.interface, t.behind)
        δ = u_full[face_b] - u_full[core_b]  # sliding, opening (mm), rotation jump (rad)
        u_x = u_full[global_dof(t.node, TIES[t.interface][0][0] + ",x")]
        w_x = u_full[core[2]]
        φ = np.arctan2(w_x, 1.0 + u_x)  # rotation of the core boundary at the tip
        c, s = np.cos(φ), np.sin(φ)
        R_t, R_n = c * R[0] + s * R[1], -s * R[0] + c * R[1]
        δ_t, δ_n = c * δ[0] + s * δ[1], -s * δ[0] + c * δ[1]
        scale = 1.0 / (2.0 * model.width * t.closure_length)
        gi = max(scale * (R_n * δ_n + R[2] * δ[2]), 0.0)
        gii = scale * R_t * δ_t
        out.append(TipRelease(t.debond, t.tip, gi + gii, gi, gii, t.closure_length))
    return out




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
    """G over a closure length of ``elements`` tip elements (a diagnostic of the VCCT estimate).

    Δ = the distance from the tip node to the ``elements``-th untied node behind it. The tie
    reactions R_k of the bonded nodes ahead of the tip at s_k < Δ (tip node included) close the
    jumps δ found at the mirrored distance Δ − s_k behind (linear interpolation between the
    untied nodes): G = Σ_k R_k · δ(Δ − s_k) / (2 b Δ), the discrete closure integral
    ∫₀^Δ t(s) δ(Δ − s) ds / (2Δ) with the ties' force representation, as in 2D
    (reference2d/fracture.py). ``elements = 1`` is :func:`tip_releases`.
    """
    u_full = model.expand(u)
    f_full = model.full_response(u_full, tangent=False)[0]
    x = model.mesh.x
    back = int(np.sign(t.behind - t.node))
    n_nodes = len(x)
    behind_nodes = [t.node + back * k for k in range(0, elements + 1)
                    if 0 <= t.node + back * k < n_nodes]
    if len(behind_nodes) < 2:
        return TipRelease(t.debond, t.tip, 0.0, 0.0, 0.0, 0.0)
    delta = float(abs(x[behind_nodes[-1]] - x[t.node]))
    # jumps at the nodes behind (distance r from the tip); r = 0 at the tip itself (tied: 0)
    r_b = np.abs(x[behind_nodes] - x[t.node])
    jumps = np.array([u_full[tie_dofs(t.interface, k)[1]] - u_full[tie_dofs(t.interface, k)[0]]
                      for k in behind_nodes])
    jumps[0] = 0.0
    c, s = _frame(model, u_full, t)
    work_n = work_t = 0.0
    k = t.node
    while 0 <= k < n_nodes:
        s_k = abs(x[k] - x[t.node])
        if s_k >= delta * (1.0 - 1e-9):
            break
        core, _ = tie_dofs(t.interface, k)
        R = f_full[core]
        d = np.array([np.interp(delta - s_k, r_b, jumps[:, j]) for j in range(3)])
        R_t, R_n = c * R[0] + s * R[1], -s * R[0] + c * R[1]
        d_t, d_n = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        work_n += R_n * d_n + R[2] * d[2]
        work_t += R_t * d_t
        k -= back
    scale = 1.0 / (2.0 * model.width * delta)
    gi = max(scale * work_n, 0.0)
    gii = scale * work_t
    return TipRelease(t.debond, t.tip, gi + gii, gi, gii, delta)
