"""Frictionless unilateral contact on debonded stretches (eqs. 41-42), by a penalty.

Each contact pair's force f = −p A ∂g/∂u and consistent tangent K = −A p'(g) ∂g ∂gᵀ − p A ∂²g
(the second term is the rotation of the normal), from

* the pairs (:mod:`sandwich.beam.contact_search`): each untied face node against the core of
  the same x (``"same-x"``) or against its closest point (``"closest-point"``);
* the gap g and its derivatives (:mod:`sandwich.beam.contact_gap`, same-x;
  :mod:`sandwich.beam.contact_projection`, closest point);
* the law p(g) (:mod:`sandwich.beam.contact_law`): a penalty regularised by a shifted softplus.

A growing tip's cohesive pairs (:mod:`sandwich.beam.cohesive`) are same-x pairs whose response
adds the cohesive law to the contact's.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.cohesive import cohesive_response
from sandwich.beam.contact_gap import PairKinematics, same_x_kinematics
from sandwich.beam.contact_law import penalty_blocks
from sandwich.beam.contact_projection import chosen_segment_kinematics, pair_block_kinematics
from sandwich.beam.contact_search import ContactPairs, located


def pair_kinematics(pairs: ContactPairs, u_full: np.ndarray) -> PairKinematics:
    """Gap along the slave's deformed normal, eq. (42), with first and second derivatives."""
    if pairs.search == "closest-point":
        return pair_block_kinematics(pairs, u_full)
    return same_x_kinematics(pairs, u_full)


def gap_change(
    pairs: ContactPairs, u_full: np.ndarray, du_full: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's gap g at ``u_full`` and its linearised change ∂g/∂u · du along ``du_full``.

    Closest-point pairs on their chosen segments (the projection at ``u_full`` is the one the
    force evaluation there made, reused); same-x pairs on their six DOFs.
    """
    if pairs.search == "closest-point":
        c = chosen_segment_kinematics(pairs, u_full)
        return c.gap, np.einsum("ij,ij->i", c.grad, du_full[c.dofs])
    k = pair_kinematics(pairs, u_full)
    return k.gap, np.einsum("ij,ij->i", k.grad, du_full[pairs.block_dofs])


def penalty_response(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics]:
    """Contact forces (m, n), tangents (m, n, n), pressures (m,) MPa and the kinematics.

    On the pairs' blocks: same-x pairs' six DOFs, closest-point pairs' located windows
    (:func:`block_rows`). ``smoothing`` is the regularisation width s (mm) of
    :func:`~sandwich.beam.contact_law.pressure_law`.
    """
    if pairs.cohesive is not None:  # a growing tip's cohesive pairs
        return cohesive_response(pairs, u_full, penalty, smoothing)
    k = pair_kinematics(pairs, u_full)
    f, K, p = penalty_blocks(k.gap, k.grad, k.hess, pairs.area, penalty, smoothing)
    return f, K, p, k


def compact_response(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, PairKinematics, np.ndarray]:
    """Closest-point pairs: :func:`penalty_response` on each pair's chosen segment only.

    Returns forces (m, 10), tangents (m, 10, 10), pressures (m,), the kinematics (gap,
    sliding, ξ, segment, outside; gradient and Hessian on the 10 DOFs) and the 10 full DOFs.
    The same numbers as the blocks of :func:`penalty_response` at those DOFs (its other
    entries are zero), without forming the (m, n, n) blocks (a window holds up to 17
    segments).
    """
    if pairs.search != "closest-point":
        raise ValueError("compact_response is for closest-point pairs")
    c = chosen_segment_kinematics(pairs, u_full)
    f, K, p = penalty_blocks(c.gap, c.grad, c.hess, pairs.area, penalty, smoothing)
    k = PairKinematics(c.gap, c.grad, c.hess, c.sliding, c.xi, c.segment, c.outside)
    return f, K, p, k, c.dofs


def block_rows(pairs: ContactPairs, u_full: np.ndarray) -> np.ndarray:
    """Full DOFs (m, n) of the blocks :func:`penalty_response` returns at ``u_full``."""
    return located(pairs, u_full).block_dofs


def contact_state(
    pairs: ContactPairs, u_full: np.ndarray, penalty: float, smoothing: float = 0.0
) -> tuple[np.ndarray, PairKinematics]:
    """Pressures (m,) MPa and kinematics of the pairs (gap, sliding, …), without the blocks.

    Closest-point pairs through :func:`compact_response` (no (m, n, n) block is formed).
    """
    if pairs.search == "closest-point":
        return compact_response(pairs, u_full, penalty, smoothing)[2:4]
    return penalty_response(pairs, u_full, penalty, smoothing)[2:4]
