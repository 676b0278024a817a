"""Small discrete systems with closed-form equilibrium paths, for the solver tests.

All satisfy the :class:`sandwich.solver.DiscreteSystem` protocol and factorise their (dense)
tangents with :class:`sandwich.solver.SparseFactorization`, so the inertia is exercised too.
"""

from __future__ import annotations

import math

import numpy as np

from sandwich.solver import SparseSystemMixin


class ToySystem(SparseSystemMixin):
    """Common bookkeeping: probes are unit vectors on named DOFs; commits are recorded."""

    dof_names: tuple[str, ...] = ()
    load_dof: int = 0

    def __init__(self) -> None:
        self.commits: list[tuple[np.ndarray, float]] = []
        self.evaluations = 0

    @property
    def size(self) -> int:
        return len(self.dof_names)

    @property
    def f_ref(self) -> np.ndarray:
        f = np.zeros(self.size)
        f[self.load_dof] = self.p_ref
        return f

    p_ref = 1.0

    def probe_vector(self, name: str) -> np.ndarray:
        c = np.zeros(self.size)
        c[self.dof_names.index(name)] = 1.0
        return c

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        assert np.all(np.isfinite(u)) and math.isfinite(load_factor)
        self.commits.append((u.copy(), load_factor))


class VonMisesTruss(ToySystem):
    """Shallow two-bar (von Mises) truss, apex deflection ``w`` (downwards) under ``λ P``.

    Bars of axial stiffness ``EA``, half-span ``a``, rise ``h``; the strain energy is
    ``2 · EA/(2 L0) · (L − L0)²`` with ``L(w) = √(a² + (h − w)²)``, so

        f(w)  = 2 EA (h − w) (1/L − 1/L0),
        f'(w) = 2 EA [(h − w)²/L³ − 1/L + 1/L0],
        f''(w) = −6 EA a² (h − w) / L⁵.

    With ``spring`` given, a spring of that stiffness links the apex (``w1``) to a second DOF
    ``w2`` where the load acts (2 DOFs); otherwise the load acts on the apex (1 DOF, ``w``).
    """

    def __init__(self, ea: float = 1000.0, a: float = 1.0, h: float = 0.4,
                 spring: float | None = None) -> None:
        super().__init__()
        self.ea, self.a, self.h, self.ks = ea, a, h, spring
        self.l0 = math.hypot(a, h)
        self.dof_names = ("w",) if spring is None else ("w1", "w2")
        self.load_dof = self.size - 1

    # closed form of the bars -------------------------------------------------------------
    def bar_force(self, w: np.ndarray | float) -> np.ndarray | float:
        y = self.h - np.asarray(w, dtype=float)
        L = np.sqrt(self.a**2 + y**2)
        return 2.0 * self.ea * y * (1.0 / L - 1.0 / self.l0)

    def bar_stiffness(self, w: np.ndarray | float) -> np.ndarray | float:
        y = self.h - np.asarray(w, dtype=float)
        L = np.sqrt(self.a**2 + y**2)
        return 2.0 * self.ea * (y**2 / L**3 - 1.0 / L + 1.0 / self.l0)

    def bar_curvature(self, w: np.ndarray | float) -> np.ndarray | float:
        y = self.h - np.asarray(w, dtype=float)
        L = np.sqrt(self.a**2 + y**2)
        return -6.0 * self.ea * self.a**2 * y / L**5

    def limit_points(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((w_max, λ_max), (w_min, λ_min))``: f'(w) = 0 ⇔ L³ = a² L0 (closed form)."""
        L = (self.a**2 * self.l0) ** (1.0 / 3.0)
        y = math.sqrt(L**2 - self.a**2)
        out = []
        for w in (self.h - y, self.h + y):
            out.append((w, float(self.bar_force(w)) / self.p_ref))
        return out[0], out[1]

    # DiscreteSystem -----------------------------------------------------------------------
    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        if self.ks is None:
            return np.array([self.bar_force(u[0])])
        s = self.ks * (u[1] - u[0])
        return np.array([self.bar_force(u[0]) - s, s])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        k = float(self.bar_stiffness(u[0]))
        if self.ks is None:
            return np.array([[k]])
        return np.array([[k + self.ks, -self.ks], [-self.ks, self.ks]])


class Pitchfork(ToySystem):
    """Symmetric two-DOF system with a pitchfork on a monotonically loaded fundamental path.

    Potential ``Π = ½ k1 x² + ½ k2 y² − ½ x y² + ¼ y⁴ − λ P x``: on the fundamental path
    ``y = 0, x = λ P / k1`` the tangent is ``diag(k1, k2 − x)``, so it loses positive
    definiteness at ``λ_c = k1 k2 / P`` while λ keeps increasing (no load maximum).
    """

    dof_names = ("x", "y")
    load_dof = 0

    def __init__(self, k1: float = 2.0, k2: float = 1.0) -> None:
        super().__init__()
        self.k1, self.k2 = k1, k2

    @property
    def critical_load_factor(self) -> float:
        return self.k1 * self.k2 / self.p_ref

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        x, y = u
        return np.array([self.k1 * x - 0.5 * y * y, self.k2 * y - x * y + y**3])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        x, y = u
        return np.array([[self.k1, -y], [-y, self.k2 - x + 3.0 * y * y]])


class CurvedPitchfork(ToySystem):
    """A pitchfork whose critical eigenvalue is not linear in λ along the fundamental path.

    Potential ``Π = ½ k1 x² + ⅓ a x³ + ½ k2 y² − ½ x y² + ¼ y⁴ − λ P x``: on ``y = 0``,
    ``k1 x + a x² = λ P`` and the tangent is ``diag(k1 + 2 a x, k2 − x)``, singular at
    ``x = k2``, i.e. ``λ_c = (k1 k2 + a k2²) / P``; the eigenvalue ``k2 − x(λ)`` is curved in λ.
    """

    dof_names = ("x", "y")
    load_dof = 0

    def __init__(self, k1: float = 2.0, k2: float = 1.0, a: float = 1.5) -> None:
        super().__init__()
        self.k1, self.k2, self.a = k1, k2, a

    @property
    def critical_load_factor(self) -> float:
        return (self.k1 * self.k2 + self.a * self.k2**2) / self.p_ref

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        x, y = u
        return np.array([self.k1 * x + self.a * x * x - 0.5 * y * y,
                         self.k2 * y - x * y + y**3])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        x, y = u
        return np.array([[self.k1 + 2.0 * self.a * x, -y], [-y, self.k2 - x + 3.0 * y * y]])


class BoundedDomain(ToySystem):
    """``f(u) = u / (1 − u)`` defined only for ``u < 1`` (NaN beyond): equilibrium
    ``u = λ / (1 + λ)``. A tangent predictor ``u = Δλ`` leaves the domain when ``Δλ ≥ 1 − u``."""

    dof_names = ("u",)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(u < 1.0, u / (1.0 - u), np.nan)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[1.0 / (1.0 - u[0]) ** 2]]) if u[0] < 1.0 else np.array([[np.nan]])


class Saturating(ToySystem):
    """``f(u) = tanh(u)``: equilibrium ``u = artanh(λ)`` exists only for ``|λ| < 1``."""

    dof_names = ("u",)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return np.tanh(u)

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[1.0 / np.cosh(u[0]) ** 2]])


class SvkBar(ToySystem):
    """A St. Venant–Kirchhoff bar (length ``L``, axial stiffness ``EA``) crushed by ``λ P``.

    Shortening ``w``, stretch ``s = 1 − w/L``; the Green-strain law S = E (s² − 1)/2 gives the
    compressive resistance

        f(w)  = EA s (1 − s²) / 2,        f'(w) = EA (3 s² − 1) / (2 L),

    a material limit point at ``s = 1/√3`` (``λ_max P = EA / (3√3)``), zero force at ``s = 0``
    (the bar crushed flat) and, beyond, equilibrium states with the bar turned inside out
    (``s < 0``) and λ < 0 — the law has no physical meaning there. With ``guard`` the system
    declares those states inadmissible (``admissible(u)``), as the 2D reference does for
    det F ≤ 0.
    """

    dof_names = ("w",)

    def __init__(self, ea: float = 100.0, length: float = 1.0, guard: bool = True) -> None:
        super().__init__()
        self.ea, self.length = ea, length
        if guard:
            self.admissible = self._admissible

    def stretch(self, w: np.ndarray | float) -> np.ndarray | float:
        return 1.0 - np.asarray(w, dtype=float) / self.length

    def force(self, w: np.ndarray | float) -> np.ndarray | float:
        s = self.stretch(w)
        return 0.5 * self.ea * s * (1.0 - s * s)

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        return np.array([float(self.force(u[0]))])

    def tangent(self, u: np.ndarray) -> np.ndarray:
        s = float(self.stretch(u[0]))
        return np.array([[0.5 * self.ea * (3.0 * s * s - 1.0) / self.length]])

    def _admissible(self, u: np.ndarray) -> str:
        s = float(self.stretch(u[0]))
        return "" if s > 0.0 else f"bar inverted (stretch {s:.3g} <= 0)"
