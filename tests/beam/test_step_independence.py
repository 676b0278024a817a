"""The beam's end state does not depend on the path's step sizes where it must not.

fig. 7 c1 at the paper's core and 120 elements: its default steps took the load maximum and the
−40 mm target in one hard step, and the target control from before the maximum ended on another
equilibrium (λ 735.38). A step across a critical point and the target that needs more than the
desired iterations is now cut (``sandwich.solver.path.CRITICAL_TARGET_CUTS``). Reference: the
same path in short steps (``max_increment`` 15, every step easy), which is what the answer of a
path follower must not depend on.
"""

import dataclasses
from pathlib import Path

import pytest

from sandwich.beam import run
from sandwich.scene_file import load_scene

C1 = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig7-cantilever-c1.toml"


def test_c1_at_120_elements_ends_where_its_path_in_short_steps_does():
    scene = load_scene(C1)
    short = dataclasses.replace(scene, analysis=dataclasses.replace(scene.analysis,
                                                                    max_increment=15.0))
    ends = []
    for sc in (scene, short):
        result = run(sc, elements=120, model_options={"core_level": 1})
        assert result.solution.converged
        ends.append(result.states[-1].load_factor)
    default, reference = ends
    # the same equilibrium at w = −40 mm: to the target tolerance (1e-6), not another branch
    # (735.38 before the guard, 860.66 in short steps)
    assert default == pytest.approx(reference, rel=1e-6)
