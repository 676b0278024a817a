"""Warnings travel as a list on the solution, apart from the message, into summary.json and back.

Reference by construction: a solution with two warnings; and a scene whose until target lies the
other way from where its load pushes (a sign slip a user makes), which the path follower reaches
with λ < 0 and must warn about.
"""

import dataclasses
import json
from pathlib import Path

from sandwich.beam import run
from sandwich.results import Solution, StepRecord, load_result, write_solution
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parent.parent


def test_warnings_round_trip_through_summary_json(tmp_path):
    sol = Solution("beam", "s", [StepRecord(1, 1.0, {"w": -0.1}, 3)], [], True, "reached",
                   [], 0.1, 10, warnings=["first thing", "second thing"])
    write_solution(sol, tmp_path / "r")
    data = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert data["warnings"] == ["first thing", "second thing"]
    assert data["message"] == "reached"
    assert load_result(tmp_path / "r").warnings == ["first thing", "second thing"]


def test_a_target_against_the_load_is_a_warning_not_part_of_the_message():
    scene = load_scene(ROOT / "scenes" / "default.toml")
    a = dataclasses.replace(scene.analysis, until_value=+0.5, kind="nonlinear")
    scene = dataclasses.replace(scene, analysis=a, beam_model=dataclasses.replace(
        scene.beam_model, core=1, elements=40))
    sol = run(scene).solution
    assert sol.history[-1].load_factor < 0
    assert any("λ < 0" in w for w in sol.warnings)
    assert "WARNING" not in sol.message and "λ < 0" not in sol.message
