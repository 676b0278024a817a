"""Where, within a step, the tangent turns singular: a bifurcation located between two states.

A bifurcation is detected when the tangent's negative-pivot count changes between two converged
states A and B (:mod:`sandwich.solver.limits`); it lies somewhere on that step, and reporting it
at B is wrong by up to the whole step (first order in the step length: the longer steps the
controller takes, the larger the error — up to 13 % of the load on the knock-down study's
centred debonds, benchmarks/results/beam/critical_location.md).

The eigenvalues that crossed zero are computed at both ends from the two factorisations the
path already has (solves only: no tangent is evaluated, so the path that follows is not
disturbed):

* at B, the eigenvalues of K_B nearest zero by subspace inverse iteration (a block of
  :data:`BLOCK` + |change| − 1 vectors, X ← orth(K⁻¹X), Rayleigh–Ritz on K⁻¹ over
  span X); the crossed ones are the |change| nearest zero whose sign is the new one (negative
  where the count rose);
* at A, the same iteration started from B's vectors; the Ritz vector nearest each of B's
  (largest overlap) is the same mode, whose eigenvalue must have the old sign.

Each crossed eigenvalue is then taken as linear along the step, μ(t) = μ_A + t (μ_B − μ_A),
t ∈ (0, 1) the fraction of the step, so it is zero at t* = μ_A / (μ_A − μ_B); the first of
them (the smallest t*) is the bifurcation, and the load factor and probes there are
interpolated at t*. The error is second order in the step (the curvature of μ along it) where
reporting B's values is first order (`tests/solver/test_solver_critical_location.py`: the
order measured on a synthetic family, and on a pitchfork whose eigenvalue is not linear in λ).
The eigenvalues are those of K in the Euclidean metric of the free unknowns (no mass or metric
matrix): their zero crossing is the singular tangent whatever the metric; the metric only
changes how straight μ(t) is. Two eigenvalues crossing on one step are both located where the
iteration reaches them: those nearest zero at B must include them (on fig. 6 and c1 at the
paper's core both are far past zero at the step's end, behind smaller positive ones, and the
step is not located from its ends; :mod:`sandwich.solver.path` can narrow it instead).

Nothing is located (None) where the count changed by more than :data:`MAX_CROSSINGS`, an
iteration did not settle in :data:`MAX_ITERATIONS`, or the matched eigenvalues do not change
sign: the bifurcation is then reported at B as before.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sandwich.solver.system import _local_dot

__all__ = ["BracketEnd", "Crossing", "CrossingFraction", "crossed_eigenvalue", "crossing_in",
           "locate_crossing", "nearest_eigenpairs", "next_fraction", "zero_fraction"]

#: Vectors of the inverse-iteration block for one crossed eigenvalue (one more per further
#: crossed one; at most the system's size).
BLOCK = 3
#: Most eigenvalues located on one step (a count that changed by more is not located).
MAX_CROSSINGS = 2
#: Inverse iterations allowed at each end of the step. The crossed eigenvalues are the block's
#: nearest to zero and settle in 3-8; one that needs more is not well separated from another
#: (a near-degenerate pair of modes: the 20-mm centred debond of the knock-down study), its
#: vector is unreliable, and the step is not located from its ends.
MAX_ITERATIONS = 12
#: Relative change of the crossed eigenvalue's Ritz value at which the iteration has converged
#: (an error ε in μ at the two ends moves the located fraction t by at most ε t (1 − t) · 2).
RITZ_TOL = 1e-4
#: Equilibria solved inside a step across a bifurcation (or a load extremum,
#: :mod:`sandwich.solver.extrema`) to narrow it (each one corrector of a shorter step from the
#: state before), with ``PathOptions.locate_critical_points``.
MAX_SUBSTEPS = 3
#: Narrowing stops once the located load factor moves by less than this (relative), or the
#: bracket is narrower than it.
LOCATE_RTOL = 2e-3
#: A regula-falsi try stays this fraction of the bracket away from either end.
SAFEGUARD = 0.05


@dataclass(frozen=True)
class CrossingFraction:
    """The fraction ``t`` of the step A → B at which the tangent is singular, and its evidence."""

    t: float
    mu_before: float  # the crossed eigenvalue at A
    mu_after: float  # at B


def _start_block(size: int, m: int) -> np.ndarray:
    """A fixed pseudo-random (size, m) start block: the same answer on every run."""
    return np.random.default_rng(20261205).standard_normal((size, m))


def _solve_block(fac: object, X: np.ndarray) -> np.ndarray:
    if getattr(fac, "solves_columns", False):
        return np.asarray(fac.solve(X), dtype=float).reshape(X.shape)
    return np.column_stack([np.asarray(fac.solve(X[:, j]), dtype=float)
                            for j in range(X.shape[1])])


def _gram(dot: Callable, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """XᵀY under ``dot`` (one product where it is the plain local one; MPI: pair by pair)."""
    if dot is _local_dot:
        return X.T @ Y
    m = X.shape[1]
    return np.array([[dot(X[:, i], Y[:, j]) for j in range(m)] for i in range(m)])


def _orthonormal(dot: Callable, X: np.ndarray) -> np.ndarray | None:
    """X R⁻¹ with RᵀR = XᵀX (under ``dot``), or None if the block is rank deficient."""
    G = _gram(dot, X, X)
    G = 0.5 * (G + G.T)
    try:
        R = np.linalg.cholesky(G).T
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(R)) or np.min(np.abs(np.diag(R))) <= 1e-12 * np.max(np.abs(R)):
        return None
    return np.linalg.solve(R.T, X.T).T


def nearest_eigenpairs(
    fac: object, start: np.ndarray, dot: Callable,
    pick: Callable[[np.ndarray, np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, int] | None:
    """The eigenpairs of K picked by ``pick`` among those nearest zero, by inverse iteration.

    ``fac`` solves with K (``fac.solve``); ``start`` is the (n, m) start block; ``pick(mu, V)``
    returns the indices of the wanted Ritz pairs (eigenvalues ``mu``, vectors the columns of
    ``V``), empty for none. Returns (their μ, their unit vectors as columns, iterations), or
    None where the block degenerates or the picked values have not settled to
    :data:`RITZ_TOL` within :data:`MAX_ITERATIONS`.
    """
    X = _orthonormal(dot, start)
    previous = None
    for it in range(1, MAX_ITERATIONS + 1):
        if X is None:
            return None
        Y = _solve_block(fac, X)
        if not np.all(np.isfinite(Y)):
            return None
        H = _gram(dot, X, Y)  # Rayleigh–Ritz for K⁻¹ on span X (X orthonormal)
        nu, C = np.linalg.eigh(0.5 * (H + H.T))
        keep = np.abs(nu) > 0.0
        mu = np.where(keep, 1.0 / np.where(keep, nu, 1.0), np.inf)
        V = X @ C
        k = np.asarray(pick(mu, V), dtype=int)
        values = mu[k]
        if k.size and previous is not None and previous.size == k.size and \
                np.all(np.isfinite(values)) and \
                np.all(np.abs(values - previous) <= RITZ_TOL * np.abs(values)):
            W = V[:, k] / np.sqrt([dot(V[:, j], V[:, j]) for j in k])
            return values, W, it
        previous = values if k.size else None
        X = _orthonormal(dot, Y @ C)  # the next block, its columns ordered as the Ritz pairs
    return None


def locate_crossing(
    fac_before: object, fac_after: object, change: int, size: int, dot: Callable,
    seed_vector: np.ndarray | None = None,
) -> CrossingFraction | None:
    """The fraction of the step A → B at which the first eigenvalue that changed sign crosses.

    ``fac_before``/``fac_after`` are the factorised tangents at A and B; ``change`` the change
    of their negative-pivot counts (0 < |change| ≤ :data:`MAX_CROSSINGS`: that many eigenvalues
    changed sign on the step, each is located and the first crossing is returned);
    ``seed_vector`` (optional, length ``size``) joins the start block, e.g. the step's
    displacement increment.
    """
    crossed = abs(change)
    if not 0 < crossed <= MAX_CROSSINGS or size < crossed:
        return None
    m = min(BLOCK + crossed - 1, size)
    start = _start_block(size, m)
    if seed_vector is not None and m > crossed and np.all(np.isfinite(seed_vector)) \
            and np.any(seed_vector):
        start[:, -1] = seed_vector
    new_sign = -1.0 if change > 0 else 1.0  # the crossed eigenvalues' sign at B

    def nearest_of_new_sign(mu: np.ndarray, V: np.ndarray) -> np.ndarray:
        ok = np.flatnonzero(np.sign(mu) == new_sign)
        if ok.size < crossed:
            return np.empty(0, dtype=int)
        return ok[np.argsort(np.abs(mu[ok]))[:crossed]]

    after = nearest_eigenpairs(fac_after, start, dot, nearest_of_new_sign)
    if after is None:
        return None
    mu_b, V_b, _ = after

    def same_modes(mu: np.ndarray, V: np.ndarray) -> np.ndarray:
        overlap = np.abs(np.array([[dot(V[:, j], V_b[:, i]) for j in range(V.shape[1])]
                                   for i in range(crossed)]))
        best = np.argmax(overlap, axis=1)
        return best if np.unique(best).size == crossed else np.empty(0, dtype=int)

    start_a = start.copy()
    start_a[:, :crossed] = V_b
    before = nearest_eigenpairs(fac_before, start_a, dot, same_modes)
    if before is None:
        return None
    mu_a, _, _ = before
    if not np.all(np.sign(mu_a) == -new_sign):
        return None
    t = mu_a / (mu_a - mu_b)
    first = int(np.argmin(t))
    if not 0.0 < t[first] < 1.0:  # pragma: no cover - opposite signs give t in (0, 1)
        return None
    return CrossingFraction(float(t[first]), float(mu_a[first]), float(mu_b[first]))


@dataclass(frozen=True)
class BracketEnd:
    """A converged equilibrium on a step across a critical point.

    Its fraction ``f`` of the step's size from the state before, its load factor, probes and
    crossed μ.
    """

    f: float
    load_factor: float
    probes: dict[str, float]
    mu: float | None  # the crossed eigenvalue there (None: not found)


@dataclass(frozen=True)
class Crossing:
    """A bifurcation located within the step that ends at a path state.

    ``fraction`` of the step's size from the state before (the located point), its
    ``load_factor`` and ``probes`` (interpolated between the ends of the final bracket),
    ``between`` the load factors of that bracket's ends (converged equilibria either side of
    the crossing: the step's two states, or equilibria solved inside it), ``substeps`` how many
    such equilibria were solved, ``kind`` what it is (``"bifurcation"``, or ``"max"`` /
    ``"min"`` where the equilibria inside the step rise above / fall below both of its states).
    """

    fraction: float
    load_factor: float
    probes: dict[str, float]
    between: tuple[float, float]
    substeps: int = 0
    # "max" / "min" where the located point's load lies beyond both of the step's states: the
    # count changed at a load extremum inside the step that the states did not sample
    kind: str = "bifurcation"


def crossed_eigenvalue(fac: object, sign: float, size: int, dot: Callable) -> float | None:
    """The eigenvalue of K nearest zero among those of ``sign`` (inverse iteration, as above)."""
    m = min(BLOCK, size)
    if m < 1:
        return None
    start = _start_block(size, m)

    def nearest_of_sign(mu: np.ndarray, V: np.ndarray) -> np.ndarray:
        ok = np.flatnonzero(np.sign(mu) == sign)
        return ok[np.argsort(np.abs(mu[ok]))[:1]] if ok.size else np.empty(0, dtype=int)

    found = nearest_eigenpairs(fac, start, dot, nearest_of_sign)
    return None if found is None else float(found[0][0])


def zero_fraction(lo: BracketEnd, hi: BracketEnd) -> float:
    """μ's zero interpolated linearly between the bracket's ends (a fraction of the step).

    Where both ends know μ with opposite signs; else the bracket's middle.
    """
    if lo.mu is not None and hi.mu is not None and lo.mu * hi.mu < 0:
        return lo.f + (hi.f - lo.f) * lo.mu / (lo.mu - hi.mu)
    return 0.5 * (lo.f + hi.f)


def next_fraction(lo: BracketEnd, hi: BracketEnd) -> float:
    """Where to solve next: :func:`zero_fraction`, kept off the ends.

    At least :data:`SAFEGUARD` of the bracket from either end.
    """
    w = hi.f - lo.f
    return min(max(zero_fraction(lo, hi), lo.f + SAFEGUARD * w), hi.f - SAFEGUARD * w)


def halved(end: BracketEnd) -> BracketEnd:
    """``end`` with its μ halved (Illinois: an end kept by two tries weighs half)."""
    return end if end.mu is None else dataclasses.replace(end, mu=0.5 * end.mu)


def crossing_in(lo: BracketEnd, hi: BracketEnd, substeps: int) -> Crossing:
    """The located point of the bracket lo–hi.

    At :func:`zero_fraction`, its load factor and probes interpolated linearly between the ends.
    """
    f = zero_fraction(lo, hi)
    s = 0.0 if hi.f == lo.f else (f - lo.f) / (hi.f - lo.f)
    return Crossing(f, lo.load_factor + s * (hi.load_factor - lo.load_factor),
                    {n: v + s * (hi.probes[n] - v) for n, v in lo.probes.items()
                     if n in hi.probes},
                    (lo.load_factor, hi.load_factor), substeps)
