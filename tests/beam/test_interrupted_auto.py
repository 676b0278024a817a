"""Ctrl-C while ``auto`` with reruns checks a pass that reached the target: that pass is the
written answer (``AutoSettings(one_pass=False)``; the one pass is one path: the runner keeps its
converged steps, test_one_pass.py).

Reference by construction: the check (the second path pass) is interrupted at its start; the
first pass reached the target, so the result folder holds its whole answer (profiles, the core
section with that pass's estimate, converged) with a warning, and is never reused.
"""

import json
import sys
from pathlib import Path

import pytest

import sandwich.beam.core_controller as core_controller
import sandwich.beam.solve  # noqa: F401 - its module, for the monkeypatch below
from sandwich.models import run_model, with_options
from sandwich.results import InterruptedSolve
from sandwich.scene_file import load_scene

FIG5 = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def test_an_interrupt_during_the_check_keeps_the_pass_that_reached_the_target(
        tmp_path, monkeypatch):
    scene = with_options(load_scene(FIG5), "beam", elements=60)
    calls = []
    follow = core_controller.follow_penalised

    def interrupted_second(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return follow(*args, **kwargs)

    monkeypatch.setattr(core_controller, "follow_penalised", interrupted_second)
    monkeypatch.setattr(sys.modules["sandwich.beam.solve"], "AutoSettings",
                        lambda: core_controller.AutoSettings(one_pass=False))
    with pytest.raises(InterruptedSolve):
        run_model(scene, "beam", tmp_path / "beam")
    assert len(calls) == 2  # the first pass, then the check it was interrupted in
    summary = json.loads((tmp_path / "beam" / "summary.json").read_text())
    assert summary["converged"] is True
    said = [w for w in summary["warnings"] if "interrupted while checking the core levels" in w]
    assert len(said) == 1 and len(summary["warnings"]) == 1  # no contradicting second warning
    # the kept pass's own estimate, where it had one, is reported and said
    estimate = summary["core"]["estimated_error"]
    assert ("not estimated" in said[0]) == (estimate is None)
    assert summary["identity"]["complete"] is False  # never reused
    profiles = (tmp_path / "beam" / "profiles.csv").read_text().splitlines()
    assert len(profiles) > 2
