"""compare and demo take the options a user reaches for, and say what matters.

The models are the synthetic solvers of ``cmp_synthetic`` (known answers): tested here is what
the command passes to each model and what it prints.
"""

import json

from sandwich.cli import main


def _identity(folder):
    return json.loads((folder / "summary.json").read_text())["identity"]


def test_compare_sets_the_2d_level_and_the_beam_elements(tmp_path, scene_file, fake_models,
                                                         capsys):
    out = tmp_path / "o"
    code = main(["compare", str(scene_file), "--out", str(out), "--level", "coarse",
                 "--refine", "1", "--elements", "60"])
    printed = capsys.readouterr().out
    assert code == 0
    assert _identity(out / "2d")["resolution"]["level"] == "coarse"
    assert _identity(out / "2d")["resolution"]["refine"] == 1
    assert _identity(out / "beam")["resolution"]["elements"] == 60
    # the synthetic paths have a load maximum: its line with both loads and the error
    line = next(ln for ln in printed.splitlines() if ln.startswith("first load maximum:"))
    assert "beam " in line and "2d " in line and "% on 2D" in line


def test_demo_writes_under_out(tmp_path, scene_file, fake_models, monkeypatch):
    work = tmp_path / "cwd"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["demo", str(scene_file), "--out", str(tmp_path / "d"), "--quiet"]) == 0
    assert (tmp_path / "d" / "metrics.json").is_file()
    assert (tmp_path / "d" / "beam" / "summary.json").is_file()
    assert list(work.iterdir()) == []  # nothing in ./results


def test_an_interrupt_before_the_first_step_says_no_step_was_written(tmp_path, scene_file,
                                                                    monkeypatch, capsys):
    import dataclasses

    from sandwich.models import registry

    def interrupted(scene, progress=None):
        raise KeyboardInterrupt

    monkeypatch.setitem(registry.MODELS, "beam",
                        dataclasses.replace(registry.MODELS["beam"], solve=interrupted))
    code = main(["solve", str(scene_file), "--model", "beam", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 1
    assert "before any step converged" in err and "every converged step" not in err
