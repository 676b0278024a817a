"""The small-displacement (linear) step with unilateral contact on the debonds.

The tangent at u = 0 plus the penalty on the linearised gap g ≈ s_n (w_face − w_core) of the
pairs in contact; the set of pairs in contact (the active set) is iterated to a fixed point
(:func:`active_set_solution`). The linear analysis (:func:`sandwich.beam.solve.run`), the
``auto`` core levels (:mod:`sandwich.beam.core_choice`) and the studies' error indicator solve it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from sandwich.beam.contact_search import NORMAL_SIGN
from sandwich.beam.model import BeamModel

# Passes of the linear step's active-set iteration: at least this many, and at least
# ACTIVE_SET_PASSES_PER_PAIR per contact pair. Where the contact zone is narrower than the
# debond, each pass releases the zone's edge pair alone (it alone is in tension) and the edge
# walks one pair per pass: fig. 5's scene with a 65-80 mm top debond needs 52-58 passes over
# 140-152 pairs (the flat 50 stopped every `auto` run and linear analysis of it).
MAX_ACTIVE_SET_PASSES = 50
ACTIVE_SET_PASSES_PER_PAIR = 2


class ActiveSetSolution(NamedTuple):
    """A linear step's solution: free DOFs, the active-set passes and the settled set."""

    u: np.ndarray
    passes: int
    active: list[np.ndarray]  # per contact group: pairs in contact


class TargetSolution(NamedTuple):
    """The linear step at λ = ``sign``, the sign that moves a probe towards its target."""

    sign: float
    u: np.ndarray
    passes: int
    active: list[np.ndarray]


def linear_contact_matrix(model: BeamModel, active: list[np.ndarray]) -> sp.csr_matrix:
    """Penalty stiffness of the linearised gap g ≈ s_n (w_face − w_core) on active pairs."""
    n = model.dof_map.n_full
    K = sp.csr_matrix((n, n))
    for pairs, on in zip(model.pairs, active, strict=True):
        s_n = NORMAL_SIGN[pairs.interface]
        grad = np.array([0.0, s_n, 0.0, -s_n, 0.0, 0.0])  # ∂g_lin/∂(pair DOFs)
        blocks = (model.penalty * pairs.area * on)[:, None, None] * np.outer(grad, grad)
        six = pairs.dofs[:, :6]  # (a cohesive pair's seventh, the face slope, not involved)
        rows = np.repeat(six[:, :, None], 6, axis=2)
        cols = np.repeat(six[:, None, :], 6, axis=1)
        K = K + sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n))
    T = model.dof_map.T
    return (T.T @ K @ T).tocsr()


def pattern_keys(model: BeamModel, K: sp.csr_matrix) -> np.ndarray | None:
    """Row · n + column of each entry of ``K`` (increasing), if ``K`` is on the model's pattern.

    :meth:`~sandwich.beam.model.BeamModel.tangent` returns its matrices on that pattern, explicit
    zeros included. None for any other pattern.
    """
    p = model.pattern
    if (K.shape != (p.n, p.n) or K.indices.size != p.indices.size
            or not np.array_equal(K.indptr, p.indptr) or not np.array_equal(K.indices, p.indices)):
        return None
    rows = np.repeat(np.arange(p.n, dtype=np.int64), np.diff(p.indptr))
    return rows * p.n + p.indices


def plus_on_pattern(K0: sp.csr_matrix, C: sp.csr_matrix, keys: np.ndarray
                     ) -> sp.csr_matrix | None:
    """``K0 + C`` on ``K0``'s pattern (``keys``: :func:`pattern_keys`), or None.

    ``C`` (the linearised contact's few entries) is added at its slots of a copy of ``K0``'s
    values: each entry is K0_ij + C_ij, what scipy's sum gives, without the sum's new pattern
    (it drops ``K0``'s explicit zeros) and its embedding back into the model's
    (:meth:`~sandwich.beam.model.BeamModel.factorize`): 4 ms of a 10 ms pass at level 3. None
    where an entry of ``C`` lies outside the pattern.
    """
    C = sp.csr_matrix(C)
    C.sum_duplicates()
    n = K0.shape[0]
    wanted = np.repeat(np.arange(n, dtype=np.int64), np.diff(C.indptr)) * n + C.indices
    slots = np.searchsorted(keys, wanted)
    if np.any(slots >= keys.size) or not np.array_equal(keys[slots], wanted):
        return None
    data = K0.data.copy()
    data[slots] += C.data  # (canonical C: each slot once)
    return sp.csr_matrix((data, K0.indices, K0.indptr), shape=K0.shape)


def linear_solution(model: BeamModel, load_factor: float) -> tuple[np.ndarray, int]:
    """Small-displacement solution at ``load_factor`` with unilateral contact on debonds.

    The tangent at u = 0 plus the penalty on the linearised gap of the pairs in contact; the
    active set is iterated to a fixed point. Returns the free DOFs and the number of passes.
    """
    u, passes, _ = active_set_solution(model, load_factor)
    return u, passes


def active_set_solution(
    model: BeamModel, load_factor: float, start: list[np.ndarray] | None = None
) -> ActiveSetSolution:
    """:func:`linear_solution` from the active set ``start`` (default: every pair open).

    Also returns the active set it settled on. The start changes the passes, not the answer:
    a fixed point is a stationary point of ½uᵀK₀u − fᵀu + ½ε Σ A ⟨−g_lin⟩², strictly convex
    for a positive definite K₀, so there is one (pairs with a gap exactly zero aside). The auto
    core levels solve the same scene at several levels with the same pairs, and each solve
    starts from the last one's set.
    """
    K0 = model.tangent(np.zeros(model.size))
    keys = pattern_keys(model, K0)
    f = load_factor * model.f_ref
    active = [np.zeros(p.size, dtype=bool) for p in model.pairs]
    if start is not None and [a.shape for a in start] == [a.shape for a in active]:
        active = [np.array(a, dtype=bool) for a in start]
    most = max(MAX_ACTIVE_SET_PASSES, ACTIVE_SET_PASSES_PER_PAIR * sum(p.size for p in model.pairs))
    for passes in range(1, most + 1):
        C = linear_contact_matrix(model, active)
        K = plus_on_pattern(K0, C, keys) if keys is not None else None
        fac = model.factorize(K0 + C if K is None else K)
        u = np.asarray(fac.solve(f), dtype=float)
        u_full = model.expand(u)
        new = []
        for pairs in model.pairs:
            v = u_full[pairs.dofs]
            new.append(NORMAL_SIGN[pairs.interface] * (v[:, 1] - v[:, 3]) < 0.0)
        if all(np.array_equal(a, b) for a, b in zip(active, new, strict=True)):
            return ActiveSetSolution(u, passes, active)
        active = new
    raise RuntimeError(f"linear contact active set did not settle in {most} passes")


def toward_target(
    model: BeamModel, probe: str, target: float, start: list[np.ndarray] | None = None
) -> TargetSolution:
    """The sign of λ whose linear solution moves ``probe`` towards ``target``.

    Unilateral contact makes the response homogeneous for λ > 0 only, so both signs are solved
    if need be, each from the active set ``start`` (:func:`active_set_solution`).
    """
    row = model.probe_vector(probe)
    for sign in (1.0, -1.0):
        u1, passes, active = active_set_solution(model, sign, start)
        if float(row @ u1) * target > 0:
            return TargetSolution(sign, u1, passes, active)
    raise ValueError(f"probe {probe!r} does not move under the scene's loads")
