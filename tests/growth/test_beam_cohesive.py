"""Growth by the beam's cohesive law, against the closed form and the tied interface.

The face cantilever of ``benchmarks.cases.growth_cases`` (an end force on the top face at an
open mouth, debond [0, 40], the faces clamped at x = 200), driven by the end deflection δ:
while the debond grows at G = G_c, beam theory with a root rotation gives the load
P = √(4 b² t^{3/2} (E G_c / 6)^{3/2} / (E δ)) whatever the root rotation
(:func:`~benchmarks.cases.growth_cases.propagation_load`). A cohesive zone reproduces it once
its process zone is small against the debond; undamaged, the cohesive pairs are the tie as
their stiffness grows (the same mesh, the tied model as reference).
"""

import dataclasses

import numpy as np
import pytest

from benchmarks.cases.growth_cases import cohesive_cantilever, propagation_load
from sandwich.beam.solve import run
from sandwich.scene import Growth, Toughness


@pytest.fixture(scope="module")
def grown():
    return run(cohesive_cantilever()).solution


def test_propagation_follows_the_closed_form(grown):
    assert grown.converged, grown.message
    # from 15 mm past the initial tip (where the process zone has formed: up to 3.2 % above
    # the closed form before) to one process zone before the span's end
    rows = [r for r in grown.history if 55.0 <= r.extra["tip_0_end"] <= 105.0]
    assert len(rows) >= 10  # the tip crosses the range in many steps
    ratio = np.array([r.load_factor / propagation_load(r.probes["w0"]) for r in rows])
    assert np.all(np.abs(ratio - 1.0) < 0.03), ratio
    # the process zone's share shrinks as the debond grows: the ratio falls towards 1
    assert ratio[-1] < ratio[0]


def test_tip_moves_forward_only_and_the_summary_says_where_it_went(grown):
    tips = np.array([r.extra["tip_0_end"] for r in grown.history])
    assert np.all(np.diff(tips) >= 0.0)
    summary = grown.extra["debond_growth"]
    assert summary["method"] == "cohesive law"
    tip = summary["tips"]["0_end"]
    assert tip["from"] == 40.0 and tip["to"] == pytest.approx(tips[-1])
    assert summary["residual_strength"] >= summary["first_growth_load"] > 0.0
    # the process zone reached the span's end (x = 120): the run says growth stops there
    assert any("end of its cohesive span" in w for w in grown.warnings)
    assert "G_0_end" not in grown.history[-1].extra  # no crack closure on a cohesive tip


def test_undamaged_cohesive_pairs_are_the_tie_as_their_stiffness_grows():
    sc = cohesive_cantilever(until=0.05)
    tied = dataclasses.replace(sc.debonds[0], toughness=None, growth=None)
    changes = []
    for stiffness in (None, 2.2e7):  # the default, 1000 × it
        strong = dataclasses.replace(sc.debonds[0], toughness=Toughness(1e3, 1e3),
                                     growth=Growth(method="cohesive", sigma_c=1e3, tau_c=1e3,
                                                   zone=80.0, stiffness=stiffness))
        a = run(dataclasses.replace(sc, debonds=(strong,)))
        b = run(dataclasses.replace(sc, debonds=(tied,)), model_options={"mesh": a.model.mesh})
        assert a.solution.extra["debond_growth"]["first_growth_load"] is None
        changes.append(a.solution.history[-1].load_factor / b.solution.history[-1].load_factor
                       - 1.0)
    assert -0.005 < changes[0] < 0.0  # the law's compliance 1/K
    assert abs(changes[1]) < 1e-4


def test_cohesive_path_follows_the_crack_length_envelope(grown):
    """At each crack-length onset's deflection the cohesive path carries the onset load.

    The beam's own envelope, G from the crack closure at fixed lengths: the established check
    of propagation codes against the static G.
    """
    from benchmarks.cases.growth_cases import cantilever
    from sandwich.beam import solve
    from sandwich.growth import grow, onset_rows

    onsets = onset_rows(grow(cantilever(step=10.0, max_length=100.0), solve).history)[1:]
    tip = np.array([r.extra["tip_0_end"] for r in grown.history])
    moving = tip > tip[0]
    d = np.array([abs(r.probes["w0"]) for r in grown.history])[moving]
    lam = np.array([r.load_factor for r in grown.history])[moving]
    ratio = [np.interp(abs(o.probes["w0"]), d, lam) / o.load_factor for o in onsets
             if d[0] <= abs(o.probes["w0"]) <= d[-1]]
    assert len(ratio) >= 4
    assert np.allclose(ratio, 1.0, atol=0.03), ratio


@pytest.mark.heavy
def test_fig5_grows_both_tips_through_its_snap_back():
    """fig. 5 given a weak mixed-mode interface: both tips grow past the maximum.

    growth_cohesive's case (≈ 3 min): the unsymmetric tangent's solve and the path follower
    take the path through the snap-back.
    """
    from benchmarks.cases.growth_cases import shipped

    sc = shipped("paper-fig5-top-debond-40-load-top", (0.004, 0.008))
    d = dataclasses.replace(sc.debonds[0], growth=Growth(method="cohesive", sigma_c=0.15,
                                                         zone=30.0))
    sol = run(dataclasses.replace(sc, debonds=(d,))).solution
    assert sol.converged, sol.message
    growth = sol.extra["debond_growth"]
    assert growth["bounded"] and growth["first_growth_load"] < growth["residual_strength"]
    for tip in growth["tips"].values():
        assert tip["grew_mm"] > 20.0
    # a finite strength softens the interface before G reaches G_c at a sharp tip: below
    # crack-length control's 447.4 N (growth_envelopes.md), and not far below
    assert 0.8 * 447.4 < growth["residual_strength"] < 447.4
