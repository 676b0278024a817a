"""Every shipped scene (``scenes/*.toml``) runs with the 2D reference at level coarse.

Default suite: a copy of the scene with the path shortened to 1/5 of its ``until`` value is
written to ``tmp_path`` and solved; it must reach that target (reference: the scene file itself,
its until probe and value). The full shipped paths are heavy tests.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from sandwich.plane2d import solve
from sandwich.scene_file import load_scene

pytestmark = pytest.mark.dolfinx

SCENES = Path(__file__).resolve().parents[2] / "scenes"
NAMES = sorted(p.stem for p in SCENES.glob("*.toml"))
FIG4_CRUSH = pytest.mark.xfail(strict=True, reason=(
    "the Green-strain core (eq. 27) crushes under the patch: material limit point "
    "lambda=1930.67 at w=-12.99 mm, next steps invert core cells; -15 mm is out of reach "
    "(docs/reference2d.md)"))
# measured (docs/reference2d.md, "Heavy full paths"): the same St. Venant-Kirchhoff core limit as
# fig4, at a corner where a face end is held and the core bears on it
CORNER_CRUSH = {
    "paper-fig7-cantilever-c2": pytest.mark.xfail(strict=True, reason=(
        "core corner on the clamped bottom face (x=0.875, z=-12.33) crushes in step 11 "
        "(lambda 669.5, the maximum); the path loops through crushed states and returns onto "
        "its own branch at steps 20-22 (w_top_tip -33.3 mm), where it stops; -40 mm is out of "
        "reach (test_c2_full_path_stops_where_it_returns_onto_its_branch)")),
}
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
    # the core's crushing diagnostic on every state: at rest 1 (no strain), then a stretch ≤ 1
    # (some core point is compressed under any load) and an ellipticity ratio ≤ 1
    first = sol.history[0].extra
    assert first["core_min_stretch"] == pytest.approx(1.0) and first["core_ellipticity"] == \
        pytest.approx(1.0)
    for r in sol.history:
        assert 0.0 < r.extra["core_min_stretch"] <= 1.0 + 1e-12
        assert np.isfinite(r.extra["core_ellipticity"]) and r.extra["core_ellipticity"] <= 1.0


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
@pytest.mark.parametrize("name", [
    pytest.param(n, marks=FIG4_CRUSH) if n == "paper-fig4-bonded-3pb"
    else pytest.param(n, marks=CORNER_CRUSH[n]) if n in CORNER_CRUSH else n for n in NAMES
    if n != "paper-fig6-top-debond-20-load-bottom"])
def test_shipped_scene_coarse_full_path(name):
    scene = load_scene(SCENES / f"{name}.toml")
    sol = solve(scene, level="coarse")
    check_reached(sol, scene)


@pytest.mark.heavy
@pytest.mark.xfail(strict=True, reason=(
    "measured 2026-12-07 on the coarse mesh with elements of aspect <= 5 over the debond: the "
    "path crawls up to the snap maximum (lambda 1982.73 at w_bottom_mid = -9.577 mm, the "
    "maximum located before at 1983.07) and stops there; its probe rescues, also with the "
    "largest probe step of the path (1.74 mm), do not converge past it: the lip nodes next to "
    "both crack tips release at the maximum and Newton cycles between the two contact sets; "
    "whether a rescue lands on the snapped branch is chance (at k 22000 instead of 21000 it "
    "does, 2151.29 at -15 mm; on the coarser debond mesh, aspect 20, a rescue passed it too; "
    "docs/contact.md, 'Past a snap')"))
def test_fig6_full_path_passes_the_face_snap_maximum_without_crushing_the_core():
    """fig6: a load maximum λ ≈ 1983 at w_bottom_mid ≈ −9.6 mm, passed by the path follower's
    probe rescue (docs/solver.md) to −15 mm. It was read as the core's corner above the pin
    crushing (a principal stretch 0.593 at the corner node, near the St Venant-Kirchhoff
    1/√3); the crushing diagnostic says the core keeps its ellipticity at every Gauss point up
    to there, and the beam, whose core cannot crush locally, snaps at the same load: the
    debonded face's snap. Reference: the beam model on the same scene (its located maximum)."""
    from sandwich.beam import solve as solve_beam

    scene = load_scene(SCENES / "paper-fig6-top-debond-20-load-bottom.toml")
    sol = solve(scene, level="coarse")
    check_reached(sol, scene)
    maxima = [lp.load_factor for lp in sol.limit_points if lp.kind == "max"]
    # the reported maximum is located inside its step (measured before: 1983.07 at the state
    # bracketed by refined steps, 1980.05 the step's state)
    assert maxima and maxima[0] == pytest.approx(1983.07, rel=5e-3), sol.limit_points
    crushed = sol.extra["core_crushed_at_step"]
    at_max = next(r.step for r in sol.history if r.load_factor == max(
        h.load_factor for h in sol.history))
    assert crushed is None or crushed > at_max, (crushed, at_max)
    beam = solve_beam(scene)
    beam_max = [lp.load_factor for lp in beam.limit_points if lp.kind == "max"]
    print(f"2D max {maxima[0]:.6g}, beam max {beam_max[:1]}, core crushed at step {crushed}")
    assert beam_max and maxima[0] == pytest.approx(beam_max[0], rel=1e-2)


@pytest.mark.heavy
def test_c2_full_path_stops_past_its_crush_without_running_back():
    """fig. 7 c2: past its crush the 2D path once looped and came back onto its own loading
    branch, then ran it backwards through λ = 0 to λ = −117 (175 steps) until an element
    inverted. Now it stops past the crush: on the mesh refined over the debonds (elements of
    aspect ≤ 5) where its cells invert (det F ≤ 0, step 31 at λ 619, w_top_tip −31.7 mm;
    measured 2026-12-07), and the path follower's return guard (docs/solver.md,
    tests/solver/test_solver_return_guard.py) stops a path that returns onto a passed step. No
    state after the turn with λ < 0 or with the tip deflection undone, and the crush reported."""
    scene = load_scene(SCENES / "paper-fig7-cantilever-c2.toml")
    sol = solve(scene, level="coarse")
    assert not sol.converged and "admissible domain" in sol.message
    lam = np.array([r.load_factor for r in sol.history])
    w = np.array([r.probes[scene.analysis.until_probe] for r in sol.history])
    assert lam.min() >= 0.0 and len(sol.history) < 40
    top = int(np.argmax(lam))
    assert np.all(w[top:] <= 0.95 * w[top])  # beyond its maximum the tip has not gone back
    assert sol.extra["core_crushed_at_step"] is not None
    assert sol.extra["core_crushed_at_step"] <= sol.history[top].step + 1


def test_solution_carries_a_paraview_frame_of_the_last_step(tmp_path):
    """FieldFrame of the last state: 4 CCW sub-quads per 9-node cell, displacement equal to the
    probe (reference: the history row), regions, Cauchy stresses; written as VTU + PVD."""
    from sandwich.results import write_solution

    scene = load_scene(shortened_copy("paper-fig4-bonded-3pb", tmp_path, 0.1))
    sol = solve(scene, level="coarse")
    assert sol.converged and len(sol.fields) == 1
    fr = sol.fields[0]
    assert fr.step == sol.history[-1].step and fr.load_factor == sol.history[-1].load_factor
    assert len(fr.cells) == 4 * sol.extra["cells"]
    p = fr.points[fr.cells]  # (m, 4, 2): shoelace area > 0 for every sub-quad
    area = 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, 1)
                        - np.roll(p[:, :, 0], -1, 1) * p[:, :, 1], axis=1)
    assert np.all(area > 0)
    assert area.sum() == pytest.approx(scene.length * (scene.top.thickness + scene.core.thickness
                                                       + scene.bottom.thickness), rel=1e-9)
    z_mid = 0.5 * (scene.core.thickness + scene.top.thickness)  # the probe: top face mid-surface
    i = np.argmin(np.hypot(fr.points[:, 0] - 150.0, fr.points[:, 1] - z_mid))
    assert fr.points[i] == pytest.approx([150.0, z_mid])
    assert fr.displacement[i, 1] == pytest.approx(sol.history[-1].probes["w_top_mid"], rel=1e-9)
    assert set(np.unique(fr.cell_data["region"])) == {0, 1, 2}
    for k in ("sigma_x", "sigma_z", "tau", "von_mises"):
        assert np.all(np.isfinite(fr.cell_data[k]))
    assert np.all(fr.cell_data["von_mises"] >= 0)
    # faces (region 1, 2) carry the bending: |σx| there far above the core's
    faces = np.abs(fr.cell_data["sigma_x"][fr.cell_data["region"] > 0]).max()
    core = np.abs(fr.cell_data["sigma_x"][fr.cell_data["region"] == 0]).max()
    assert faces > 10 * core
    files = write_solution(sol, tmp_path / "out")
    names = {Path(f).name for f in files}
    assert "fields.pvd" in names and any(n.endswith(".vtu") for n in names)
    assert all(isinstance(v, (int, float, str, bool)) or v is None
               for k, v in sol.extra.items() if k != "mesh_error")
    # level coarse has no coarser level: the estimate says so instead of a number
    assert sol.extra["mesh_error"]["estimated_error"] is None
    assert "no coarser level" in sol.extra["mesh_error"]["not_measured"]
