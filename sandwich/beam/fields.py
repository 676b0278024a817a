"""Fields of a solved state: profiles along the beam and the section's 2D fields on a grid.

Only mechanics here (strains, stresses, deformed positions as arrays); plotting lives elsewhere.
Stresses are second Piola-Kirchhoff (eq. 3) from the Green-Lagrange strains (eq. 15), or from the
small-strain part of eq. (15) for a linear analysis. Within the core, u, w and their first
derivatives are continuous across element ends (Hermite in x, no twist DOF), so values at nodes
are unique.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.beam.contact import contact_state
from sandwich.beam.contact_law import pressure_law
from sandwich.beam.contact_search import NORMAL_SIGN
from sandwich.beam.kinematics import gradients, green_lagrange, linear_strains
from sandwich.beam.model import BeamModel


@dataclass(frozen=True)
class LayerSample:
    """One layer sampled at the same reference points (η, ξ) of every element, shape ``(E, G)``."""

    x: np.ndarray  # reference position (mm)
    z: np.ndarray
    u: np.ndarray  # displacements (mm)
    w: np.ndarray
    sigma_x: np.ndarray  # MPa
    sigma_z: np.ndarray
    tau: np.ndarray

    @property
    def von_mises(self) -> np.ndarray:
        """Plane-stress von Mises stress √(σx² − σxσz + σz² + 3τ²) (MPa)."""
        return np.sqrt(self.sigma_x**2 - self.sigma_x * self.sigma_z + self.sigma_z**2
                       + 3 * self.tau**2)


def sample_layer(
    model: BeamModel, layer: str, u_full: np.ndarray, eta: np.ndarray, xi: np.ndarray,
    nonlinear: bool = True,
) -> LayerSample:
    """Displacements and stresses of ``layer`` at points (η, ξ) of every element.

    The core is sampled group by group (its level may change along x, :class:`CoreGroup`).
    """
    eta, xi = np.asarray(eta, float), np.asarray(xi, float)
    if layer == "core":
        families = [(g.op, g.elements, g.dofs) for g in model.core]
    else:
        families = [(model.layers[layer], np.arange(model.mesh.n_elements),
                     model.face_family_dofs(layer))]
    E, G = model.mesh.n_elements, eta.size
    out = {k: np.empty((E, G)) for k in ("x", "z", "u", "w", "sigma_x", "sigma_z", "tau")}
    for rows, els, dofs in families:
        op = rows.at(eta, xi)
        lengths = model.mesh.lengths[els]
        u_ref = u_full[dofs] * op.x_slope_scale(lengths)
        g = gradients(op, u_ref, lengths)
        ε = np.stack(green_lagrange(g) if nonlinear else linear_strains(g), axis=-1)
        σ = ε @ op.stiffness.T  # eq. (3)
        out["x"][els] = model.mesh.x[els, None] + 0.5 * (op.eta[None, :] + 1) * lengths[:, None]
        out["z"][els] = (op.z_bottom + 0.5 * (op.xi + 1) * op.thickness)[None, :]
        out["u"][els], out["w"][els] = u_ref @ op.N.T, u_ref @ op.M.T
        out["sigma_x"][els], out["sigma_z"][els], out["tau"][els] = σ[..., 0], σ[..., 1], σ[..., 2]
    return LayerSample(**out)


def _stations(per_element: int) -> np.ndarray:
    if per_element < 1:
        raise ValueError(f"per_element must be >= 1, got {per_element}")
    return np.linspace(-1.0, 1.0, per_element + 1)[:-1]


def _along(sample: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Flatten (E, G) stations and append the last node's value."""
    return np.concatenate([sample.reshape(-1), last[-1:, -1]])


def profile_columns(
    model: BeamModel, u: np.ndarray, nonlinear: bool = True, per_element: int = 2
) -> dict[str, np.ndarray]:
    """Profile columns along x (mm, MPa): face deflections, interface σ_z, core τ, contact.

    Columns: ``x, w_top, w_bottom, sigma_zz_top, sigma_zz_bottom, tau_core`` (core σ_z at the
    core's top/bottom boundary, core τ at mid-core), ``tau_top, tau_bottom`` (core τ at its
    top/bottom boundary: the interface shear traction), ``u_top, u_bottom`` (axial displacement of
    the faces' mid-surfaces), ``sigma_xx_top_face, sigma_xx_bottom_face`` (face σ_x at
    mid-thickness), ``p_contact_top, p_contact_bottom`` (contact pressure, zero where bonded or
    open), ``gap_top, gap_bottom`` (normal gap of debonded pairs, zero where bonded) and
    ``sliding_top, sliding_bottom`` (the pairs' tangential sliding, mm; zero where bonded and in
    a linear analysis).
    """
    u_full = model.expand(u)
    η = _stations(per_element)
    ends = np.array([1.0])

    samples: dict[tuple[str, float], tuple[LayerSample, LayerSample]] = {}

    def col(layer: str, ξ: float, what: str) -> np.ndarray:
        if (layer, ξ) not in samples:  # each layer and height sampled once for its columns
            samples[layer, ξ] = (
                sample_layer(model, layer, u_full, η, np.full_like(η, ξ), nonlinear),
                sample_layer(model, layer, u_full, ends, np.array([ξ]), nonlinear))
        s, e = samples[layer, ξ]
        return _along(getattr(s, what), getattr(e, what))

    x = col("core", 0.0, "x")
    out = {
        "x": x,
        "w_top": col("top", 0.0, "w"),
        "w_bottom": col("bottom", 0.0, "w"),
        "sigma_zz_top": col("core", 1.0, "sigma_z"),
        "sigma_zz_bottom": col("core", -1.0, "sigma_z"),
        "tau_core": col("core", 0.0, "tau"),
        "tau_top": col("core", 1.0, "tau"),  # interface shear tractions (tip_tractions.csv)
        "tau_bottom": col("core", -1.0, "tau"),
        "u_top": col("top", 0.0, "u"),
        "u_bottom": col("bottom", 0.0, "u"),
        "sigma_xx_top_face": col("top", 0.0, "sigma_x"),
        "sigma_xx_bottom_face": col("bottom", 0.0, "sigma_x"),
    }
    for interface in ("top", "bottom"):
        p_nodes = np.zeros(model.mesh.n_nodes)
        g_nodes = np.zeros(model.mesh.n_nodes)
        s_nodes = np.zeros(model.mesh.n_nodes)
        for pairs in model.pairs:
            if pairs.interface == interface:
                if nonlinear:
                    p, k = contact_state(pairs, u_full, model.penalty, model.smoothing)
                    gap = k.gap
                    s_nodes[pairs.nodes] = k.sliding
                else:  # the linear analysis' law: plain penalty on the linearised gap
                    v = u_full[pairs.dofs]
                    gap = NORMAL_SIGN[pairs.interface] * (v[:, 1] - v[:, 3])
                    p = pressure_law(gap, model.penalty)[0]
                p_nodes[pairs.nodes], g_nodes[pairs.nodes] = p, gap
        out[f"p_contact_{interface}"] = np.interp(x, model.mesh.x, p_nodes)
        out[f"gap_{interface}"] = np.interp(x, model.mesh.x, g_nodes)
        out[f"sliding_{interface}"] = np.interp(x, model.mesh.x, s_nodes)
        cohesive = [p for p in model.pairs if p.interface == interface and p.cohesive is not None]
        if cohesive:  # a growing interface: its committed damage (1: debonded)
            d_nodes = np.zeros(model.mesh.n_nodes)
            for p in model.pairs:
                if p.interface == interface and p.cohesive is None:
                    d_nodes[p.nodes] = 1.0  # the debond itself
            for p in cohesive:
                d_nodes[p.nodes] = p.cohesive.damage.max(axis=1)
            out[f"damage_{interface}"] = np.interp(x, model.mesh.x, d_nodes)
    return out


@dataclass(frozen=True)
class SectionFields:
    """The whole section on a structured grid of quadrilaterals (mm, MPa).

    ``points`` (n, 2) reference (x, z); ``displacement`` (n, 2) (u, w); ``cells`` (m, 4)
    counter-clockwise; per point ``sigma_x``, ``sigma_z``, ``tau``, ``von_mises``; ``region``
    (m,) 0 core, 1 top face, 2 bottom face. Face stresses are the face's (σ_x, 0, τ).
    """

    points: np.ndarray
    displacement: np.ndarray
    cells: np.ndarray
    sigma_x: np.ndarray
    sigma_z: np.ndarray
    tau: np.ndarray
    von_mises: np.ndarray
    region: np.ndarray
    core_level: np.ndarray  # (m,) the element's core level on core cells, 0 on face cells

    @property
    def deformed(self) -> np.ndarray:
        """Deformed positions (n, 2)."""
        return self.points + self.displacement


def core_rows(model: BeamModel, through: int) -> np.ndarray:
    """ξ of the core's grid rows: ``through`` even rows plus every sublayer surface in use."""
    cuts = [g.op.basis.partition(g.level) for g in model.core if g.op.basis is not None]
    return np.unique(np.concatenate([np.linspace(-1.0, 1.0, through), *cuts]))


def layer_grid(
    model: BeamModel, layer: str, u: np.ndarray, per_element: int = 4, through: int = 9,
    nonlinear: bool = True, rows: np.ndarray | None = None,
) -> LayerSample:
    """One layer on a grid, arrays shaped ``(through, columns)``.

    ``per_element`` columns per element (plus the last node) by ``through`` rows from the layer's
    bottom to its top (or at the reference coordinates ``rows`` in [−1, 1]).
    """
    ξ1 = np.linspace(-1.0, 1.0, through) if rows is None else np.asarray(rows, dtype=float)
    through = ξ1.size
    if through < 2:
        raise ValueError(f"need at least 2 rows through the thickness, got {through}")
    u_full = model.expand(u)
    η1 = _stations(per_element)
    η, ξ = np.repeat(η1, through), np.tile(ξ1, η1.size)
    s = sample_layer(model, layer, u_full, η, ξ, nonlinear)
    e = sample_layer(model, layer, u_full, np.ones(through), ξ1, nonlinear)

    def grid(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        body = a.reshape(model.mesh.n_elements, η1.size, through).reshape(-1, through)
        return np.concatenate([body, b[-1:, :]], axis=0).T

    return LayerSample(**{k: grid(getattr(s, k), getattr(e, k)) for k in
                          ("x", "z", "u", "w", "sigma_x", "sigma_z", "tau")})


def section_fields(
    model: BeamModel, u: np.ndarray, per_element: int = 4, through_core: int = 9,
    nonlinear: bool = True,
) -> SectionFields:
    """Core and faces on one quadrilateral grid each, stacked (for deformed-shape pictures).

    The core's rows include every sublayer surface of its levels (:func:`core_rows`), so a
    ParaView view of the cells shows the sublayers; cell data ``core_level`` says the level.
    """
    points, disp, cells, region, stress, level = [], [], [], [], [], []
    offset = 0
    for label, (layer, rows) in enumerate((("core", through_core), ("top", 2), ("bottom", 2))):
        xi = core_rows(model, rows) if layer == "core" else None
        g = layer_grid(model, layer, u, per_element, rows, nonlinear, rows=xi)
        nz, nx = g.x.shape
        points.append(np.column_stack([g.x.ravel(), g.z.ravel()]))
        disp.append(np.column_stack([g.u.ravel(), g.w.ravel()]))
        stress.append(np.column_stack([g.sigma_x.ravel(), g.sigma_z.ravel(), g.tau.ravel(),
                                       g.von_mises.ravel()]))
        j, i = np.meshgrid(np.arange(nz - 1), np.arange(nx - 1), indexing="ij")
        p0 = offset + j * nx + i
        cells.append(np.stack([p0, p0 + 1, p0 + 1 + nx, p0 + nx], axis=-1).reshape(-1, 4))
        region.append(np.full(cells[-1].shape[0], label))
        column_element = np.minimum(np.arange(nx - 1) // per_element, model.mesh.n_elements - 1)
        per_cell = np.broadcast_to(model.element_levels[column_element], (nz - 1, nx - 1))
        level.append(per_cell.reshape(-1) if layer == "core" else np.zeros(cells[-1].shape[0]))
        offset += nz * nx
    S = np.concatenate(stress)
    return SectionFields(points=np.concatenate(points), displacement=np.concatenate(disp),
                         cells=np.concatenate(cells), sigma_x=S[:, 0], sigma_z=S[:, 1],
                         tau=S[:, 2], von_mises=S[:, 3], region=np.concatenate(region),
                         core_level=np.concatenate(level).astype(int))
