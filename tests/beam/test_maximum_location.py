"""The beam's load maximum is located within the step that passes it (sandwich.solver.extrema).

Reference: the same model (fig. 4, the bonded sandwich in three-point bending, core level 2 —
the core crushing under the pad) followed in displacement steps of at most 0.2 mm, its maximum
narrowed — a converged fine-step path, not the long step under test (measured with 0.05-mm
steps: 1927.0092, the same to 1e-9; benchmarks/results/beam/maximum_location.md). As the scene
has it the path passes the maximum inside its last step (1436.5 → 1882.6, to the target), and
its extreme state lies 2.3 % below the top.
"""

import dataclasses
import math
from pathlib import Path

import pytest

from sandwich.beam import run as solve_run
from sandwich.beam.core_controller import AutoSettings
from sandwich.scene_file import load_scene
from sandwich.studies.study_file import load_study

ROOT = Path(__file__).resolve().parents[2]


def _scene(narrowed: bool, fine: bool = False):
    scene = load_scene(ROOT / "scenes" / "paper-fig4-bonded-3pb.toml")
    a = dataclasses.replace(scene.analysis, locate_critical_points=narrowed)
    if fine:
        a = dataclasses.replace(a, control="displacement", max_increment=0.2,
                                initial_increment=0.2, max_steps=500)
    return dataclasses.replace(scene, analysis=a, beam_model=dataclasses.replace(
        scene.beam_model, core=2))


def _maximum(run):
    return next(p for p in run.solution.limit_points if p.kind == "max")


def test_a_maximum_inside_a_long_step_is_located_and_narrowed_to_the_fine_paths_value():
    fine = solve_run(_scene(True, fine=True))
    ref = _maximum(fine).load_factor
    # the fine path's own extreme state, read without any location: within its step of it
    top_fine = max(s.load_factor for s in fine.states)
    assert 0.0 <= ref - top_fine < 1e-4 * ref
    plain, narrowed = solve_run(_scene(False)), solve_run(_scene(True))
    # the same path: the equilibria solved inside the step are not path states
    assert [s.load_factor for s in plain.states] == [s.load_factor for s in narrowed.states]
    top = max(s.load_factor for s in plain.states)
    assert top < (1 - 0.01) * ref  # the extreme state: 2.3 % below (measured)
    p, n = _maximum(plain), _maximum(narrowed)
    assert p.located_at is not None and 0.0 < p.located_at < 1.0
    low, high = p.between  # the step's two states, both below the top
    assert max(low, high) < p.load_factor
    assert abs(p.load_factor - ref) < 0.01 * ref  # located from the slopes: +0.30 % (measured)
    assert abs(p.load_factor - ref) < 0.25 * (ref - top)
    assert abs(n.load_factor - ref) < 1e-4 * ref  # narrowed: 2e-10 (measured)


def test_the_top_a_probe_rescue_jumps_over_is_bounded_by_walking_its_branch():
    # fig. 6 with auto's reruns (AutoSettings(one_pass=False)): at λ 1952.4 the arc collapses
    # where the debonded face is about to snap, and the probe rescue steps to λ 1915.3 on the
    # branch beyond, both of its tangents rising. Reference: the same model (its core levels
    # frozen) in displacement steps of at most 0.2 mm, stalling where that branch ends (the
    # same end state in steps of 0.05 and 0.1 mm: λ 1976.79 at w_bottom −9.6470 mm, to 1e-11;
    # the tangent stays regular up to it).
    scene = load_scene(ROOT / "scenes" / "paper-fig6-top-debond-20-load-bottom.toml")
    shipped = solve_run(scene, auto=AutoSettings(one_pass=False))
    assert "under control of w_bottom_mid" in shipped.solution.message
    fine_analysis = dataclasses.replace(scene.analysis, control="displacement",
                                        max_increment=0.2, initial_increment=0.2,
                                        max_steps=500)
    fine = solve_run(dataclasses.replace(scene, analysis=fine_analysis),
                     model_options={"core_level": shipped.model.element_levels})
    top = max(fine.states, key=lambda s: s.load_factor)
    ref = top.load_factor
    p = _maximum(shipped)
    before = max(s.load_factor for s in shipped.states if s.step < p.step)
    assert before < (1 - 0.01) * ref  # the state before the jump: 1.2 % below (measured)
    assert max(p.between) == before and 0.0 < p.located_at < 1.0
    # an equilibrium of the branch: a bound from below, 0.05 % below the end (measured)
    assert p.load_factor <= ref * (1 + 1e-9)
    assert p.load_factor > ref * (1 - 2e-3)
    w = "w_bottom_mid"
    assert top.probes[w] <= p.probes[w] < shipped.states[p.step - 1].probes[w]


@pytest.mark.parametrize(("index", "until"), [(91, -2.0), (57, -3.5), (89, -2.0)])
def test_a_face_snap_a_step_jumps_over_is_found_by_walking_the_branch(index, until):
    # The knock-down study's off-centre debonds (91: 40 mm at x = 110; 57: 25 mm at x = 90;
    # 89: 40 mm at x = 70): the debonded face snaps away from the core under the bending
    # compression, and one step lands on the snapped branch (91: an arc step, λ 159.5 → 182.4,
    # below the top; 57: the kept half of a bent step, 472.7 → 548.0, 0.1 % below it; 89: the
    # probe rescue from λ 288.10, 0.001 mm short of the top, to 305.6). Reference: the same
    # case in displacement steps of 0.01 mm, which stall at the branch's end (its top). Closed
    # form for scale: the clamped-strip Euler load of the debonded face, π² E t²/(3 L²) × b t d
    # over the moment arm x/2 (196.0, 613.4, 308.1): the tops are 0.98, 0.89, 0.94 of it.
    case = load_study(ROOT / "studies" / "shipped" / "fig5-knockdown.toml").cases[index]
    path = solve_run(case.scene)
    fine_analysis = dataclasses.replace(case.scene.analysis, control="displacement",
                                        max_increment=0.01, initial_increment=0.01,
                                        until_value=until, max_steps=1000)
    fine = solve_run(dataclasses.replace(case.scene, analysis=fine_analysis))
    ref = max(s.load_factor for s in fine.states)
    assert "no convergence" in fine.solution.message  # it stalls at the snap, short of `until`
    first = path.solution.limit_points[0]
    assert first.kind == "max" and first.located_at is not None
    assert ref * (1 - 5e-3) < first.load_factor <= ref * (1 + 1e-9)
    E, t, b, d, span = 27420.0, 0.5, 60.0, 25.5, case.values["length"]
    arm = min(case.values["centre"], 300.0 - case.values["centre"]) / 2.0
    euler = math.pi**2 * E * t**2 / (3.0 * span**2) * b * t * d / arm
    assert 0.85 * euler < first.load_factor < euler


def test_mirror_image_debonds_report_the_same_snap():
    # Symmetry: the knock-down study's 10-mm debonds at x = 110 and x = 190 are mirror images
    # of each other (the span, the supports and the load are symmetric about x = 150). Their
    # paths are not: at 190 the probe rescue lands below the snap (2023.1, after 2059.9); at
    # 110 it goes on to the target (2137.5), and the snap is seen only by the walk from before
    # it and its corrector past the branch's end. Before that corrector, x = 110 reported no
    # limit point at all, its capacity 3.8 % above its mirror's.
    study = load_study(ROOT / "studies" / "shipped" / "fig5-knockdown.toml")
    tops = []
    for centre in (110.0, 190.0):
        case = next(c for c in study.cases
                    if c.values == {"length": 10.0, "centre": centre})
        first = solve_run(case.scene).solution.limit_points[0]
        assert first.kind == "max"
        tops.append(first.load_factor)
    assert abs(tops[0] - tops[1]) <= 1e-4 * tops[1]
