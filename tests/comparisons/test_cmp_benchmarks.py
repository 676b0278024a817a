"""Plumbing of benchmarks/tradeoff.py and benchmarks/extremes.py with synthetic solvers."""

import importlib.util
import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _load(name):
    spec = importlib.util.spec_from_file_location(f"bench_{name}",
                                                  ROOT / "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up while the class is made
    spec.loader.exec_module(mod)
    return mod


def test_tradeoff_errors_front_and_headline(tmp_path, scene, synth):
    tradeoff = _load("tradeoff")
    # synthetic convergence: the end load misses the exact one by 8/n (beam) and 4/level² (2D)
    exact = synth.make_solution("2d").final_load_factor
    level_err = {"coarse": 0.04, "medium": 0.01, "fine": 0.0025}

    def ref(sc, level, refine):
        return synth.make_solution("2d", eps=level_err[level] * 0.5 ** refine, scene=sc.name)

    def beam(sc):
        return synth.make_solution("beam", eps=8.0 / sc.beam_model.elements, scene=sc.name)

    runs = tradeoff.measure(scene, beam, ref, [20, 100, 1000], ["coarse", "medium", "fine"], [0])
    errs = {(r.model, r.resolution): r.error for r in runs}
    fine = exact * (1 + 0.0025)
    assert errs[("2d", "fine+0")] == 0.0
    assert errs[("2d", "coarse+0")] == pytest.approx(abs(exact * 1.04 - fine) / fine)
    assert errs[("beam", "1000")] == pytest.approx(abs(exact * 1.008 - fine) / fine)
    assert tradeoff.cheapest(runs, "beam").resolution == "1000"  # 100: 7.7 % > 1 %
    assert tradeoff.cheapest(runs, "2d").error <= 0.01
    assert "2D/beam time ratio" in tradeoff.headline(runs, scene.name)
    tradeoff.write(runs, [tradeoff.headline(runs, scene.name)], tmp_path)
    for f in ("tradeoff.csv", "tradeoff.md", "tradeoff.png"):
        assert (tmp_path / f).is_file()
    assert "nan" not in (tmp_path / "tradeoff.csv").read_text().lower()


def test_tradeoff_says_when_beam_never_reaches_one_percent(scene, synth):
    tradeoff = _load("tradeoff")
    runs = tradeoff.measure(
        scene, lambda sc: synth.make_solution("beam", eps=0.05),
        lambda sc, level, refine: synth.make_solution("2d"), [10], ["coarse"], [0])
    assert "1 % not reached by beam" in tradeoff.headline(runs, scene.name)


def test_extremes_cases_rows_and_map(tmp_path, scene, synth):
    extremes = _load("extremes")
    made = {(sw, v): sc for sw, v, sc in extremes.cases(scene, list(extremes.SWEEPS))}
    assert len(made) == sum(len(v) for v in extremes.SWEEPS.values())
    slender = made[("slenderness", 100)]
    assert slender.length == pytest.approx(100 * scene.total_height)
    assert slender.loads[0].x == pytest.approx(slender.length / 2)
    assert made[("stiffness", 1e-4)].core.material.Ez == pytest.approx(
        1e-4 * scene.top.material.Ex)
    assert made[("thickness", 500)].top.thickness == pytest.approx(scene.core.thickness / 500)
    whole = made[("debond", 1.0)].debonds[0]
    assert (whole.start, whole.end) == (0.0, scene.length)

    def broken(sc):
        raise RuntimeError("diverged at step 2")

    rows = []
    for key in [("load", 1.0), ("debond", 0.3)]:
        solvers = {"beam": lambda sc: synth.make_solution("beam", eps=0.02),
                   "2d": (lambda sc: synth.make_solution("2d")) if key[0] == "load" else broken}
        rows.append(extremes.row(*key, made[key], extremes.run_case(made[key], solvers)))
    assert rows[0]["load_l2"] == pytest.approx(0.02, abs=5e-4)
    assert rows[0]["beam_cuts"] == 50  # the synthetic history marks a cut every third step
    assert rows[1]["2d_converged"] is False and "diverged at step 2" in rows[1]["2d_note"]
    assert rows[1]["load_l2"] is None
    extremes.write(rows, tmp_path)
    text = (tmp_path / "extremes.md").read_text()
    assert "| load | 1 | ✓ | ✓ |" in text and "| debond | 0.3 | ✓ | ✗ |" in text
    assert not any(isinstance(v, float) and math.isnan(v) for r in rows for v in r.values())
    assert (tmp_path / "extremes.png").is_file()
