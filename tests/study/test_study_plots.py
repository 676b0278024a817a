"""Study plots as figure objects: units on the axes, full titles, legends only for what is drawn,
map cells within the axis values; the summary's crossing table holds the quantity's value.

The tiny study (3 lengths 0, 30, 60 mm × 2 centres 130, 150 mm) with capacities set by hand.
"""

from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

from sandwich.studies.study_file import load_study
from sandwich.studies.study_report import crossings, figures, rows, summary

TINY = Path(__file__).resolve().parent / "tiny.toml"
CAPACITY = {0: 1000.0, 1: 1000.0, 2: 900.0, 3: 700.0, 4: 500.0, 5: 400.0}


def _table(checked=()):
    study = load_study(TINY)
    recs = {i: {"status": "done", "capacity": v, "first_limit_kind": "bifurcation"}
            for i, v in CAPACITY.items()}
    checks = {i: {"2d_capacity": 0.98 * CAPACITY[i], "error_capacity": 0.02} for i in checked}
    return study, rows(study, recs, checks)


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_map_axes_carry_units_and_cells_stay_within_the_axis_values():
    study, table = _table()
    (name, fig), = figures(study, table)
    ax = fig.axes[0]
    assert name == "tiny-map.png"
    assert ax.get_xlabel() == "length (mm)" and ax.get_ylabel() == "centre (mm)"
    assert ax.get_xlim() == (0.0, 60.0) and ax.get_ylim() == (130.0, 150.0)
    mesh = ax.collections[0]
    corners = mesh.get_coordinates()
    assert corners[..., 0].min() == 0.0 and corners[..., 0].max() == 60.0
    assert corners[..., 1].min() == 130.0 and corners[..., 1].max() == 150.0
    # no 2D check: no legend promising red circles, no title promising them
    assert ax.get_legend() is None
    assert "red" not in ax.get_title() and "2D" not in ax.get_title()


def test_a_checked_case_gets_its_legend_entry():
    study, table = _table(checked=(2,))
    (_, fig), = figures(study, table)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["checked with the 2D model (beam − 2D error of capacity)"]


def test_one_axis_curve_has_units_a_whole_title_and_only_drawn_legend_entries():
    study, table = _table()
    one = replace(study, axes=study.axes[:1])
    rows_one = [r for r in table if r["centre"] == 130]
    (name, fig), = figures(one, rows_one)
    ax = fig.axes[0]
    assert name == "tiny-curve.png"
    assert ax.get_xlabel() == "length (mm)"
    title = ax.get_title()
    assert title.startswith("tiny:") and "length" in title and "…" not in title
    fig.canvas.draw()  # the title fits inside the figure: nothing cut at either end
    box = ax.title.get_window_extent()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["threshold 0.8"]


def test_the_crossing_table_holds_the_load_and_the_kind_apart():
    study, table = _table()
    cross = {c["centre"]: c for c in crossings(study, table)}
    assert cross[130]["value"] == pytest.approx(500.0)  # the first case below 0.8 at 130: 60 mm
    md = summary(study, table, [], [], [])
    line = next(ln for ln in md.splitlines() if ln.startswith("| 130"))
    assert "| 500 | bifurcation |" in line
