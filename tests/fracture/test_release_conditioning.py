"""G close below a critical load is flagged as ill-conditioned, with how steep it grows.

Reference by construction: a history whose G follows G = c λ^s exactly (s = 2 far from the
critical load, s = 8 close to it), so the steepest exponent between two flagged states is 8;
ordinary growth (s = 2) close to a critical load is not flagged.
"""

import pytest

from sandwich.fracture import ill_conditioned_releases
from sandwich.results import LimitPoint, StepRecord


def _history():
    loads = [100.0, 200.0, 300.0, 400.0, 500.0, 560.0, 590.0, 605.0]
    out = [StepRecord(0, 0.0, {"w": 0.0}, 0, {"G_0_end": 0.0})]
    for k, lam in enumerate(loads, start=1):
        g = 1e-6 * lam**2 if lam <= 500 else 1e-6 * 500.0**2 * (lam / 500.0) ** 8
        out.append(StepRecord(k, lam, {"w": -lam / 100}, 3, {"G_0_end": g}))
    return out


def test_states_within_ten_percent_below_the_bifurcation_are_named_with_the_exponent():
    crit = [LimitPoint("bifurcation", 9, 610.0, {"w": -6.1})]  # in the step after state 8
    said = ill_conditioned_releases(_history(), crit)
    assert "step(s) 6, 7, 8" in said  # λ 560, 590, 605 ≥ 0.9 × 610 = 549
    assert "bifurcation at λ 610" in said
    assert "λ^8 " in said


def test_no_critical_point_or_no_g_is_no_warning():
    assert ill_conditioned_releases(_history(), []) == ""
    no_g = [StepRecord(r.step, r.load_factor, r.probes, 3, {}) for r in _history()]
    assert ill_conditioned_releases(no_g, [LimitPoint("max", 8, 610.0, {})]) == ""


@pytest.mark.parametrize("kind", ["bifurcation", "max"])
def test_states_after_the_critical_point_are_not_flagged(kind):
    # in the step that ends at state 6 (λ 500 → 560): of the states before it only step 5
    # (λ 500 ≥ 0.9 × 520) is near, and G grows there as λ² (not steep): no warning; the states
    # past the critical load (560, 590, 605), where G grows as λ^8, are not looked at
    crit = [LimitPoint(kind, 6, 520.0, {})]
    assert ill_conditioned_releases(_history(), crit) == ""


def test_ordinary_growth_close_to_a_critical_load_is_not_flagged():
    history = [StepRecord(k, 100.0 * k, {"w": -k}, 3, {"G_0_end": 1e-6 * (100.0 * k) ** 2})
               for k in range(1, 7)]
    assert ill_conditioned_releases(history, [LimitPoint("max", 7, 610.0, {})]) == ""
