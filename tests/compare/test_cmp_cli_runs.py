"""The command line over the one runner: reuse decided by identity, interrupts keep the steps.

The models are replaced in the registry by the synthetic solvers (known answers, no mechanics):
what is tested here is which result folder is solved, reused or written, and what is said.
"""

import csv
import dataclasses
import json

import pytest

from sandwich.cli import main
from sandwich.models import obtain, registry, stored_identity
from sandwich.scene_file import load_scene


def _summary(folder):
    return json.loads((folder / "summary.json").read_text())


def test_compare_reuses_a_2d_solve_only_at_the_level_the_scene_asks(
        tmp_path, scene_file, fake_models, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # the default result folders are relative: results/<scene>/
    name = "paper-fig5-top-debond-40-load-top"
    assert "[reference2d]" not in scene_file.read_text()  # the scene asks the default, medium
    assert main(["solve", str(scene_file), "--model", "2d", "--level", "medium", "--quiet"]) == 0
    folder = tmp_path / "results" / name / "2d"
    assert _summary(folder)["identity"]["resolution"]["level"] == "medium"
    assert fake_models == ["2d"]
    capsys.readouterr()
    assert main(["compare", str(scene_file)]) == 0
    out = capsys.readouterr().out
    assert fake_models == ["2d", "beam"]  # the medium 2D result is reused
    assert f"2d: reused results/{name}/2d/" in out
    # the scene now asks level coarse: the medium result is not reused, and compare says why
    scene_file.write_text(scene_file.read_text() + '\n[reference2d]\nlevel = "coarse"\n')
    assert main(["compare", str(scene_file)]) == 0
    out = capsys.readouterr().out
    assert fake_models == ["2d", "beam", "2d"]  # the beam's result does not depend on it
    assert "solved at level=medium, the scene asks level=coarse; solved again" in out
    assert _summary(folder)["identity"]["resolution"]["level"] == "coarse"
    # a solve at another level than the scene's is not reused either
    assert main(["solve", str(scene_file), "--model", "2d", "--level", "fine", "--quiet"]) == 0
    assert main(["compare", str(scene_file), "--quiet"]) == 0
    assert fake_models == ["2d", "beam", "2d", "2d", "2d"]


def test_compare_with_out_writes_nothing_outside_it(tmp_path, scene_file, fake_models,
                                                    monkeypatch):
    work = tmp_path / "cwd"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["compare", str(scene_file), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert list(work.iterdir()) == []
    assert (tmp_path / "o" / "beam" / "summary.json").is_file()
    assert (tmp_path / "o" / "2d" / "summary.json").is_file()
    assert (tmp_path / "o" / "metrics.json").is_file()


def test_interrupted_solve_keeps_its_converged_steps_and_is_never_reused(
        tmp_path, scene_file, synth, monkeypatch, capsys):
    def interrupted(scene, progress=None):
        for sol_step in synth.make_solution("2d", n_steps=8).history[:5]:
            progress(sol_step)
        raise KeyboardInterrupt

    monkeypatch.setitem(registry.MODELS, "2d",
                        dataclasses.replace(registry.MODELS["2d"], solve=interrupted))
    out = tmp_path / "r"
    assert main(["solve", str(scene_file), "--model", "2d", "--out", str(out), "--quiet"]) == 1
    assert "interrupted" in capsys.readouterr().err
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["step"]) for r in rows] == [1, 2, 3, 4, 5]
    summary = _summary(out)
    assert summary["converged"] is False and "interrupted after step 5" in summary["message"]
    assert stored_identity(out) is None  # an interrupted run is never taken for a result
    calls = []
    run = obtain(load_scene(scene_file), "2d", out,
                 solver=synth.fake_solvers(0.0, calls=calls)["2d"])
    assert run.origin == "run" and calls == ["2d"] and "no identity" in run.stale


@pytest.mark.parametrize("argv, words", [
    (["--model", "2d", "--refine", "-3"], "--refine: must be between 0 and 6"),
    (["--model", "2d", "--refine", "9"], "--refine: must be between 0 and 6"),
    (["--model", "beam", "--elements", "1"], "--elements: must be between 2 and 200000"),
    (["--model", "beam", "--level", "fine"], "set the 2D mesh"),
    (["--model", "2d", "--elements", "40"], "not the 2D model's"),
])
def test_bad_options_are_refused_before_any_work(tmp_path, scene_file, fake_models, argv,
                                                 words, capsys):
    code = main(["solve", str(scene_file), *argv, "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 2 and words in err and "Traceback" not in err
    assert fake_models == [] and not (tmp_path / "r").exists()


def test_an_output_folder_that_is_a_file_is_refused_before_the_solve(
        tmp_path, scene_file, fake_models, capsys):
    (tmp_path / "f").write_text("x")
    code = main(["solve", str(scene_file), "--model", "beam", "--out", str(tmp_path / "f")])
    assert code == 2 and "not a folder" in capsys.readouterr().err
    assert fake_models == [] and (tmp_path / "f").read_text() == "x"


def test_a_full_disk_keeps_the_previous_result_and_says_so(tmp_path, scene_file, fake_models,
                                                           monkeypatch, capsys):
    import errno

    from sandwich.results import writing

    out = tmp_path / "r"
    assert main(["solve", str(scene_file), "--model", "beam", "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def full(path, text):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(writing, "_write_file", full)
    code = main(["solve", str(scene_file), "--model", "beam", "--out", str(out), "--quiet",
                 "--elements", "60"])
    err = capsys.readouterr().err
    assert code == 2 and "No space left on device" in err and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r", "scene.toml"]


def test_a_models_note_restarts_the_streamed_path(tmp_path, scene_file, synth, monkeypatch,
                                                  capsys):
    from sandwich.results import PathNote

    history = synth.make_solution("2d", n_steps=8).history

    def rerun_then_interrupted(scene, progress=None):
        for rec in history[:3]:
            progress(rec)
        progress(PathNote("rerunning the path"))
        for rec in history[:2]:
            progress(rec)
        raise KeyboardInterrupt

    monkeypatch.setitem(registry.MODELS, "beam",
                        dataclasses.replace(registry.MODELS["beam"], solve=rerun_then_interrupted))
    out = tmp_path / "r"
    assert main(["solve", str(scene_file), "--model", "beam", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "rerunning the path" in err and "Traceback" not in err
    with open(out / "history.csv") as fh:
        assert [int(r["step"]) for r in csv.DictReader(fh)] == [1, 2]  # the rerun's states only
