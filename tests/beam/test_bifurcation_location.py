"""The beam's buckling (bifurcation) load is located within the step that crosses it.

Reference: the same model (the knock-down study's: fig. 5 scene, core level 1, 240 elements)
followed in displacement steps of at most 0.05 mm, its bifurcation narrowed between equilibria
either side (a bracket 0.6 % wide) — a converged fine-step path, not the long step under test.
The long step (as shipped, a 60 mm centred debond) crosses the bifurcation 12 % below its end
state (docs/solver.md, benchmarks/results/beam/critical_location.md).
"""

import dataclasses
from pathlib import Path

import numpy as np

from sandwich.beam import run as solve_run
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[2]


def _scene(narrowed: bool, fine: bool = False):
    scene = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    debonds = tuple(dataclasses.replace(d, start=120.0, end=180.0) for d in scene.debonds)
    a = dataclasses.replace(scene.analysis, locate_critical_points=narrowed)
    if fine:
        a = dataclasses.replace(a, control="displacement", until_value=-5.0, max_increment=0.05,
                                initial_increment=0.05, max_steps=2000)
    return dataclasses.replace(scene, debonds=debonds, analysis=a, beam_model=dataclasses.replace(
        scene.beam_model, core=1, elements=240))


def _bifurcation(run):
    lp = next(p for p in run.solution.limit_points if p.kind == "bifurcation")
    state = next(s for s in run.states if s.step == lp.step)
    return lp, state.load_factor


def test_a_long_step_across_the_buckling_load_is_narrowed_to_the_fine_paths_value():
    ref, _ = _bifurcation(solve_run(_scene(True, fine=True)))
    assert ref.between[1] - ref.between[0] < 0.01 * ref.load_factor
    plain_run, narrowed_run = solve_run(_scene(False)), solve_run(_scene(True))
    plain, at_state = _bifurcation(plain_run)
    narrowed, _ = _bifurcation(narrowed_run)

    def err(v):
        return abs(v - ref.load_factor) / ref.load_factor

    assert err(at_state) > 0.05  # the state after the crossing: the step is long
    assert err(plain.load_factor) < 0.5 * err(at_state)  # located from the step's two ends
    assert err(narrowed.load_factor) < 0.01  # narrowed by equilibria inside the step
    assert narrowed.between[0] >= plain.between[0] and narrowed.between[1] <= plain.between[1]
    assert 0.0 < narrowed.located_at < 1.0
    # the equilibria solved inside the step are not path states: the path is the same
    assert len(plain_run.states) == len(narrowed_run.states)
    for a, b in zip(plain_run.states, narrowed_run.states, strict=True):
        assert a.load_factor == b.load_factor and np.array_equal(a.u, b.u)
