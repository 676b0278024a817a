"""A cohesive growth run through the `sandwich` command: the growth line, columns, summary."""

import csv
import json
from pathlib import Path

import numpy as np

from sandwich.cli import main

SCENE = """
name = "peel-cohesive"
description = "face cantilever peeled by an end force, debond grown by a cohesive law"

[beam]
length = 200.0
width = 20.0

[layers]
top = { thickness = 1.0, material = "face" }
core = { thickness = 10.0, material = "core" }
bottom = { thickness = 1.0, material = "face" }

[materials.face]
E = 70000.0
nu = 0.3

[materials.core]
E = 200.0
nu = 0.3

[[supports]]
x = 200
on = "faces"
type = "clamp"

[[loads]]
on = "top"
x = 0
width = 0
force = 1

[[debonds]]
interface = "top"
start = 0
end = 40
toughness = { GIc = 1e-5, GIIc = 1e-5 }
growth = { method = "cohesive", sigma_c = 0.01, zone = 30 }

[[probes]]
name = "w0"
on = "top"
x = 0

[analysis]
kind = "nonlinear"
control = "displacement"
until = { probe = "w0", value = 0.2 }

[beam_model]
elements = 160
core = 1
"""


def test_solve_prints_the_growth_and_writes_the_tips(tmp_path: Path, capsys):
    path = tmp_path / "peel.toml"
    path.write_text(SCENE)
    out = tmp_path / "out"
    assert main(["solve", str(path), "--model", "beam", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "growth (cohesive law): first at load factor" in said
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    tips = [float(r["tip_0_end"]) for r in rows]
    assert tips[0] == 40.0 and tips[-1] > 45.0
    assert all("process_zone_0_end" in r for r in rows)
    with open(out / "profiles.csv") as fh:
        profile = list(csv.DictReader(fh))
    last = [r for r in profile if r["step"] == profile[-1]["step"]]
    damage = {float(r["x"]): float(r["damage_top"]) for r in last}
    assert damage[min(damage)] == 1.0 and damage[max(damage)] == 0.0  # debond, bonded end
    assert max(v for x, v in damage.items() if 40.0 < x < tips[-1]) == 1.0  # the grown part
    summary = json.loads((out / "summary.json").read_text())
    growth = summary["debond_growth"]
    assert growth["method"] == "cohesive law"
    assert growth["residual_strength"] >= growth["first_growth_load"] > 0


def test_the_2d_model_grows_the_same_debond_by_the_same_law(tmp_path: Path, capsys):
    """`sandwich solve --model 2d`: its own cohesive law, the same columns and summary."""
    import pytest

    pytest.importorskip("dolfinx")
    path = tmp_path / "peel.toml"
    path.write_text(SCENE + '\n[reference2d]\nlevel = "coarse"\n')
    out = tmp_path / "out"
    assert main(["solve", str(path), "--model", "2d", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "growth (cohesive law): first at load factor" in said
    assert "no cohesive law" not in said
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    tips = [float(r["tip_0_end"]) for r in rows]
    assert tips[0] == 40.0 and tips[-1] > 45.0 and all(np.diff(tips) >= 0)
    with open(out / "profiles.csv") as fh:
        profile = list(csv.DictReader(fh))
    last = [r for r in profile if r["step"] == profile[-1]["step"]]
    damage = {float(r["x"]): float(r["damage_top"]) for r in last}
    assert damage[min(damage)] == 1.0 and damage[max(damage)] == 0.0
    growth = json.loads((out / "summary.json").read_text())["debond_growth"]
    assert growth["method"] == "cohesive law"
    assert growth["residual_strength"] >= growth["first_growth_load"] > 0


def test_compare_draws_the_cohesive_path_as_a_growth_envelope(tmp_path: Path):
    from sandwich.beam import solve
    from sandwich.compare.growth import growth_figures
    from sandwich.scene_file import load_scene

    path = tmp_path / "peel.toml"
    path.write_text(SCENE)
    scene = load_scene(path)
    figures, tables = growth_figures(scene, {"beam": solve(scene)}, tmp_path, 1.0)
    assert [f.name for f in figures] == ["growth_0.png", "growth_tips_0.png"]
    with open(tmp_path / "growth.csv") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["method"] == "cohesive law" and float(row["residual_strength_N"]) > 0


def test_an_interrupted_growing_run_keeps_its_steps_and_tip_positions(tmp_path: Path):
    import pytest

    from sandwich.beam import solve
    from sandwich.models import run_model
    from sandwich.scene_file import load_scene

    path = tmp_path / "peel.toml"
    path.write_text(SCENE)
    scene = load_scene(path)

    def interrupted_once_grown(scene, progress=None):
        def on_state(item):
            if progress is not None:
                progress(item)
            if getattr(item, "extra", {}).get("tip_0_end", 40.0) > 45.0:
                raise KeyboardInterrupt  # a Ctrl-C once the tip has run 5 mm
        return solve(scene, progress=on_state)

    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_model(scene, "beam", out, solver=interrupted_once_grown)
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert float(rows[-1]["tip_0_end"]) > 45.0 and float(rows[0]["tip_0_end"]) == 40.0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and "interrupted" in summary["message"]
    growth = summary["debond_growth"]
    assert growth["method"] == "cohesive law"
    assert growth["tips"]["0_end"]["to"] == float(rows[-1]["tip_0_end"])
