"""Cross-validation: the beam model against the 2D reference on three scenes (CI).

Runs both real models: the beam at its scene default (240 graded elements, core levels "auto"
at tolerance 1 %, docs/beam_element.md "Core levels") and the 2D reference at level "coarse"
(within 1 % of level "medium" on these quantities, see docs/reference2d.md). Reference: the 2D
model.

Tolerances, and why (3 %, 5 % and 25 % were written before either model existed, from the
issue's "a few percent" and "looser, stated"; none was loosened). With the core hierarchy they
were tightened to the measured agreement (2026-12-01, auto against 2D coarse: load L2 0.57 %,
0.78 %, 0.57 % and max 0.67 %, 0.83 %, 0.62 % on fig4, fig5, c2; window-averaged stress
extremes within 16 % of the 2D's largest magnitude):

- load-deflection curve, relative L2 over the common range ≤ 1 %, max ≤ 1.5 % (was 3 %, 5 %
  with the paper's element alone, which was 2.1 %, 2.5 % and 0.6 % off in L2).
- interface σzz (top, bottom) and core τ: the profiles are averaged over a 5 mm window first,
  because at crack tips and where a clamped or pinned face sits on the free core the 2D stress is
  singular (its raw peak grows under refinement, see tests/compare/test_cmp_window.py), while
  the window average converges. The smallest and largest averaged values of each model must lie
  within 20 % of the 2D's largest magnitude (was 25 %).

What changed after the first runs, and is said here: the fig5 case first ran to w = −5 mm and
failed; it runs to −2 mm (before the debonded face buckles), and the −5 mm run, a strict xfail
while the paper's element alone stayed about 7 % stiffer there (docs/comparisons.md), is a test
again since the core hierarchy closed the gap to 1-1.5 %. Stress peaks were
first compared raw, which is meaningless at the singular points named above.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sandwich.compare import compare
from sandwich.models import MODELS
from sandwich.results.peaks import window_average
from sandwich.scene_file import load_scene

pytestmark = pytest.mark.dolfinx

ROOT = Path(__file__).resolve().parents[2]
REF_LEVEL = "coarse"
LOAD_L2, LOAD_MAX = 0.01, 0.015
STRESS_TOL = 0.20
WINDOW = 5.0  # mm
STRESSES = ("sigma_zz_top", "sigma_zz_bottom", "tau_core")

CASES = [  # scene, path end (until probe value, mm): before the debonded face buckles
    ("paper-fig4-bonded-3pb", -5.0),
    ("paper-fig5-top-debond-40-load-top", -2.0),
    ("paper-fig7-cantilever-c2", -15.0),
]


def _solvers():
    try:
        import sandwich.beam  # noqa: F401
        import sandwich.plane2d  # noqa: F401
    except ImportError as exc:
        pytest.skip(f"cross-validation needs both models: {exc}")
    return {m: MODELS[m].solve for m in ("beam", "2d")}


def _compare(tmp_path, name, until, level=REF_LEVEL, **analysis):
    scene = load_scene(ROOT / "scenes" / f"{name}.toml")
    scene = dataclasses.replace(
        scene, analysis=dataclasses.replace(scene.analysis, until_value=until, **analysis),
        reference2d=dataclasses.replace(scene.reference2d, level=level, refine=0))
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", reuse=False,
                  solvers=_solvers())
    assert not cmp.missing, cmp.missing
    return cmp


def _load_curve_agrees(cmp):
    load = cmp.metrics.curve("load_factor")
    assert load is not None and load.l2_relative is not None, cmp.metrics.notes
    assert load.l2_relative <= LOAD_L2, load
    assert load.max_relative <= LOAD_MAX, load


@pytest.mark.parametrize(("name", "until"), CASES)
def test_beam_agrees_with_2d(tmp_path, name, until):
    cmp = _compare(tmp_path, name, until)
    _load_curve_agrees(cmp)
    beam, ref = (cmp.chosen_profiles[m].profile for m in ("beam", "2d"))
    for col in STRESSES:
        _, b = window_average(beam.columns["x"], beam.columns[col], WINDOW)
        _, r = window_average(ref.columns["x"], ref.columns[col], WINDOW)
        scale = np.abs(r).max()
        assert abs(b.min() - r.min()) <= STRESS_TOL * scale, (col, b.min(), r.min(), scale)
        assert abs(b.max() - r.max()) <= STRESS_TOL * scale, (col, b.max(), r.max(), scale)


def test_fig5_beyond_face_buckling(tmp_path):
    """Past the debonded face's buckling (w = −5 mm): the paper's element alone was ~7 % too
    stiff here (a strict xfail until the core hierarchy), auto core levels with the paper's faces
    1.0 % (L2) / 1.5 % (max) against 2D coarse; with the stretch faces, averaged membrane and
    closest-point contact (the defaults since 2026-12-02) 0.21 % / 0.39 %, so it is held to the
    same 1 % / 1.5 % as the paths before buckling (was 3 % / 5 %).

    Both models run under displacement control in 0.25-mm steps, so that both histories sample
    the buckling knee at the same deflections: under arc-length each model's own steps cut the
    knee's corner differently, and the piecewise-linear curves then differ by the sampling
    (1.96 % max, measured 2026-12-07, where 2D coarse stepped from −2.52 to −3.26 mm across the
    knee while the beam's states at −3.0 mm agree with it within 0.6 %)."""
    cmp = _compare(tmp_path, "paper-fig5-top-debond-40-load-top", -5.0,
                   control="displacement", initial_increment=0.25, max_increment=0.25)
    _load_curve_agrees(cmp)


def test_fig5_to_the_end_of_its_path(tmp_path):
    """The whole shipped fig5 path (to w = −15 mm, the debonded face buckled and pressed)
    against the 2D model at level medium (0.17 % from 2D fine at the end; coarse is 1.7 %, more
    than the beam's error here). With the paper's faces auto was 8.8 % too stiff at the end; with
    the defaults since 2026-12-02 the load curves agree within 0.30 % (L2), 0.49 % (max), measured
    (~1 min). Held to the 1 % / 1.5 % of the other paths."""
    cmp = _compare(tmp_path, "paper-fig5-top-debond-40-load-top", -15.0, level="medium")
    _load_curve_agrees(cmp)
