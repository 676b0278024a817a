"""Every shipped scene (``scenes/*.toml``) runs with the 2D reference at level coarse.

Default suite: a copy of the scene with the path shortened to 1/5 of its ``until`` value is
written to ``tmp_path`` and solved; it must reach that target (reference: the scene file itself,
its until probe and value). The full shipped paths are heavy tests.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from reference2d import solve
from sandwich.scene import load_scene

pytestmark = pytest.mark.dolfinx

SCENES = Path(__file__).resolve().parents[2] / "scenes"
NAMES = sorted(p.stem for p in SCENES.glob("*.toml"))
UNTIL = re.compile(r"(until\s*=\s*\{[^}]*value\s*=\s*)([-+0-9.eE]+)")
FRACTION = 0.2


def shortened_copy(name: str, tmp_path: Path, fraction: float = FRACTION) -> Path:
    """The scene file with its until value scaled by ``fraction``, written into tmp_path."""
    text = (SCENES / f"{name}.toml").read_text()
    new, n = UNTIL.subn(lambda m: f"{m.group(1)}{float(m.group(2)) * fraction!r}", text)
    assert n == 1, f"{name}: expected one `until = {{ probe, value }}` line"
    path = tmp_path / f"{name}.toml"
    path.write_text(new)
    return path


def check_reached(sol, scene):
    a = scene.analysis
    assert sol.converged, sol.message
    last = sol.history[-1]
    assert last.probes[a.until_probe] == pytest.approx(a.until_value, rel=1e-3)
    assert all(np.isfinite(r.load_factor) for r in sol.history)
    assert sol.extra["max_penetration_over_face_thickness"] <= 1e-3


@pytest.mark.timeout(400)
@pytest.mark.parametrize("name", NAMES)
def test_shipped_scene_coarse_short_path(name, tmp_path):
    scene = load_scene(shortened_copy(name, tmp_path))
    full = load_scene(SCENES / f"{name}.toml")
    assert scene.analysis.until_value == pytest.approx(FRACTION * full.analysis.until_value)
    sol = solve(scene, level="coarse")
    print(f"{name}: {len(sol.history) - 1} steps, {sol.extra['newton_iterations']} Newton its, "
          f"{sol.wall_seconds:.1f} s, λ = {sol.history[-1].load_factor:.6g}, "
          f"newton_tol {sol.extra['newton_tol']:.2g}")
    check_reached(sol, scene)


@pytest.mark.heavy
@pytest.mark.parametrize("name", NAMES)
def test_shipped_scene_coarse_full_path(name):
    scene = load_scene(SCENES / f"{name}.toml")
    sol = solve(scene, level="coarse")
    check_reached(sol, scene)
