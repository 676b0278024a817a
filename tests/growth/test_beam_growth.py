"""Growth by crack-length control in the beam model, against closed forms.

The face cantilever of ``benchmarks.cases.growth_cases`` (an end force on the top face at an
open mouth, the tip at a, linear analysis): beam theory with a root rotation gives
G = 6 P² (a + χ t)² / (b² E t³) with χ independent of a, so the onset load of each length is
λ_c = √(G_c b² E t³ / 6) / (a + χ t): 1/λ_c is linear in a with the closed-form slope
√(6 / (G_c b² E t³)), whatever χ. Independently of any closed form, linear fracture mechanics
ties the envelope to the model's own compliance C(a) = w/λ at the load: G = λ² / (2 b) dC/da,
which the central differences of the envelope give at the mid lengths (the compliance method,
an energy estimate independent of the virtual crack closure that drives the growth).
"""

import numpy as np
import pytest

from benchmarks.cases.fracture_cases import WIDTH
from benchmarks.cases.growth_cases import GC, cantilever, onset_slope
from sandwich.beam import solve
from sandwich.growth import grow, onset_rows


@pytest.fixture(scope="module")
def envelope():
    sol = grow(cantilever(step=10.0, max_length=80.0), solve)
    assert sol.converged, sol.message
    return onset_rows(sol.history)


def test_onsets_follow_the_closed_form_slope_of_one_over_the_load(envelope):
    a = np.array([r.extra["tip_0_end"] for r in envelope])
    assert list(a) == [40.0, 50.0, 60.0, 70.0, 80.0]
    inv = 1.0 / np.array([r.load_factor for r in envelope])
    slope = np.polyfit(a, inv, 1)[0]
    exact = onset_slope()
    assert slope == pytest.approx(exact, rel=0.02)
    # with the closed-form slope and the one root-rotation length χ t that fits best, every
    # onset load is within the 1 % of the beam's G (docs/fracture.md) of the closed form
    root = np.mean(inv / exact - a)  # χ t (mm)
    assert root > 0.0
    assert 1.0 / (exact * (a + root)) == pytest.approx(1.0 / inv, rel=0.01)


def test_compliance_method_gives_the_toughness_along_the_envelope(envelope):
    a = np.array([r.extra["tip_0_end"] for r in envelope])
    lam = np.array([r.load_factor for r in envelope])
    c = np.array([r.probes["w0"] for r in envelope]) / lam  # mm/N at the load point
    dcda = (c[2:] - c[:-2]) / (a[2:] - a[:-2])
    mid_lam = lam[1:-1]
    g = mid_lam**2 / (2.0 * WIDTH) * dcda
    assert g == pytest.approx(np.full_like(g, GC), rel=0.02)
