"""Newton's method at a fixed load factor on a :class:`DiscreteSystem`.

Used for manufactured solutions and tests; path following lives in :mod:`sandwich.solver.path`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class NewtonResult:
    """Outcome of a Newton solve: the state, whether it converged, and the residual log."""

    u: np.ndarray
    converged: bool
    iterations: int
    residuals: list[float] = field(default_factory=list)  # ‖R‖ before each update, then final
    negative_pivots: int | None = None


def newton(system, u0: np.ndarray, load_factor: float, tol: float = 1e-10,
           max_iterations: int = 30) -> NewtonResult:
    """Solve f_int(u) = λ f_ref to ‖R‖ ≤ tol ‖λ f_ref‖ (or a round-off-level correction)."""
    norm_of = getattr(system, "norm", np.linalg.norm)  # global over MPI ranks if provided
    u = u0.copy()
    f_ext = load_factor * system.f_ref
    scale = max(norm_of(f_ext), 1e-300)
    log = []
    neg = None
    du_norm = np.inf
    for it in range(max_iterations + 1):
        r = system.internal_force(u) - f_ext
        norm = float(norm_of(r))
        log.append(norm)
        if not np.isfinite(norm):
            return NewtonResult(u, False, it, log, neg)
        # converged: small residual, or a correction at round-off level of the state
        if norm <= tol * scale or du_norm <= 1e-13 * norm_of(u):
            return NewtonResult(u, True, it, log, neg)
        if it == max_iterations:
            break
        fac = system.factorize(system.tangent(u))
        neg = fac.negative_pivots
        du = fac.solve(r)
        du_norm = float(norm_of(du))
        u = u - du
    return NewtonResult(u, False, max_iterations, log, neg)
