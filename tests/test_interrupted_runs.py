"""A run interrupted before its first converged step: a result set whose files say so.

The solver is a stand-in that is interrupted at once (the runner's behaviour, not a model's).
"""

import csv
import json
from pathlib import Path

import pytest

from sandwich.models import run_model
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parent.parent


def _interrupted(scene, progress=None):
    raise KeyboardInterrupt


def test_history_of_a_run_interrupted_before_any_step_has_the_probe_columns(tmp_path):
    scene = load_scene(ROOT / "scenes" / "default.toml")
    with pytest.raises(KeyboardInterrupt):
        run_model(scene, "beam", tmp_path / "beam", solver=_interrupted)
    with open(tmp_path / "beam" / "history.csv") as fh:
        header = next(csv.reader(fh))
        assert list(fh) == []  # no row
    assert header[:2] == ["step", "load_factor"]
    assert header[2:2 + len(scene.probes)] == [p.name for p in scene.probes]
    summary = json.loads((tmp_path / "beam" / "summary.json").read_text())
    assert summary["converged"] is False
    assert "before any step converged" in summary["message"]
