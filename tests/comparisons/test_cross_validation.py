"""Cross-validation: the beam model against the 2D reference on three scenes (CI).

Runs both real models at moderate resolution: beam 60 elements, 2D level "coarse". Paths are cut
short of the paper's end points (to keep the suite quick) but past the linear range.

Tolerances, and why:

- load-deflection curve, relative L2 over the common range ≤ 3 %, max ≤ 5 %: the paper shows the
  beam element's curves on top of the 2D ones ("a few percent" in the issue); the coarse 2D mesh
  itself is within about 1 % of its refined solution on these global quantities.
- peak |σzz| at the interfaces and peak |τ| in the core ≤ 25 % (bonded scene) and ≤ 40 % (scenes
  with a debond tip): looser because at a debond tip the 2D stress is singular (its peak grows
  as the mesh is refined) while the beam's is finite, and because both peaks are sampled at
  different stations; the sign and the location (within 10 mm) must agree.
"""

import dataclasses
from pathlib import Path

import pytest

from comparisons import compare
from comparisons.runs import import_solver
from sandwich.scene import load_scene

pytestmark = pytest.mark.dolfinx

ROOT = Path(__file__).resolve().parents[2]
BEAM_ELEMENTS = 60
REF_LEVEL = "coarse"
LOAD_L2, LOAD_MAX = 0.03, 0.05
PEAK_LOCATION = 10.0  # mm

CASES = [  # scene, path end (until probe value, mm), peak tolerance
    ("paper-fig4-bonded-3pb", -5.0, 0.25),
    ("paper-fig5-top-debond-40-load-top", -5.0, 0.40),
    ("paper-fig7-cantilever-c2", -15.0, 0.40),
]


def _solvers():
    missing = []
    found = {}
    for model in ("beam", "2d"):
        try:
            found[model] = import_solver(model)
        except ImportError as exc:
            missing.append(str(exc))
    if missing:
        pytest.skip("cross-validation needs both models: " + "; ".join(missing))
    return found


def _moderate(scene, until_value):
    analysis = dataclasses.replace(scene.analysis, until_value=until_value)
    beam = dataclasses.replace(scene.beam_model, elements=BEAM_ELEMENTS)
    ref = dataclasses.replace(scene.reference2d, level=REF_LEVEL, refine=0)
    return dataclasses.replace(scene, analysis=analysis, beam_model=beam, reference2d=ref)


@pytest.mark.parametrize(("name", "until", "peak_tol"), CASES)
def test_beam_agrees_with_2d(tmp_path, name, until, peak_tol):
    solvers = _solvers()
    scene = _moderate(load_scene(ROOT / "scenes" / f"{name}.toml"), until)
    cmp = compare(scene, tmp_path / "out", results_root=tmp_path / "res", reuse=False,
                  solvers=solvers)
    assert not cmp.missing, cmp.missing
    m = cmp.metrics
    load = m.curve("load_factor")
    assert load is not None and load.l2_relative is not None, m.notes
    assert load.l2_relative <= LOAD_L2, load
    assert load.max_relative <= LOAD_MAX, load
    peaks = {p.column: p for p in m.peaks}
    assert set(peaks) == {"sigma_zz_top", "sigma_zz_bottom", "tau_core"}
    for p in peaks.values():
        assert p.same_sign, p
        assert p.shift <= PEAK_LOCATION, p
        assert abs(p.relative_error) <= peak_tol, p
