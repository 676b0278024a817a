"""The 2D reference under MPI: `mpirun -n 2 ... solve --model 2d` gives the serial history.

Reference: the serial run of the same CLI on the same scene (a partition-independence check,
not an accuracy check). The scene is fig5 (top debond with the lip pressed shut under the load,
so contact pairs whose slave and anchor lie on different ranks are active), shortened to
w_top_mid = -1.5 mm at level coarse (9 steps, ~4 s per run on this machine).
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
FIG5 = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _scene(tmp_path: Path) -> Path:
    text = FIG5.read_text()
    assert 'value = -15 }' in text
    text = text.replace('value = -15 }', 'value = -1.5 }', 1)
    text = text.replace('name = "paper-fig5-top-debond-40-load-top"', 'name = "fig5-mpi"', 1)
    path = tmp_path / "fig5-mpi.toml"
    path.write_text(text)
    return path


def _run(cmd: list[str], env: dict) -> None:
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]


def _rows(path: Path) -> list[dict[str, float]]:
    with path.open() as f:
        return [{k: float(v) for k, v in r.items() if v != ""} for r in csv.DictReader(f)]


def test_two_ranks_give_the_serial_history_and_profiles(tmp_path):
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found on PATH")
    scene = _scene(tmp_path)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env.setdefault("XDG_CACHE_HOME", str(ROOT / ".cache"))
    base = [sys.executable, "-m", "sandwich.cli", "solve", str(scene), "--model", "2d",
            "--level", "coarse", "--quiet"]
    _run(base + ["--out", str(tmp_path / "serial")], env)
    _run([mpirun, "-n", "2", "--oversubscribe"] + base + ["--out", str(tmp_path / "mpi")], env)

    ser = _rows(tmp_path / "serial" / "history.csv")
    par = _rows(tmp_path / "mpi" / "history.csv")
    assert len(ser) == len(par) >= 5
    for a, b in zip(ser, par, strict=True):
        assert a["step"] == b["step"]
        for key in ("load_factor", "w_top_mid", "w_bottom_mid"):
            assert b[key] == pytest.approx(a[key], rel=1e-6, abs=1e-12), (a["step"], key)
    assert ser[-1]["max_contact_pressure"] > 0  # contact was active (the point of the test)

    summary = {k: json.loads((tmp_path / k / "summary.json").read_text())
               for k in ("serial", "mpi")}
    assert summary["mpi"]["mpi_ranks"] == 2
    assert summary["mpi"]["dofs"] == summary["serial"]["dofs"]

    ps = _rows(tmp_path / "serial" / "profiles.csv")
    pp = _rows(tmp_path / "mpi" / "profiles.csv")
    assert len(ps) == len(pp) > 0
    for key in ("x", "w_top", "w_bottom", "sigma_zz_top", "sigma_zz_bottom", "tau_core",
                "p_contact_top"):
        x = np.array([r[key] for r in ps])
        y = np.array([r[key] for r in pp])
        assert np.max(np.abs(x - y)) <= 1e-6 * np.max(np.abs(x)), key
