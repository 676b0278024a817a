"""The cohesive law of a growing interface: bilinear, mixed-mode, Benzeggagh–Kenane, irreversible.

Model-independent (the contract): the beam applies it on its interface pairs
(:mod:`sandwich.beam.cohesive`).

Tractions on the interface per unit area (MPa) of the opening g (along the core's deformed
normal, > 0 opens) and the sliding s (mm), with a scalar damage D ∈ [0, 1] that never decreases:

    t_n = (1 − D) K g,    t_s = (1 − D) K s,

K the penalty stiffness (N/mm³). In compression (g < 0) the contact law of the debonded
stretches acts as well (:mod:`sandwich.beam.contact_law`, added by the caller), so a fully
damaged interface is the frictionless contact of a debond; the damage is driven by the opening
and the sliding only, and t_n in compression takes the damage of the last converged state
(the sliding of a closed pair does not change its normal traction within an increment, which
keeps the tangent symmetric there; the updated damage acts from the next increment on).

Damage (Camanho & Dávila 2002, with the thresholds of Turon et al. 2010 that make the law
consistent under changing mode mix). The mixed-mode jump δ = √(⟨g⟩² + s²) and its mode mix
B = s² / δ² (= G_II / G under a constant mix, the two stiffnesses being equal). Onset and
final jumps:

    δ₀ = √(δ₀ₙ² + (δ₀ₛ² − δ₀ₙ²) B^η),           δ₀ₙ = σ_c / K,   δ₀ₛ = τ_c / K,
    δ_f = (δ₀ₙ δ_fn + (δ₀ₛ δ_fs − δ₀ₙ δ_fn) B^η) / δ₀,   δ_fn = 2 G_Ic / σ_c,  δ_fs = 2 G_IIc / τ_c,

so that the work of separation under a constant mix, ½ K δ₀ δ_f, is the Benzeggagh–Kenane
toughness G_Ic + (G_IIc − G_Ic) B^η. The trial damage of a jump is

    d(δ) = δ_f (δ − δ₀) / (δ (δ_f − δ₀)),  0 below δ₀, 1 beyond δ_f,

and D = max(D_committed, d(δ)): damage only grows, and unloading goes linearly to the origin.

The local tangent ∂(t_n, t_s)/∂(g, s) is computed by complex-step differentiation of the same
expressions (exact to round-off, with the damage growing where the trial damage exceeds the
committed one). It is symmetric where the mode mix does not change along the increment, not
where it does: the beam model then solves with the whole matrix
(:mod:`sandwich.beam.unsymmetric`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

STEP = 1e-30  # complex step (mm); any step far below the jumps gives the derivative exactly
TINY = 1e-300


@dataclass(frozen=True)
class CohesiveLaw:
    """The law's constants: stiffness K (N/mm³), strengths (MPa), toughnesses (N/mm), η."""

    stiffness: float
    sigma_c: float
    tau_c: float
    GIc: float
    GIIc: float
    eta: float = 2.0

    def __post_init__(self) -> None:
        for name in ("stiffness", "sigma_c", "tau_c", "GIc", "GIIc", "eta"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"cohesive law: {name} must be positive, got {v!r}")
        if self.stiffness <= self.least_stiffness():
            raise ValueError(f"cohesive law: stiffness {self.stiffness:g} N/mm³ must exceed "
                             f"{self.least_stiffness():g} (σ_c²/(2 G_Ic), τ_c²/(2 G_IIc)): below "
                             "it the law softens before it reaches its strength")

    def least_stiffness(self) -> float:
        """The stiffness below which a pure mode's final jump falls below its onset (N/mm³)."""
        return least_stiffness(self.sigma_c, self.tau_c, self.GIc, self.GIIc)

    def toughness(self, mix: np.ndarray | float) -> np.ndarray:
        """Benzeggagh–Kenane G_c at the mode mix B = G_II / G (N/mm)."""
        return self.GIc + (self.GIIc - self.GIc) * np.asarray(mix) ** self.eta

    def jumps(self, mix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Onset and final jumps δ₀, δ_f (mm) at the mode mix ``mix`` (real or complex)."""
        K = self.stiffness
        d0n, d0s = self.sigma_c / K, self.tau_c / K
        dfn, dfs = 2 * self.GIc / self.sigma_c, 2 * self.GIIc / self.tau_c
        be = mix**self.eta
        d0 = np.sqrt(d0n**2 + (d0s**2 - d0n**2) * be)
        return d0, (d0n * dfn + (d0s * dfs - d0n * dfn) * be) / d0

    def trial_damage(self, g: np.ndarray, s: np.ndarray) -> np.ndarray:
        """d(δ) of the jumps (g, s) (real or complex arrays), before the history's maximum."""
        gp = np.where(np.real(g) > 0, g, 0.0)
        d2 = gp * gp + s * s
        live = np.real(d2) > TINY
        d2safe = np.where(live, d2, 1.0)
        delta = np.sqrt(d2safe)
        mix = np.where(live, s * s / d2safe, 0.0)
        d0, df = self.jumps(mix)
        d = df * (delta - d0) / (delta * (df - d0))
        d = np.where(np.real(delta) <= np.real(d0), 0.0, d)
        d = np.where(np.real(delta) >= np.real(df), 1.0, d)
        return np.where(live, d, 0.0)

    def damage(self, g: np.ndarray, s: np.ndarray, committed: np.ndarray) -> np.ndarray:
        """D = max(committed, d(g, s)): the damage of the jumps (g, s) after the history."""
        d = self.trial_damage(g, s)
        return np.where(np.real(d) > committed, d, committed)

    def tractions(self, g: np.ndarray, s: np.ndarray, committed: np.ndarray) -> np.ndarray:
        """(t_n, t_s) (MPa), stacked on the last axis, of the jumps after the history."""
        keep = 1.0 - self.damage(g, s, committed)
        closed = np.where(np.real(g) < 0, 1.0 - committed, keep)  # compression: committed D
        return np.stack([closed * self.stiffness * g, keep * self.stiffness * s], axis=-1)

    def response(self, g: np.ndarray, s: np.ndarray, committed: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Tractions (m, 2), tangent (m, 2, 2), damage (m,) and its gradient (m, 2).

        The tangent ∂t/∂(g, s) and the gradient ∂D/∂(g, s) by complex steps in g and in s
        (see the module docstring).
        """
        g = np.asarray(g, dtype=float)
        s = np.asarray(s, dtype=float)
        committed = np.asarray(committed, dtype=float)
        t = self.tractions(g, s, committed).real
        gc, sc = g + 1j * STEP, s + 1j * STEP
        dg = self.tractions(gc, s.astype(complex), committed).imag / STEP
        ds = self.tractions(g.astype(complex), sc, committed).imag / STEP
        T = np.stack([dg, ds], axis=-1)  # T[:, i, j] = ∂t_i / ∂(g, s)_j
        dD = np.stack([self.damage(gc, s.astype(complex), committed).imag,
                       self.damage(g.astype(complex), sc, committed).imag], axis=-1) / STEP
        return t, T, self.damage(g, s, committed).real, dD


@dataclass(eq=False)
class CohesiveTip:
    """A debond tip grown by the law: the law, which tip, where it started and which way."""

    law: CohesiveLaw
    debond: int
    tip: str  # "start" | "end"
    origin: float  # the tip's x at the start of the run (mm)
    direction: int  # +1: the tip grows towards larger x


def least_stiffness(sigma_c: float, tau_c: float, GIc: float, GIIc: float) -> float:
    """max(σ_c²/(2 G_Ic), τ_c²/(2 G_IIc)) (N/mm³): a stiffer law reaches its strengths."""
    return max(sigma_c**2 / (2 * GIc), tau_c**2 / (2 * GIIc))


def default_shear_strength(sigma_c: float, GIc: float, GIIc: float) -> float:
    """τ_c = σ_c √(G_IIc/G_Ic) (MPa): both pure modes then soften over the same jump ratio."""
    return sigma_c * (GIIc / GIc) ** 0.5


STIFFNESS_FACTOR = 1e3  # default K = STIFFNESS_FACTOR · Q_z / h_c


def default_stiffness(core_modulus: float, core_thickness: float, law_floor: float) -> float:
    """The default K (N/mm³): ``STIFFNESS_FACTOR`` × the core's through-thickness Q_z / h_c.

    The bonded interface then adds 1e-3 to the core's through-thickness compliance: the face
    cantilever undamaged is 0.31 % more compliant than tied on the same mesh (0.05 % at
    10⁴ Q_z / h_c, where its displacement-controlled growth stops at the first node's
    release: the stiffer the law's rise, the more abrupt each node's softening). At least ten
    times ``law_floor`` (:meth:`CohesiveLaw.least_stiffness`), so that the law's elastic part
    stays a small share of its work of separation.
    """
    return max(STIFFNESS_FACTOR * core_modulus / core_thickness, 10.0 * law_floor)
