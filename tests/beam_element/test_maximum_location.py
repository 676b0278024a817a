"""The beam's load maximum is located within the step that passes it (sandwich.solver.extrema).

Reference: the same model (fig. 4, the bonded sandwich in three-point bending, core level 2 —
the core crushing under the pad) followed in displacement steps of at most 0.2 mm, its maximum
narrowed — a converged fine-step path, not the long step under test (measured with 0.05-mm
steps: 1927.0092, the same to 1e-9; benchmarks/results/beam/maximum_location.md). As the scene
has it the path passes the maximum inside its last step (1436.5 → 1882.6, to the target), and
its extreme state lies 2.3 % below the top.
"""

import dataclasses
from pathlib import Path

from beam_element import run as solve_run
from sandwich.scene_file import load_scene

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
    # fig. 6 as shipped: at λ 1952.4 the arc collapses where the debonded face is about to
    # snap, and the probe rescue steps to λ 1915.3 on the branch beyond, both of its tangents
    # rising. Reference: the same model (its core levels frozen) in displacement steps of at
    # most 0.2 mm, stalling where that branch ends (the same end state in steps of 0.05 and
    # 0.1 mm: λ 1976.79 at w_bottom −9.6470 mm, to 1e-11; the tangent stays regular up to it).
    scene = load_scene(ROOT / "scenes" / "paper-fig6-top-debond-20-load-bottom.toml")
    shipped = solve_run(scene)
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
