"""Constraints that close the system R(u, λ) = 0 with one more equation for λ.

Each Newton iteration solves, with one factorised tangent ``K``, the two systems

    K δu_R = −R,        K δu_f = f_ref,

and every correction has the form ``δu = δu_R + δλ δu_f`` (the bordered system eliminated by
blocks). A constraint only has to pick ``δλ``:

- :class:`LoadConstraint` — λ prescribed: ``δλ = λ* − λ``;
- :class:`ProbeConstraint` — a probe ``c · u`` prescribed (displacement control):
  ``δλ = (v* − c·u − c·δu_R) / (c·δu_f)``;
- :class:`ArcLengthConstraint` — Crisfield's quadratic arc constraint on the step increment
  ``(Δu, Δλ)`` counted from the last converged state,
  ``‖Δu + δu‖² + ψ² (Δλ + δλ)² = Δs²``, with the root that keeps the increment closest in angle
  to the previous iterate's increment. ``ψ`` scales λ into displacement units (``ψ = 0`` gives
  Crisfield's cylindrical arc).

A constraint returns ``None`` when it cannot produce a correction (insensitive probe, complex
roots); the corrector then reports a failure.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

__all__ = ["ArcLengthConstraint", "Constraint", "LoadConstraint", "ProbeConstraint"]

Dot = Callable[[np.ndarray, np.ndarray], float]


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    return float(a @ b)


class Constraint(Protocol):
    """The extra equation of the corrector."""

    def delta_lambda(
        self,
        du_r: np.ndarray,
        du_f: np.ndarray,
        u: np.ndarray,
        load_factor: float,
        delta_u: np.ndarray,
        delta_lambda: float,
    ) -> float | None:
        """Return δλ for the correction ``δu = du_r + δλ du_f``, or ``None`` if impossible.

        Parameters
        ----------
        du_r, du_f
            ``K⁻¹(−R)`` and ``K⁻¹ f_ref`` at the current iterate.
        u, load_factor
            Current iterate.
        delta_u, delta_lambda
            Current iterate minus the last converged state (the step increment so far).
        """
        ...


@dataclass(frozen=True)
class LoadConstraint:
    """Load control: λ = ``target``."""

    target: float

    def delta_lambda(
        self,
        du_r: np.ndarray,
        du_f: np.ndarray,
        u: np.ndarray,
        load_factor: float,
        delta_u: np.ndarray,
        delta_lambda: float,
    ) -> float | None:
        """Return ``target − λ``."""
        return self.target - load_factor


@dataclass(frozen=True)
class ProbeConstraint:
    """Displacement control: ``c · u = target`` with λ an unknown."""

    c: np.ndarray
    target: float
    dot: Dot | None = None  # the system's global inner product (MPI); default a @ b

    def delta_lambda(
        self,
        du_r: np.ndarray,
        du_f: np.ndarray,
        u: np.ndarray,
        load_factor: float,
        delta_u: np.ndarray,
        delta_lambda: float,
    ) -> float | None:
        """Return the δλ that puts the linearised probe on ``target``."""
        dot = self.dot or _dot
        cf = dot(self.c, du_f)
        scale = math.sqrt(max(dot(self.c, self.c), 0.0) * max(dot(du_f, du_f), 0.0))
        if not math.isfinite(cf) or abs(cf) <= 1e-13 * scale or scale == 0.0:
            return None  # the probe does not respond to the load: a turning point of the probe
        return (self.target - dot(self.c, u) - dot(self.c, du_r)) / cf


@dataclass(frozen=True)
class ArcLengthConstraint:
    """Crisfield's arc ``‖Δu‖² + ψ² Δλ² = radius²`` on the step increment.

    Parameters
    ----------
    radius
        Arc length Δs of the step (displacement units).
    psi
        Weight of λ in the arc (displacement per unit load factor); ``0`` is the cylindrical arc.
    """

    radius: float
    psi: float
    dot: Dot | None = None  # the system's global inner product (MPI); default a @ b

    def delta_lambda(
        self,
        du_r: np.ndarray,
        du_f: np.ndarray,
        u: np.ndarray,
        load_factor: float,
        delta_u: np.ndarray,
        delta_lambda: float,
    ) -> float | None:
        """Return the root of the quadratic arc equation closest in angle to the last increment."""
        dot = self.dot or _dot
        psi2 = self.psi * self.psi
        w = delta_u + du_r
        a = dot(du_f, du_f) + psi2
        b = 2.0 * (dot(du_f, w) + psi2 * delta_lambda)
        c = dot(w, w) + psi2 * delta_lambda * delta_lambda - self.radius * self.radius
        disc = b * b - 4.0 * a * c
        if not (math.isfinite(disc) and a > 0.0):
            return None
        if disc < 0.0:
            # Complex roots: accept a tiny negative discriminant from round-off, else give up.
            if disc < -1e-10 * b * b:
                return None
            disc = 0.0
        sq = math.sqrt(disc)
        q = -0.5 * (b + math.copysign(sq, b))  # numerically stable roots
        roots = [q / a, c / q] if q != 0.0 else [0.0]
        # Crisfield's angle criterion: maximise the projection of the new increment on the old.
        old_norm2 = dot(delta_u, delta_u) + psi2 * delta_lambda * delta_lambda

        def projection(dl: float) -> float:
            new_u = w + dl * du_f
            return dot(new_u, delta_u) + psi2 * (delta_lambda + dl) * delta_lambda

        if old_norm2 == 0.0:
            return min(roots, key=abs)
        return max(roots, key=projection)
