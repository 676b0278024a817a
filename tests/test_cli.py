"""The `sandwich` command as a user runs it: files written, exit codes, no traceback."""

import csv
import json
import os
from pathlib import Path

import pytest

from sandwich.cli import main

ROOT = Path(__file__).resolve().parent.parent


def _small_scene(tmp_path, extra_analysis=""):
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = text.replace("value = -8", "value = -1")
    text = text.replace("max_steps = 400", "max_steps = 400" + extra_analysis)
    text += "\n[beam_model]\nelements = 40\n"
    path = tmp_path / "small.toml"
    path.write_text(text)
    return path


def test_solve_beam_writes_the_contract_files(tmp_path, capsys):
    scene = _small_scene(tmp_path)
    out = tmp_path / "out"
    assert main(["solve", str(scene), "--model", "beam", "--out", str(out), "--quiet"]) == 0
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert float(rows[-1]["w_top_mid"]) == pytest.approx(-1.0, rel=1e-4)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["model"] == "beam" and summary["converged"] is True
    assert summary["steps"] == len(rows)
    assert (out / "profiles.csv").stat().st_size > 0
    assert capsys.readouterr().out == ""  # --quiet


def test_stopped_run_keeps_converged_steps_and_exits_1(tmp_path, capsys):
    scene = _small_scene(tmp_path)
    scene.write_text(scene.read_text().replace("max_steps = 400", "max_steps = 2"))
    out = tmp_path / "out"
    code = main(["solve", str(scene), "--model", "beam", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1
    assert "stopped before the target" in err and "Traceback" not in err
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) >= 2
    assert json.loads((out / "summary.json").read_text())["converged"] is False


def test_mesh_command_writes_msh_and_xdmf(tmp_path, capsys):
    out = tmp_path / "mesh"
    assert main(["mesh", str(ROOT / "scenes" / "default.toml"), "--level", "coarse",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "cells" in printed and "lip pairs" in printed
    assert (out / "default.msh").exists() and (out / "default.xdmf").exists()


def test_bad_model_name_is_a_usage_error_not_a_traceback(capsys):
    with pytest.raises(SystemExit) as info:
        main(["solve", str(ROOT / "scenes" / "default.toml"), "--model", "fem3d"])
    assert info.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_progress_is_a_few_lines_when_not_a_terminal(tmp_path):
    import io
    from types import SimpleNamespace

    from sandwich.progress import PathProgress
    from sandwich.scene_file import load_scene

    scene = load_scene(_small_scene(tmp_path))  # until w_top_mid = -1
    log = io.StringIO()  # not a terminal
    with PathProgress(scene, "small", stream=log) as bar:
        for i in range(1, 101):
            bar(SimpleNamespace(step=i, load_factor=float(i), probes={"w_top_mid": -i / 100}))
    lines = log.getvalue().splitlines()
    assert 10 <= len(lines) <= 11  # one per tenth of the way, not one per step
    assert lines[-1].startswith("small: 100% step 100")
    assert "\r" not in log.getvalue()


def test_library_log_lines_are_held_back_unless_verbose():
    import logging

    from sandwich.quiet_logs import hush_libraries, unhush_libraries

    seen = []
    handler = logging.Handler()
    handler.emit = lambda record: seen.append(record.getMessage())
    root = logging.getLogger()
    root.addHandler(handler)
    try:
        hush_libraries()
        root.setLevel(logging.INFO)  # as setuptools does when the 2D forms are compiled
        root.info("running build_ext")
        logging.getLogger("UFL").warning("Discontinuous Lagrange element requested")
        root.error("a real error")
        unhush_libraries()
        root.info("shown again")
    finally:
        root.removeHandler(handler)
        root.setLevel(logging.WARNING)
    assert seen == ["a real error", "shown again"]


def test_warnings_before_a_solve(tmp_path):
    import dataclasses

    from sandwich.cli.scene_commands import warnings_before_solve
    from sandwich.scene import Analysis, Load
    from sandwich.scene_file import load_scene

    scene = load_scene(ROOT / "scenes" / "default.toml")
    assert warnings_before_solve(scene, "beam") == []
    pin = scene.supports[0]
    over = dataclasses.replace(scene, loads=(Load(pin.faces[0], pin.x, 0.0, -1.0),),
                               analysis=Analysis(kind="linear", until_load_factor=-2.0))
    said = " / ".join(warnings_before_solve(over, "beam"))
    assert "acts over supports[0]" in said and "reverses every load" in said


def test_an_internal_error_names_its_crash_log_and_leaves_the_current_folder_clean(
        tmp_path, monkeypatch, capsys):
    import re

    from sandwich.cli import commands

    def broken(args):
        raise RuntimeError("a bug")

    monkeypatch.setattr(commands, "cmd_validate", broken)  # what the parser runs for validate
    work = tmp_path / "cwd"
    work.mkdir()
    monkeypatch.chdir(work)
    work.chmod(0o555)  # even a read-only current folder gets no crash log and no crash
    try:
        code = main(["validate", str(ROOT / "scenes" / "default.toml")])
    finally:
        work.chmod(0o755)
    err = capsys.readouterr().err
    assert code == 3 and "internal error (RuntimeError: a bug)" in err
    log = re.search(r"details in (\S+)", err).group(1)
    assert "Traceback" in Path(log).read_text() and list(work.iterdir()) == []
    Path(log).unlink()


def test_ctrl_c_in_a_real_solve_keeps_the_converged_steps(tmp_path):
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "r"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "sandwich.cli", "solve", str(ROOT / "scenes" / "default.toml"),
         "--model", "beam", "--out", str(out)],
        cwd=tmp_path, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=env,
        # as a terminal's foreground job: a suite started in the background (`make test &`)
        # hands its children SIGINT ignored, and Python then never raises KeyboardInterrupt
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    lines = []
    t0 = time.monotonic()
    for line in proc.stderr:  # not a terminal: one progress line per tenth of the way
        lines.append(line)
        if "% step" in line and int(line.split("% step ")[1].split(",")[0]) >= 5:
            break
        assert time.monotonic() - t0 < 300, lines
    proc.send_signal(signal.SIGINT)
    rest = proc.stderr.read()
    code = proc.wait(timeout=120)
    if "reached" in rest and code == 0:  # the path finished before the signal landed
        pytest.skip("the solve ended before the interrupt")
    assert code == 1, rest
    assert "interrupted" in rest and "Traceback" not in rest
    with open(out / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) >= 2 and float(rows[-1]["w_top_mid"]) < 0
    # every kept step has the energy release rate of both debond tips (issue 14: they were lost)
    assert all(r[c] != "" for r in rows for c in ("G_0_start", "G_0_end", "GI_0_end", "GII_0_end"))
    assert all(float(r[c]) >= 0.0 for r in rows for c in ("G_0_start", "GI_0_end"))
    assert float(rows[-1]["G_0_end"]) > 0.0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and "interrupted after step" in summary["message"]
    assert "G_warning" not in summary
    assert list(tmp_path.iterdir()) == [out]


def test_a_critical_point_located_within_its_step_is_said_so(tmp_path, capsys):
    # the default scene at the paper's core buckles inside its step 10 (docs/solver.md); the
    # summary line names the step and the converged load factors either side of the point
    path = tmp_path / "paper_core.toml"
    path.write_text((ROOT / "scenes" / "default.toml").read_text() + "\n[beam_model]\ncore = 1\n")
    out = tmp_path / "out"
    assert main(["solve", str(path), "--model", "beam", "--out", str(out)]) == 0
    said = [ln for ln in capsys.readouterr().out.splitlines() if "bifurcation in step" in ln]
    assert len(said) == 1, said
    summary = json.loads((out / "summary.json").read_text())
    lp, = [p for p in summary["limit_points"] if p["kind"] == "bifurcation"]
    low, high = lp["between_load_factors"]
    assert low < lp["load_factor"] < high
    assert said[0].strip() == (f"bifurcation in step {lp['step']} (between load factors "
                               f"{low:.6g} and {high:.6g}): load factor {lp['load_factor']:.6g}")


def test_solve_names_every_file_it_wrote(tmp_path, capsys):
    from sandwich.cli import main as cli_main

    scene = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"
    text = scene.read_text().replace('kind = "nonlinear"', 'kind = "linear"')
    path = tmp_path / "s.toml"
    path.write_text(text + '\n[beam_model]\ncore = 1\nelements = 40\n')
    assert cli_main(["solve", str(path), "--model", "beam", "--out", str(tmp_path / "r")]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("results in"))
    written = {p.name for p in (tmp_path / "r").iterdir()}
    for name in ("history.csv", "profiles.csv", "summary.json", "tip_tractions.csv",
                 "fields.pvd"):
        assert name in written and name in line, (name, line)
    assert "fields_*.vtu" in line


def test_solve_says_how_accurate_the_run_claims_to_be(tmp_path, capsys):
    from sandwich.cli import main as cli_main

    scene = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"
    text = scene.read_text().replace('kind = "nonlinear"', 'kind = "linear"')
    for core, expected in (("1", "no error estimate at a fixed resolution"),
                           ('"auto"', "estimated error of the core levels")):
        path = tmp_path / f"s{len(core)}.toml"
        path.write_text(text + f'\n[beam_model]\ncore = {core}\nelements = 40\n')
        out = tmp_path / f"r{len(core)}"
        assert cli_main(["solve", str(path), "--model", "beam", "--out", str(out)]) == 0
        printed = capsys.readouterr().out
        assert expected in printed, printed
        if core == '"auto"':
            est = json.loads((out / "summary.json").read_text())["core"]["estimated_error"]
            assert f"{100 * est:.2g} %" in printed


def test_solve_names_each_estimated_quantity(tmp_path, capsys):
    """A nonlinear auto run on a debonded scene: the load and probes' estimate and G's, each
    against its tolerance, as summary.json has them."""
    from sandwich.cli import main as cli_main

    scene = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"
    text = scene.read_text().replace("value = -15", "value = -3")
    assert "value = -3" in text
    path = tmp_path / "s.toml"
    path.write_text(text + "\n[beam_model]\nelements = 60\n")
    assert cli_main(["solve", str(path), "--model", "beam", "--out", str(tmp_path / "r")]) == 0
    printed = capsys.readouterr().out
    quantities = json.loads((tmp_path / "r" / "summary.json").read_text())["core"]["quantities"]
    assert {"load and probes", "G"} <= set(quantities)
    for name, q in quantities.items():
        e, t = q["estimated_error"], q["tolerance"]
        assert (f"{name} {100 * e:.2g} % ({'within' if e <= t else 'above'} {100 * t:.2g} %)"
                in printed), printed
