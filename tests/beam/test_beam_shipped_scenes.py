"""Every shipped scene (scenes/*.toml) runs to its `until` with the beam model at a test resolution.

Core level 1 (the paper's element; the scenes' default "auto" is run by the heavy tests of
test_core_auto.py).
Resolution: 40 elements (7.5 mm; the scene default is finer). Coarse, so the loads are not
converged values, but the whole path is followed with the scene's own analysis settings (control,
tolerances, max_steps) and contact law: the checks are that the target is reached (the solver's
`reached_target`, i.e. the until probe or load factor hit within its target tolerance), that every
recorded number is finite, and that the contact penetration stays within 1e-3 × face thickness
(the issue's bound, reported by the model per converged step).
"""

from pathlib import Path

import numpy as np
import pytest

from sandwich.beam import run
from sandwich.scene_file import load_scene

SCENES = sorted((Path(__file__).resolve().parents[2] / "scenes").glob("*.toml"))
TEST_ELEMENTS = 40


def test_all_shipped_scenes_are_listed():
    assert len(SCENES) >= 14, [p.name for p in SCENES]


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_shipped_scene_reaches_its_until(path):
    scene = load_scene(path)
    result = run(scene, elements=TEST_ELEMENTS, model_options={"core_level": 1})
    sol = result.solution
    assert sol.converged, sol.message
    a = scene.analysis
    last = sol.history[-1]
    if a.until_probe is not None:
        assert last.probes[a.until_probe] == pytest.approx(a.until_value, rel=1e-5)
    else:
        assert last.load_factor == pytest.approx(a.until_load_factor, rel=1e-5)
    for step in sol.history:
        assert np.isfinite(step.load_factor)
        assert all(np.isfinite(v) for v in step.probes.values())
        assert all(np.isfinite(v) for v in step.extra.values())
    for profile in sol.profiles:
        for name, column in profile.columns.items():
            assert np.all(np.isfinite(column)), name
    assert sol.extra["max_penetration"] <= result.model.penetration_bound()
