"""A converged state's contact columns are evaluated once, by the path, and kept as they were.

The path follower asks the model for each accepted state's history columns
(``BeamModel.state_columns``, after ``commit``); the solution's history and the penetration
check of the penalty rerun take them from there. Reference: ``contact_summary`` evaluated
afresh at every converged state (fig. 5 scene, 120 elements, to −6 mm: contact closed over the
debond).
"""

import dataclasses
from pathlib import Path

import pytest

import sandwich.beam.model as model_module
from sandwich.beam.contact_summary import CONTACT_COLUMNS, contact_columns
from sandwich.beam.solve import run
from sandwich.scene_file import load_scene

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _scene():
    sc = load_scene(SCENE)
    return dataclasses.replace(
        sc, beam_model=dataclasses.replace(sc.beam_model, core=1, elements=120),
        analysis=dataclasses.replace(sc.analysis, until_value=-6.0))


def test_history_contact_columns_equal_a_fresh_summary_at_every_state():
    r = run(_scene())
    assert r.solution.converged, r.solution.message
    active = 0.0
    for s, record in zip(r.states, r.solution.history, strict=True):
        fresh = contact_columns(r.model.contact_summary(s.u))
        for name in CONTACT_COLUMNS:
            assert record.extra[name] == pytest.approx(fresh[name], rel=1e-12, abs=1e-300)
        active = max(active, fresh["contact_pairs_active"])
    assert active > 0  # the check meets contact
    assert r.solution.extra["max_penetration"] == pytest.approx(
        max(rec.extra["max_penetration"] for rec in r.solution.history), rel=1e-12)


def test_contact_is_summarised_once_per_accepted_state(monkeypatch):
    calls = []
    real = model_module.BeamModel.contact_summary

    def counting(self, u):
        calls.append(1)
        return real(self, u)

    monkeypatch.setattr(model_module.BeamModel, "contact_summary", counting)
    r = run(_scene())
    assert len(calls) == len(r.states)  # commit's, taken by state_columns and the history
