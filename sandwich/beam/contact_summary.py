"""What a state's contact amounts to: per interface penetration, pressure, sliding, pairs closed.

:func:`summarise_contact` gives a state's :class:`ContactSummary` per interface, and
:func:`contact_columns` the history's contact columns of it; :func:`contact_correction_limit`
bounds a Newton correction by the gaps of the pairs the tangent does not hold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sandwich.beam.contact import contact_state, gap_change
from sandwich.beam.contact_law import SHIFT, in_contact
from sandwich.beam.contact_search import ContactPairs


@dataclass
class ContactSummary:
    """Contact state of a converged step, per interface, over all pairs."""

    max_penetration: float = 0.0  # mm
    max_pressure: float = 0.0  # MPa
    max_sliding: float = 0.0  # mm, of pairs in contact: |t·Δ| (same-x), |x(ξ) − x_i| (closest)
    active: int = 0  # pairs in contact
    outside_reach: int = 0  # pairs in contact projecting beyond the searched segments


#: The history's contact columns (:func:`contact_columns`).
CONTACT_COLUMNS = ("max_penetration", "max_sliding", "contact_pairs_active")


def contact_columns(summary: dict[str, ContactSummary]) -> dict[str, float]:
    """History columns of a state's contact summary (0 without contact).

    Deepest penetration (mm), largest sliding of a pair in contact (mm) and the pairs in
    contact, over the interfaces.
    """
    return {
        "max_penetration": max((c.max_penetration for c in summary.values()), default=0.0),
        "max_sliding": max((c.max_sliding for c in summary.values()), default=0.0),
        "contact_pairs_active": float(sum(c.active for c in summary.values())),
    }


def summarise_contact(
    pairs: list[ContactPairs], u_full: np.ndarray, penalty: float, smoothing: float,
    known: list | None = None,
) -> dict[str, ContactSummary]:
    """Penetration, pressure and sliding per interface at the full DOF vector ``u_full``.

    ``known``: each group's (pressures, kinematics) at ``u_full`` where an evaluation there
    kept them, else they are evaluated (:func:`~sandwich.beam.contact.contact_state`).
    """
    out: dict[str, ContactSummary] = {}
    for i, group in enumerate(pairs):  # an interface may hold several groups
        if known is not None:
            p, k = known[i]
        else:
            p, k = contact_state(group, u_full, penalty, smoothing)
        active = in_contact(k.gap, smoothing)
        c = out.setdefault(group.interface, ContactSummary())
        c.max_penetration = max(c.max_penetration, float(np.max(-k.gap, initial=0.0)))
        c.max_pressure = max(c.max_pressure, float(np.max(p, initial=0.0)))
        c.max_sliding = max(c.max_sliding,
                            float(np.max(np.abs(k.sliding[active]), initial=0.0)))
        c.active += int(active.sum())
        if k.outside is not None:
            c.outside_reach += int(np.sum(k.outside & active))
    return out


def contact_correction_limit(
    pairs: list[ContactPairs], u_full: np.ndarray, du_full: np.ndarray, bound: float,
    smoothing: float,
) -> float:
    """Largest fraction α ≤ 1 of the correction ``du_full`` from ``u_full`` the contact allows.

    A pair that is open at ``u_full`` or in the law's tail (g > −c s: its stiffness below ε/2,
    :func:`~sandwich.beam.contact_law.pressure_law`) has no contact stiffness in the tangent the
    correction was solved with; α keeps every such pair's linearised gap g + α ∂g/∂u·du at or
    above −``bound``. Pairs already in the penalty's linear range are left to Newton.
    """
    tail = -SHIFT * smoothing
    alpha = 1.0
    for group in pairs:
        if group.size == 0 or group.cohesive is not None:  # cohesive pairs hold stiffness
            continue
        g, dg = gap_change(group, u_full, du_full)
        deep = (g > tail) & (g + dg < -bound)
        if np.any(deep):
            alpha = min(alpha, float(np.min((g[deep] + bound) / -dg[deep])))
    return alpha
