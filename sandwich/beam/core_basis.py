"""Through-thickness enrichment of the core: the levels of the core hierarchy.

Level 1 is the paper's core: u and w cubic Hermite in ξ (eqs. 8, 11b), fixed by the values and
z-slopes at the core's two boundaries. A level ℓ > 1 adds enrichment functions φ_k(ξ) that vanish
*with their slope* at ξ = ±1, for u and for w, each interpolated along x by the cubic Hermite
pair (H, H̄) of its own nodal DOFs (φ_k-amplitude and its x-slope):

    u_c(η, ξ) = Σ_paper + Σ_k Σ_{x ∈ {H, H̄}} X(η) φ_k(ξ) a_k,      likewise w_c with b_k.

Because every φ_k vanishes with its slope on the core's boundaries, the boundary values and slopes
are still the paper's DOFs: interface ties, contact (the core's outer boundary), supports and loads
are unchanged at every level, and level 1 is the paper's element exactly. The basis is
hierarchical: level ℓ's functions are level ℓ−1's plus new ones, so a node of a lower level simply
has the new amplitudes fixed at zero, and the level can change from element to element
conformingly (:mod:`sandwich.beam.core_groups`).

Two families (``[beam_model] core_basis``):

``"sublayers"`` (default)
    C¹ piecewise cubics on a partition of the core graded towards both faces. Level ℓ inserts the
    surfaces ξ = ±(1 − δ_ℓ), δ_ℓ = SUBLAYER_FIRST · SUBLAYER_RATIO^(ℓ−2) (in units of the half core
    thickness, measured from each face); each inserted surface p carries a value hat and a
    z-slope hat: the cubic Hermite functions of p on the partition of *its* level (supported on
    p's two neighbouring sublayers). With the paper's cubic these span every C¹ piecewise cubic
    on the level's partition: k sublayers, each the paper's cubic Hermite, sharing u, w, u,z, w,z
    at the sublayer surfaces. Integrated by a composite Gauss rule, exact per sublayer.
``"polynomial"``
    φ_k = (1 − ξ²)² P_{k−1}(ξ) (P Legendre): level ℓ raises the degree in ξ from 3 to 2ℓ + 1.
    Integrated by one Gauss rule exact for the polynomial energy (2p + 1 points for degree p).

The choice of the default is measured in docs/beam_element.md ("Core levels").
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sandwich.beam.quadrature import gauss_legendre
from sandwich.beam.shape_functions import x_shape

CORE_BASES = ("sublayers", "polynomial")
MAX_LEVEL = 6
SUBLAYER_FIRST = 0.5  # level 2 inserts the surfaces at half the half-thickness from each face
SUBLAYER_RATIO = 0.4  # each further level inserts surfaces 0.4 × closer to the faces
POLY_PER_LEVEL = 2  # polynomial family: degrees added per level
X_KINDS = ("H", "Hbar")  # every amplitude is cubic Hermite along x: value and x-slope DOFs
EXACT_POINTS_PER_SUBLAYER = 7  # the paper's core rule (degree-12 energy) on each sublayer


@dataclass(frozen=True)
class Enrichment:
    """One enrichment function φ(ξ) of the core: which level adds it and how to evaluate it."""

    level: int
    kind: str  # "value" | "slope" (sublayer hats) or "poly"
    centre: float = 0.0  # sublayer hats: the inserted surface p
    left: float = -1.0  # its neighbours on the partition of its level
    right: float = 1.0
    degree: int = 0  # polynomial: φ = (1 − ξ²)² P_degree(ξ)

    def __call__(self, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """φ(ξ) and dφ/dξ, shaped like ``xi``."""
        ξ = np.asarray(xi, dtype=float)
        if self.kind == "poly":
            P = np.polynomial.legendre.Legendre.basis(self.degree)
            b = (1 - ξ**2)
            return b**2 * P(ξ), -4 * ξ * b * P(ξ) + b**2 * P.deriv()(ξ)
        value, slope = np.zeros_like(ξ), np.zeros_like(ξ)
        for a, c, node in ((self.left, self.centre, 1), (self.centre, self.right, 0)):
            inside = (ξ >= a) & (ξ <= c) if node == 1 else (ξ > a) & (ξ <= c)
            t = 2 * (ξ[inside] - a) / (c - a) - 1
            if self.kind == "value":
                v, dv = x_shape("H", node, t)
                value[inside], slope[inside] = v, dv * 2 / (c - a)
            else:  # unit ξ-slope at p: (c − a)/2 · H̄_ref(t)
                v, dv = x_shape("Hbar", node, t)
                value[inside], slope[inside] = v * (c - a) / 2, dv
        return value, slope


@dataclass(frozen=True)
class CoreBasis:
    """The enrichment functions of a family up to ``max_level``, in hierarchical order."""

    family: str
    max_level: int

    def __post_init__(self) -> None:
        if self.family not in CORE_BASES:
            raise ValueError(f"core basis must be one of {CORE_BASES}, got {self.family!r}")
        if not (isinstance(self.max_level, int | np.integer) and 1 <= self.max_level <= MAX_LEVEL):
            raise ValueError(
                f"core level must be an integer 1..{MAX_LEVEL}, got {self.max_level!r}")

    @cached_property
    def functions(self) -> tuple[Enrichment, ...]:
        """Every enrichment function up to ``max_level``, lower levels first."""
        out: list[Enrichment] = []
        for level in range(2, self.max_level + 1):
            if self.family == "polynomial":
                first = POLY_PER_LEVEL * (level - 2)
                out += [Enrichment(level, "poly", degree=d)
                        for d in range(first, first + POLY_PER_LEVEL)]
                continue
            new = self.partition(level)
            for p in self._inserted(level):
                i = int(np.searchsorted(new, p))
                a, c = new[i - 1], new[i + 1]  # p's neighbours on its level's partition
                out += [Enrichment(level, "value", p, a, c), Enrichment(level, "slope", p, a, c)]
        return tuple(out)

    def count(self, level: int) -> int:
        """Number of enrichment functions active at ``level`` (0 at level 1)."""
        return sum(1 for f in self.functions if f.level <= level)

    @staticmethod
    def _inserted(level: int) -> tuple[float, float]:
        δ = SUBLAYER_FIRST * SUBLAYER_RATIO ** (level - 2)
        return (-1 + δ, 1 - δ)

    def partition(self, level: int) -> np.ndarray:
        """Sublayer surfaces in ξ at ``level`` (sorted; [−1, 1] at level 1 and for polynomials)."""
        pts = [-1.0, 1.0]
        if self.family == "sublayers":
            for ℓ in range(2, level + 1):
                pts += list(self._inserted(ℓ))
        return np.array(sorted(pts))

    def rule(self, level: int) -> tuple[np.ndarray, np.ndarray]:
        """Gauss points and weights in ξ on [−1, 1], exact for the level's strain energy."""
        if self.family == "polynomial":
            degree = 3 + POLY_PER_LEVEL * (level - 1)
            return gauss_legendre(2 * degree + 1)
        ref, w = gauss_legendre(EXACT_POINTS_PER_SUBLAYER)
        cuts = self.partition(level)
        half = 0.5 * np.diff(cuts)
        mid = 0.5 * (cuts[1:] + cuts[:-1])
        return ((mid[:, None] + half[:, None] * ref[None, :]).ravel(),
                (half[:, None] * w[None, :]).ravel())


@dataclass(frozen=True)
class ModeDof:
    """One nodal enrichment DOF: amplitude of function ``function`` in ``field``, x kind."""

    name: str
    function: int
    field: str  # "u" | "w"
    x_kind: str  # "H" | "Hbar"


def mode_dofs(basis: CoreBasis, level: int) -> tuple[ModeDof, ...]:
    """The enrichment DOFs of a node at ``level``, in their nodal order (4 per function)."""
    return tuple(
        ModeDof(f"{field}_c{k + 1}{',x' if kind == 'Hbar' else ''}", k, field, kind)
        for k in range(basis.count(level)) for field in ("u", "w") for kind in X_KINDS
    )
