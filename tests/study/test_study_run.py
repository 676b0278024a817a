"""The study engine: resume after a kill, failures isolated, a Dask scheduler, the progress line.

Real runs of the beam model on small studies (``tiny.toml``: 6 cases, ``resume.toml``: 12)
through the Dask engine: a LocalCluster the command starts, or one the test starts and passes
by address (``--scheduler``).
"""

import csv
import io
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sandwich.cli import main
from sandwich.studies import study_case
from sandwich.studies.study import run_study
from sandwich.studies.study_file import load_study
from sandwich.studies.study_run import Progress

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
TINY = HERE / "tiny.toml"
RESUME = HERE / "resume.toml"


def _finished(out):
    done = {}
    for f in sorted((out / "cases").glob("*/case.json")):
        rec = json.loads(f.read_text())
        if rec["status"] in ("done", "stopped"):
            done[f] = f.stat().st_mtime_ns
    return done


def test_killed_study_resumes_reusing_every_finished_case(tmp_path, capsys):
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "sandwich.cli", "study", str(RESUME), "--out", str(out),
           "--workers", "1"]
    proc = subprocess.Popen(cmd, cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        t0 = time.monotonic()
        while len(_finished(out)) < 3 and time.monotonic() - t0 < 240:
            assert proc.poll() is None, "the study ended before it could be killed"
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the study, its scheduler and its worker
        proc.wait(30)
    before = _finished(out)
    total = len(load_study(RESUME).cases)
    assert 3 <= len(before) < total, "not killed half way"
    code = main(["study", str(RESUME), "--out", str(out), "--workers", "1"])
    text = capsys.readouterr().out
    assert code == 0
    assert f"{len(before)} reused, {total - len(before)} solved now, 0 failed" in text
    for f, mtime in before.items():  # reused: never solved or written again
        assert f.stat().st_mtime_ns == mtime
    assert len(_finished(out)) == total
    rows = (out / "resume.csv").read_text().splitlines()
    assert len(rows) == total + 1 and "nan" not in "\n".join(rows).lower()


def test_a_failing_case_is_recorded_and_never_stops_the_others(tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    real = study_case.obtain

    def obtain(scene, model, folder, **kw):
        if scene.debonds[0].length == 30.0 and scene.debonds[0].start == 115.0:
            raise RuntimeError("a solver crash made by the test")
        return real(scene, model, folder, **kw)

    monkeypatch.setattr(study_case, "obtain", obtain)  # threads of this process: patched
    study = load_study(TINY)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        res = run_study(study, tmp_path, client=client, say=lambda m: None, quiet=True)
    status = {r["case"]: (r["status"], r["reason"]) for r in res.rows}
    assert len(status) == 6
    failed = [i for i, (s, _) in status.items() if s == "failed"]
    assert failed == [2]  # length 30, centre 130
    assert "RuntimeError: a solver crash made by the test" in status[2][1]
    assert all(s == "done" for i, (s, _) in status.items() if i != 2)


def test_study_on_a_dask_cluster_given_by_address(tmp_path, capsys):
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        code = main(["study", str(TINY), "--out", str(tmp_path), "--scheduler",
                     cluster.scheduler_address])
        text = capsys.readouterr().out
    assert code == 0, text
    assert "6 solved now, 0 failed now on Dask cluster" in text
    recs = [json.loads(f.read_text()) for f in tmp_path.glob("cases/*/case.json")]
    assert len(recs) == 6 and all(r["status"] == "done" for r in recs)
    assert os.getpid() not in {r["pid"] for r in recs}  # solved by the cluster's workers
    assert (tmp_path / "tiny-map.png").is_file() and (tmp_path / "summary.md").is_file()


def test_progress_lines_when_not_a_terminal():
    buf = io.StringIO()
    p = Progress(20, 5, stream=buf, label="s")
    for done in range(5, 21):
        p(done, 2 if done < 20 else 0, 1)
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("s: 5/20 done (5 reused), 2 running, 1 failed")
    assert "ETA" in lines[1] and lines[-1].startswith("s: 20/20 done") and "took" in lines[-1]
    assert 4 <= len(lines) <= 12  # about one per tenth, not one per case redraw
    assert "\r" not in buf.getvalue()


@pytest.mark.heavy
def test_check_runs_the_2d_model_on_the_selected_case_and_reports_the_error(tmp_path, capsys):
    """``check = 1`` on a 3-case beam study: the 2D model (coarse) reruns the case the indicator
    picks; the initial stiffness of the two models agrees within 10 % (the other model is the
    reference), every error is a finite number in the table and the summary."""
    code = main(["study", str(HERE / "check.toml"), "--out", str(tmp_path)])
    text = capsys.readouterr().out
    assert code == 0, text
    assert "2D spot checks: 1 case(s)" in text
    rows = list(csv.DictReader((tmp_path / "check.csv").open()))
    checked = [r for r in rows if r["checked_2d"] == "True"]
    assert len(checked) == 1 and checked[0]["2d_status"] == "done"
    ind = {r["case"]: float(r["indicator"]) for r in rows}
    assert ind[checked[0]["case"]] == max(ind.values())  # the largest indicator
    assert abs(float(checked[0]["error_initial_stiffness"])) < 0.10
    assert math.isfinite(float(checked[0]["error_capacity"]))
    assert "## 2D spot checks" in (tmp_path / "summary.md").read_text()
    assert list(tmp_path.glob("checks/*/summary.json"))  # the 2D result set is kept


def test_a_case_over_the_wall_time_cap_keeps_its_converged_steps(tmp_path, monkeypatch):
    """The study's ``timeout``: a case past the cap at a converged step is recorded as timeout,
    its converged steps written (history only, never reused); the other case is solved."""
    import dataclasses

    from distributed import Client, LocalCluster

    from sandwich.models import registry
    from sandwich.results import Solution, StepRecord

    spec = registry.MODELS["beam"]

    def slow(scene, progress=None):
        if scene.loads[0].x != 150.0:  # the other case: converged at once
            hist = [StepRecord(0, 0.0, {"w_top_mid": 0.0}, 0),
                    StepRecord(1, 5.0, {"w_top_mid": -15.0}, 2)]
            return Solution("beam", scene.name, hist, [], True, "reached", [], 0.01, 10)
        for i in range(1, 40):  # a converged state every 0.2 s, far past the 1-s cap
            time.sleep(0.2)
            progress(StepRecord(i, 10.0 * i, {"w_top_mid": -0.1 * i, "w_bottom_mid": -0.1 * i},
                                3))
        raise AssertionError("the cap did not stop the case")

    monkeypatch.setitem(registry.MODELS, "beam", dataclasses.replace(spec, solve=slow))
    path = tmp_path / "capped.toml"
    path.write_text(f'scene = "{ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"}"\n'
                    'timeout = 1.0\n[beam_model]\ncore = 1\nelements = 60\n'
                    '[[axis]]\npath = "loads.0.x"\nvalues = [150.0, 140.0]\n')
    study = load_study(path)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        res = run_study(study, tmp_path / "out", client=client, say=lambda m: None, quiet=True)
    by_x = {r["loads.0.x"]: r for r in res.rows}
    capped = by_x[150.0]
    assert capped["status"] == "timeout" and "wall-time cap of 1 s" in capped["reason"]
    folder = tmp_path / "out" / "cases" / study.cases[0].key
    states = (folder / "history.csv").read_text().splitlines()[1:]
    assert 3 <= len(states) <= 8  # about 1 s / 0.2 s of converged steps, then stopped
    assert by_x[140.0]["status"] == "done"


def test_the_indicator_of_a_load_controlled_case_is_its_compliance_change():
    """A case with a load target (no until probe): the indicator is the relative change of the
    compliance fᵀu when the core levels are raised (reference: the runner's own linear steps at
    both levels, fᵀu / λ each). It was 0 for every such case: it compared the two runs' end load
    factors, which a load target fixes."""
    import dataclasses

    from sandwich.beam import run
    from sandwich.scene import Analysis
    from sandwich.scene_file import load_scene

    base = load_scene(HERE.parents[1] / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    scene = dataclasses.replace(
        base, beam_model=dataclasses.replace(base.beam_model, core=1, elements=60),
        analysis=Analysis(kind="nonlinear", control="load", until_load_factor=300.0))
    compliance = []
    for core in (1, 1 + study_case.LOOKAHEAD):
        r = run(dataclasses.replace(
            scene, beam_model=dataclasses.replace(scene.beam_model, core=core),
            analysis=dataclasses.replace(scene.analysis, kind="linear")))
        compliance.append(float(r.model.f_ref @ r.states[-1].u) / 300.0)
    expected = abs(compliance[1] - compliance[0]) / abs(compliance[0])
    assert expected > 1e-3
    assert study_case.linear_indicator(scene) == pytest.approx(expected, rel=1e-9)


def test_no_indicator_at_the_top_core_level():
    """At the highest core level there is no level above to compare with: the indicator is
    unknown (None), not 0 (the change from a level to itself)."""
    import dataclasses

    from sandwich.scene import MAX_CORE_LEVEL
    from sandwich.scene_file import load_scene

    base = load_scene(HERE.parents[1] / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    top = dataclasses.replace(base, beam_model=dataclasses.replace(
        base.beam_model, core=MAX_CORE_LEVEL, elements=12))
    assert study_case.linear_indicator(top) is None
    below = dataclasses.replace(top, beam_model=dataclasses.replace(
        top.beam_model, core=MAX_CORE_LEVEL - 1))
    assert study_case.linear_indicator(below) > 0  # one level above it still: measured


def test_a_growth_study_reports_the_residual_strength_of_each_case(tmp_path, capsys):
    """The residual strength over the initial debond length of the face cantilever (its onset
    load falls with the length: the residual strength is the first onset load). Reference: the
    closed-form slope of 1/λ_c over the length (benchmarks/cases/growth_cases.py), 2 %."""
    from benchmarks.cases.growth_cases import onset_slope

    code = main(["study", str(HERE / "growth.toml"), "--out", str(tmp_path), "--quiet"])
    assert code == 0, capsys.readouterr().err
    rows = {float(r["a0"]): r for r in csv.DictReader((tmp_path / "growth.csv").open())}
    strength = {a: float(r["residual_strength"]) for a, r in rows.items()}
    assert set(strength) == {40.0, 50.0}
    assert all(float(rows[a]["first_growth_load"]) == strength[a] for a in rows)
    slope = (1 / strength[50.0] - 1 / strength[40.0]) / 10.0
    assert slope == pytest.approx(onset_slope(), rel=0.02)
    assert float(rows[50.0]["knockdown"]) < 1.0
