"""Shape-function matrices N, M of each layer and their reference derivatives (eqs. 10-14).

For one layer, at a set of points (η, ξ) of the reference element, this builds the rows of

    u_j = N_j u_e,  w_j = M_j u_e          (eq. 10, 13)

restricted to the element DOFs the layer depends on, together with ∂/∂η and ∂/∂ξ of them. The
rows are built from the DOF table (:mod:`sandwich.beam.dofs`): each DOF contributes
X_kind(η) · Z_kind(ξ) to the row of its field.

Convention: x-slope DOFs enter through the reference slope function (length 2), so an element's
DOF vector must be scaled by l/2 on x-slopes before use (:func:`x_slope_scale`). The thickness is
the same for every element, so the h/2 of z-slope DOFs is folded into the rows here.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from sandwich.beam.core_basis import CoreBasis, mode_dofs
from sandwich.beam.dofs import (
    DOF_TABLE,
    ELEMENT_DOFS,
    NODE_DOFS,
    NODES_PER_ELEMENT,
    layer_element_dofs,
)
from sandwich.beam.quadrature import gauss_legendre, tensor_rule
from sandwich.beam.shape_functions import slope_scale_x, slope_scale_z, x_shape, z_shape


@dataclass(frozen=True)
class LayerOperators:
    """Shape-function rows of one layer at points (η, ξ), on the layer's element DOFs.

    Attributes
    ----------
    name
        ``"top"``, ``"core"`` or ``"bottom"``.
    dofs
        Element-local indices (0..39) of the layer's DOFs, shape ``(n,)``.
    thickness
        Layer thickness h (mm).
    z_bottom
        z of the layer's bottom surface (mm), z = 0 at the core mid-plane.
    stiffness
        Voigt stiffness (MPa) in the order (ε_x, ε_z, γ).
    eta, xi, weight
        Points and weights, shape ``(G,)``.
    N, M
        Rows of u and w (eq. 13), shape ``(G, n)``.
    N_eta, N_xi, M_eta, M_xi
        Their derivatives with respect to η and ξ, shape ``(G, n)``.
    x_slope
        Boolean mask of x-slope DOFs, shape ``(n,)``.
    membrane_average
        Option, NOT the paper's element (default False): ε_x is replaced at every point by its
        Gauss-weighted average along η at the same ξ (an assumed membrane strain). For a face,
        u is linear in x, so only the ½ w,x² term changes: it becomes its element mean, which
        removes the membrane locking of u-linear / w-cubic faces. Needs a tensor Gauss rule.
    basis, level
        The core's enrichment (:mod:`sandwich.beam.core_basis`) and the level these rows carry;
        ``None`` and 1 for the paper's layers. At level > 1 the element vector is *extended*:
        indices 0..39 are the paper's DOFs of eq. (9), then each node's enrichment DOFs
        (:func:`~sandwich.beam.core_basis.mode_dofs`), node i first.
    u_mask
        Boolean mask of the u DOFs (``None``: read from the DOF table).
    """

    name: str
    dofs: np.ndarray
    thickness: float
    z_bottom: float
    stiffness: np.ndarray
    eta: np.ndarray
    xi: np.ndarray
    weight: np.ndarray
    N: np.ndarray
    M: np.ndarray
    N_eta: np.ndarray
    N_xi: np.ndarray
    M_eta: np.ndarray
    M_xi: np.ndarray
    x_slope: np.ndarray
    membrane_average: bool = False
    basis: CoreBasis | None = None
    level: int = 1
    u_mask: np.ndarray | None = None
    stretch: bool = False

    def at(self, eta: np.ndarray, xi: np.ndarray) -> LayerOperators:
        """The same layer's rows at other points (weights set to zero)."""
        if self.basis is not None and self.level > 1:
            return build_core_operators(self.thickness, self.z_bottom, self.stiffness,
                                        self.basis, self.level, eta=eta, xi=xi)
        if self.stretch:
            return build_face_operators(self.name, self.thickness, self.z_bottom,
                                        self.stiffness, eta=eta, xi=xi, stretch=True)
        return build_layer_operators(
            self.name, self.thickness, self.z_bottom, self.stiffness, eta=eta, xi=xi
        )

    @cached_property
    def reference_rows(self) -> np.ndarray:
        """``[N,η; N,ξ; M,η; M,ξ]`` stacked, shape ``(4G, n)`` (computed once per layer)."""
        return np.concatenate([self.N_eta, self.N_xi, self.M_eta, self.M_xi])

    @cached_property
    def reference_rows_by_point(self) -> np.ndarray:
        """The same rows per point, shape ``(G, 4, n)``."""
        return np.ascontiguousarray(
            np.stack([self.N_eta, self.N_xi, self.M_eta, self.M_xi], axis=1))

    @cached_property
    def u_columns(self) -> np.ndarray:
        """Boolean mask of the layer's u DOFs, shape ``(n,)``.

        N rows vanish off them, M rows on them.
        """
        if self.u_mask is not None:
            return self.u_mask
        return np.array([DOF_TABLE[int(d) % NODE_DOFS].field == "u" for d in self.dofs])

    @cached_property
    def field_products(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Products R_kᵀR_l of the reference rows per point, split by field (uu, ww, uw).

        With R = (N,η, N,ξ, M,η, M,ξ): uu pairs k, l ∈ (N,η, N,ξ) on the u columns, shape
        ``(4G, n_u²)``; ww pairs k, l ∈ (M,η, M,ξ) on the w columns, ``(4G, n_w²)``; uw pairs
        k ∈ N rows, l ∈ M rows, ``(4G, n_u n_w)``. Rows are ordered (point, k, l).
        """
        u, w = self.u_columns, ~self.u_columns
        Nr = np.stack([self.N_eta[:, u], self.N_xi[:, u]], axis=1)  # (G, 2, n_u)
        Mr = np.stack([self.M_eta[:, w], self.M_xi[:, w]], axis=1)  # (G, 2, n_w)
        G = self.eta.size

        def prod(A: np.ndarray, B: np.ndarray) -> np.ndarray:
            return np.einsum("gka,glb->gklab", A, B).reshape(4 * G, -1)

        return prod(Nr, Nr), prod(Mr, Mr), prod(Nr, Mr)

    def x_slope_scale(self, lengths: np.ndarray) -> np.ndarray:
        """Per-element DOF scale, shape ``(E, n)``: l/2 on x-slope DOFs, 1 elsewhere."""
        return np.where(self.x_slope[None, :], 0.5 * np.asarray(lengths)[:, None], 1.0)


def build_layer_operators(
    name: str,
    thickness: float,
    z_bottom: float,
    stiffness: np.ndarray,
    *,
    gauss: tuple[int, int] | None = None,
    eta: np.ndarray | None = None,
    xi: np.ndarray | None = None,
    membrane_average: bool = False,
) -> LayerOperators:
    """Build the rows of eq. (13) for one layer, at a Gauss rule or at given points.

    Parameters
    ----------
    name
        Layer name.
    thickness, z_bottom
        Thickness h (mm) and z of its bottom surface (mm).
    stiffness
        Voigt stiffness (MPa), see :mod:`sandwich.beam.constitutive`.
    gauss
        Orders (n_η, n_ξ) of a tensor Gauss rule; or give ``eta`` and ``xi`` instead.
    eta, xi
        Explicit points (same shape); their weights are zero.
    membrane_average
        See :class:`LayerOperators` (needs ``gauss``).
    """
    if not (np.isfinite(thickness) and thickness > 0):
        raise ValueError(f"{name} layer thickness must be positive, got {thickness!r}")
    if gauss is not None:
        eta, xi, weight = tensor_rule(*gauss)
    elif eta is not None and xi is not None:
        eta = np.atleast_1d(np.asarray(eta, dtype=float))
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        if eta.shape != xi.shape:
            raise ValueError("eta and xi must have the same shape")
        weight = np.zeros_like(eta)
    else:
        raise ValueError("give either gauss orders or both eta and xi")

    dofs = np.array(layer_element_dofs(name))
    G, n = eta.size, dofs.size
    rows = {key: np.zeros((G, n)) for key in ("N", "M", "N_eta", "N_xi", "M_eta", "M_xi")}
    x_slope = np.zeros(n, dtype=bool)
    for a, element_dof in enumerate(dofs):
        node, i = divmod(int(element_dof), NODE_DOFS)
        assert node < NODES_PER_ELEMENT
        d = DOF_TABLE[i]
        X, X_eta = x_shape(d.x_kind, node, eta)
        Z, Z_xi = z_shape(d.z_kind, xi)
        z_scale = 0.5 * thickness if slope_scale_z(d.z_kind) else 1.0  # Hbar(ξ; h) = h/2 Hbar_ref
        x_slope[a] = slope_scale_x(d.x_kind)
        value, d_eta, d_xi = (z_scale * X * Z, z_scale * X_eta * Z, z_scale * X * Z_xi)
        if d.field == "u":
            rows["N"][:, a], rows["N_eta"][:, a], rows["N_xi"][:, a] = value, d_eta, d_xi
        else:
            rows["M"][:, a], rows["M_eta"][:, a], rows["M_xi"][:, a] = value, d_eta, d_xi
    return LayerOperators(
        name=name, dofs=dofs, thickness=float(thickness), z_bottom=float(z_bottom),
        stiffness=np.asarray(stiffness, dtype=float), eta=eta, xi=xi, weight=weight,
        x_slope=x_slope, membrane_average=bool(membrane_average and gauss is not None), **rows,
    )


def build_core_operators(
    thickness: float,
    z_bottom: float,
    stiffness: np.ndarray,
    basis: CoreBasis,
    level: int,
    *,
    gauss: tuple[int, int] | None = None,
    eta: np.ndarray | None = None,
    xi: np.ndarray | None = None,
) -> LayerOperators:
    """Rows of the core at ``level`` of ``basis``: the paper's 24 DOFs plus the enrichment.

    At level 1 this is :func:`build_layer_operators` of the core (the paper's element, bit for
    bit) with the tensor rule ``gauss``. At level > 1 the rule is ``gauss[0]`` points along η
    times the basis' exact rule in ξ
    (:meth:`~sandwich.beam.core_basis.CoreBasis.rule`), η slowest as in
    :func:`~sandwich.beam.quadrature.tensor_rule`.
    """
    if gauss is not None and level == 1:
        return replace(build_layer_operators("core", thickness, z_bottom, stiffness,
                                             gauss=gauss), basis=basis)
    if gauss is not None:
        e1, we = gauss_legendre(gauss[0])
        x1, wx = basis.rule(level)
        eta, xi = np.repeat(e1, x1.size), np.tile(x1, e1.size)
        weight = np.outer(we, wx).ravel()
    elif eta is not None and xi is not None:
        eta = np.atleast_1d(np.asarray(eta, dtype=float))
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        weight = np.zeros_like(eta)
    else:
        raise ValueError("give either gauss or both eta and xi")
    paper = build_layer_operators("core", thickness, z_bottom, stiffness, eta=eta, xi=xi)
    if level == 1:
        return replace(paper, weight=weight, basis=basis)
    modes = mode_dofs(basis, level)
    m = len(modes)
    cols = {key: [getattr(paper, key)] for key in ("N", "M", "N_eta", "N_xi", "M_eta", "M_xi")}
    zero = np.zeros((eta.size, NODES_PER_ELEMENT * m))
    for key in cols:
        cols[key].append(zero.copy())
    x_slope = np.zeros(NODES_PER_ELEMENT * m, dtype=bool)
    is_u = np.zeros(NODES_PER_ELEMENT * m, dtype=bool)
    phi = [f(xi) for f in basis.functions[:basis.count(level)]]
    for node in range(NODES_PER_ELEMENT):
        for j, d in enumerate(modes):
            a = node * m + j
            X, X_eta = x_shape(d.x_kind, node, eta)
            Z, Z_xi = phi[d.function]
            if basis.functions[d.function].kind == "slope":  # DOF = ∂/∂z: ξ-slope × h/2
                Z, Z_xi = 0.5 * thickness * Z, 0.5 * thickness * Z_xi
            x_slope[a], is_u[a] = slope_scale_x(d.x_kind), d.field == "u"
            field = "N" if d.field == "u" else "M"
            cols[field][1][:, a] = X * Z
            cols[field + "_eta"][1][:, a] = X_eta * Z
            cols[field + "_xi"][1][:, a] = X * Z_xi
    rows = {key: np.concatenate(v, axis=1) for key, v in cols.items()}
    dofs = np.concatenate([paper.dofs, ELEMENT_DOFS + np.arange(NODES_PER_ELEMENT * m)])
    return LayerOperators(
        name="core", dofs=dofs, thickness=float(thickness), z_bottom=float(z_bottom),
        stiffness=np.asarray(stiffness, dtype=float), eta=eta, xi=xi, weight=weight,
        x_slope=np.concatenate([paper.x_slope, x_slope]), basis=basis, level=level,
        u_mask=np.concatenate([paper.u_columns, is_u]), **rows,
    )


# Through-thickness shape of a face's stretch DOF: 0 at the face's inner surface (the one on the
# core), 1 at its outer surface.
FACE_OUTER = {"top": "L_t", "bottom": "L_b"}


def build_face_operators(
    name: str,
    thickness: float,
    z_bottom: float,
    stiffness: np.ndarray,
    *,
    gauss: tuple[int, int] | None = None,
    eta: np.ndarray | None = None,
    xi: np.ndarray | None = None,
    membrane_average: bool = False,
    stretch: bool = False,
) -> LayerOperators:
    """Rows of a face: the paper's (eq. 13), optionally with the face's stretch DOF.

    ``stretch=False`` is :func:`build_layer_operators` (the paper's face: w constant through
    the thickness). ``stretch=True`` (not the paper's element) adds one w DOF per node,
    d = w(outer surface) − w(inner surface), linear along x like the face's u and linear through
    the thickness, zero at the inner surface: the face's w at the core is still the paper's w
    DOF, so ties, contact, supports and probes are unchanged. With it a rotated face fibre can
    stay straight, normal and unstretched (u,z = −sin θ, w,z = cos θ − 1); with w constant in z
    it can only stay normal by stretching (u,z = −tan θ), which raises the face's bending
    strain by 1/cos θ and its bending stiffness by 1/cos² θ at a rotation θ. The ε_z row of
    ``stiffness`` must then hold the face's through-thickness modulus (σ_z = E ε_z, uncoupled:
    no Poisson coupling, so no thickness locking in bending). The element vector is extended:
    indices 0..39 are the paper's, then the stretch DOF at node 0 and node 1 (40, 41).
    """
    paper = build_layer_operators(name, thickness, z_bottom, stiffness, gauss=gauss, eta=eta,
                                  xi=xi, membrane_average=membrane_average)
    if not stretch:
        return paper
    if name not in FACE_OUTER:
        raise ValueError(f"only a face has a stretch DOF, got {name!r}")
    cols = {key: np.zeros((paper.eta.size, NODES_PER_ELEMENT))
            for key in ("N", "N_eta", "N_xi", "M", "M_eta", "M_xi")}
    Z, Z_xi = z_shape(FACE_OUTER[name], paper.xi)
    for node in range(NODES_PER_ELEMENT):
        X, X_eta = x_shape("L", node, paper.eta)
        cols["M"][:, node], cols["M_eta"][:, node], cols["M_xi"][:, node] = (
            X * Z, X_eta * Z, X * Z_xi)
    rows = {key: np.concatenate([getattr(paper, key), cols[key]], axis=1) for key in cols}
    return replace(
        paper, dofs=np.concatenate([paper.dofs, ELEMENT_DOFS + np.arange(NODES_PER_ELEMENT)]),
        x_slope=np.concatenate([paper.x_slope, np.zeros(NODES_PER_ELEMENT, dtype=bool)]),
        u_mask=np.concatenate([paper.u_columns, np.zeros(NODES_PER_ELEMENT, dtype=bool)]),
        stretch=True, **rows)
