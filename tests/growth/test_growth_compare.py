"""`compare` on a growing debond: both models' envelopes overlaid, and the growth table.

The face cantilever of test_beam_growth (closed-form checked in each model there): here the two
models' onset loads are compared with each other, within the 3 % the issue sets for the
propagation curves.
"""

import csv

import pytest

from benchmarks.cases.growth_cases import cantilever
from sandwich.compare import compare

pytestmark = pytest.mark.dolfinx


def test_compare_overlays_both_envelopes_and_tabulates_the_strengths(tmp_path):
    sc = cantilever(step=10.0, max_length=60.0)
    cmp = compare(sc, tmp_path)
    names = {p.name for p in cmp.figures}
    assert {"growth_0.png", "growth_tips_0.png"} <= names
    rows = {r["model"]: r for r in csv.DictReader((tmp_path / "growth.csv").open())}
    assert set(rows) == {"2d", "beam"}
    for key in ("first_growth_load", "residual_strength"):
        assert float(rows["beam"][f"{key}_over_2d"]) == pytest.approx(1.0, abs=0.03)
    envelope = list(csv.DictReader((tmp_path / "growth_0.csv").open()))
    assert envelope  # the overlay's own numbers are written beside it
