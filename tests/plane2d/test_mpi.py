"""The 2D reference under MPI: `mpirun -n 2 ... solve --model 2d` gives the serial history.

Reference: the serial run of the same CLI on the same scene (a partition-independence check,
not an accuracy check). Two scenes, both shortened, level coarse:

- fig5 (three-point bending, top debond 130-170 with the lip pressed shut under the load, so
  contact pairs whose slave and anchor lie on different ranks are active), to
  w_top_mid = -1.5 mm (9 steps);
- fig7 c4 (cantilever clamped at x = 0, top and bottom debonds 0-40 with open mouths at the
  clamp, tip patch load), to w_top_tip = -3 mm (10 steps): clamp supports, two contact pairs on
  both interfaces, the bottom lip in contact all along, a first step of 15 Newton iterations
  (lip nodes leaving contact one by one) and the knee of the path near w_top_tip = -2 mm where
  the stiffness drops about 10x (the debonded bottom face buckles).

Agreement asked: every history value within 10 × the Newton tolerance the solver used
(``newton_tol`` of the serial summary), relative. Both runs stop each step at a relative
residual ≤ newton_tol (and a last correction ≤ √newton_tol of the step, i.e. a state error of
order newton_tol, Newton being quadratic there), so two partitions may differ by that much and
no more. Measured: ≤ 3e-10 (fig5, tol 1.5e-8), ≤ 1.4e-8 (c4, tol 1.2e-7; 4.6e-9 in the
last run).

Only rank 0 writes: the two ranks run in different working directories (OpenMPI MPMD syntax,
one app context per rank with its own ``-wdir``) with the same relative ``--out``; the result
folder must exist in rank 0's directory only.
"""

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.dolfinx

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


def _scene(tmp_path: Path, name: str, full_until: str, short_until: str, new_name: str) -> Path:
    text = (SCENES / f"{name}.toml").read_text()
    assert f"value = {full_until} }}" in text
    text = text.replace(f"value = {full_until} }}", f"value = {short_until} }}", 1)
    text = text.replace(f'name = "{name}"', f'name = "{new_name}"', 1)
    path = tmp_path / f"{new_name}.toml"
    path.write_text(text)
    return path


def _run(cmd: list[str], env: dict) -> None:
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]


def _rows(path: Path) -> list[dict[str, float]]:
    with path.open() as f:
        return [{k: float(v) for k, v in r.items() if v != ""} for r in csv.DictReader(f)]


def _serial_and_two_ranks(scene: Path, tmp_path: Path) -> tuple[Path, Path]:
    """Run the CLI serially and on 2 ranks; return the two result folders.

    The 2-rank run starts each rank in its own working directory with the relative output
    folder ``out``: the files must appear under rank 0's directory only.
    """
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found on PATH")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env.setdefault("XDG_CACHE_HOME", str(ROOT / ".cache"))
    env["XDG_CACHE_HOME"] = str(Path(env["XDG_CACHE_HOME"]).resolve())  # ranks change cwd
    args = ["-m", "sandwich.cli", "solve", str(scene), "--model", "2d", "--level", "coarse",
            "--quiet"]
    serial = tmp_path / "serial"
    _run([sys.executable, *args, "--out", str(serial)], env)
    rank_dirs = [tmp_path / "rank0", tmp_path / "rank1"]
    cmd = [mpirun, "--oversubscribe"]
    for i, d in enumerate(rank_dirs):
        d.mkdir()
        cmd += ([":"] if i else []) + ["-n", "1", "-wdir", str(d), sys.executable, *args,
                                       "--out", "out"]
    _run(cmd, env)
    par = rank_dirs[0] / "out"
    assert (par / "history.csv").is_file() and (par / "summary.json").is_file()
    assert list(rank_dirs[1].iterdir()) == [], "rank 1 wrote files"
    return serial, par


def _check_same(serial: Path, par: Path, keys: tuple[str, ...], profile_keys: tuple[str, ...],
                min_rows: int) -> tuple[dict, float]:
    summary = {k: json.loads((d / "summary.json").read_text())
               for k, d in (("serial", serial), ("mpi", par))}
    assert summary["serial"]["mpi_ranks"] == 1 and summary["mpi"]["mpi_ranks"] == 2
    assert summary["mpi"]["dofs"] == summary["serial"]["dofs"]
    tol = summary["serial"]["newton_tol"]
    assert summary["mpi"]["newton_tol"] == pytest.approx(tol, rel=1e-6)
    assert tol <= 1e-6  # a solver tolerance, not a loose one (1.5e-8 fig5, 1.2e-7 c4)
    rel = 10.0 * tol

    ser = _rows(serial / "history.csv")
    mpi = _rows(par / "history.csv")
    assert len(ser) == len(mpi) >= min_rows
    worst = 0.0
    # abs: rel × the column's largest value (a lip at gap ~ -1e-15 mm, round-off, shows
    # p ~ 1e-11 MPa in one run and a different 1e-11 in the other)
    scale = {key: max(abs(r[key]) for r in ser) for key in keys}
    for a, b in zip(ser, mpi, strict=True):
        assert a["step"] == b["step"]
        for key in keys:
            assert b[key] == pytest.approx(a[key], rel=rel, abs=rel * scale[key]), (a["step"], key)
            if a[key] != 0.0:
                worst = max(worst, abs(b[key] - a[key]) / abs(a[key]))
    assert ser[-1]["max_contact_pressure"] > 0  # contact was active (the point of the test)

    ps = _rows(serial / "profiles.csv")
    pp = _rows(par / "profiles.csv")
    assert len(ps) == len(pp) > 0
    for key in profile_keys:
        x = np.array([r[key] for r in ps])
        y = np.array([r[key] for r in pp])
        assert np.max(np.abs(x - y)) <= rel * np.max(np.abs(x)), key
    return summary, worst


def test_two_ranks_give_the_serial_history_and_profiles(tmp_path):
    """fig5 to w_top_mid = -1.5 mm: top lip pressed shut under the load at mid-span."""
    scene = _scene(tmp_path, "paper-fig5-top-debond-40-load-top", "-15", "-1.5", "fig5-mpi")
    serial, par = _serial_and_two_ranks(scene, tmp_path)
    _, worst = _check_same(serial, par, ("load_factor", "w_top_mid", "w_bottom_mid",
                                         "G_0_start", "G_0_end", "GII_0_start"),
                           ("x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom",
                            "tau_core", "p_contact_top"), min_rows=5)
    print(f"fig5: worst relative history difference {worst:.2e}")


def test_two_ranks_give_the_serial_history_cantilever_with_debonds_at_the_clamp(tmp_path):
    """fig7 c4 to w_top_tip = -3 mm: clamp, open-mouth debonds on both interfaces."""
    scene = _scene(tmp_path, "paper-fig7-cantilever-c4", "-40", "-3", "c4-mpi")
    serial, par = _serial_and_two_ranks(scene, tmp_path)
    summary, worst = _check_same(
        serial, par, ("load_factor", "w_top_tip", "w_bottom_tip", "max_contact_pressure"),
        ("x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom", "tau_core",
         "p_contact_top", "p_contact_bottom"), min_rows=6)
    ser = _rows(serial / "history.csv")
    # the path passes the knee (the reason for choosing it): the secant stiffness of the last
    # two steps is below 1/5 of the first step's
    lam = [r["load_factor"] for r in ser]
    w = [r["w_top_tip"] for r in ser]
    assert (lam[-1] - lam[-3]) / (w[-3] - w[-1]) < 0.2 * (lam[1] - lam[0]) / (w[0] - w[1])
    assert all(r["max_contact_pressure"] > 1e-3 for r in ser[1:])  # the lip stays in contact
    # both runs take the same iterations (± 1: a convergence test met within round-off of its
    # threshold may need one more in one run)
    mpi = _rows(par / "history.csv")
    assert all(abs(a["iterations"] - b["iterations"]) <= 1 for a, b in zip(ser, mpi, strict=True))
    assert summary["serial"]["max_penetration_over_face_thickness"] <= 1e-3
    print(f"c4: worst relative history difference {worst:.2e}")


def test_two_ranks_locate_the_bifurcation_where_one_rank_does(tmp_path):
    """fig5 to -5 mm: the bifurcation located within its step (the crossed eigenvalue's inverse
    iteration with global inner products and collective solves) is the serial run's."""
    scene = _scene(tmp_path, "paper-fig5-top-debond-40-load-top", "-15", "-5", "fig5-mpi-bif")
    serial, par = _serial_and_two_ranks(scene, tmp_path)
    points = [json.loads((d / "summary.json").read_text())["limit_points"]
              for d in (serial, par)]
    (s,), (p,) = ([lp for lp in pts if lp["kind"] == "bifurcation"] for pts in points)
    assert s["step"] == p["step"] and 0.0 < s["located_at_step_fraction"] < 1.0
    low, high = s["between_load_factors"]
    assert low < s["load_factor"] < high  # located inside the step, not at its end
    assert p["load_factor"] == pytest.approx(s["load_factor"], rel=1e-6)
    assert p["located_at_step_fraction"] == pytest.approx(s["located_at_step_fraction"],
                                                          rel=1e-5)
