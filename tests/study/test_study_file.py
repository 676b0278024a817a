"""Study files: shipped studies expand to checked cases; axes set what they name; bad ones refused.

The malformed corpus (``tests/study/malformed/``) carries the expected key and a fragment of the
reason in each file's header, written by hand from the study format (docs/studies.md), not copied
from the validator's output. Derived parameters are checked against the hand-written scenes they
reproduce (the paper's Fig. 9 files) and against the typed transformations of the extremes map.
"""

import dataclasses
import glob
import math
import re
from pathlib import Path

import pytest

from sandwich.cli import main
from sandwich.scene_file import load_scene
from sandwich.studies.study_file import StudyError, load_study

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
MALFORMED = sorted(glob.glob(str(HERE / "malformed" / "*.toml")))
SHIPPED = sorted(glob.glob(str(ROOT / "studies" / "shipped" / "*.toml")))
FIG5 = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _study(tmp_path, text, name="s"):
    path = tmp_path / f"{name}.toml"
    path.write_text(f'scene = "{FIG5}"\n' + text)
    return load_study(path)


def test_corpus_is_large_enough():
    assert len(MALFORMED) >= 15


@pytest.mark.parametrize("path", MALFORMED, ids=lambda p: Path(p).stem)
def test_malformed_study_is_refused_with_key_and_reason(path):
    head = Path(path).read_text().splitlines()[:2]
    key = re.match(r"# expect-key: (.*)", head[0]).group(1).strip()
    reason = re.match(r"# expect-reason: (.*)", head[1]).group(1).strip()
    with pytest.raises(StudyError) as info:
        load_study(path)
    problems = info.value.problems
    assert all(p.file == path for p in problems)
    hits = [p for p in problems if p.key == key and reason in p.reason]
    assert hits, f"expected {key!r} with {reason!r}; got {[str(p) for p in problems]}"


@pytest.mark.parametrize("path", MALFORMED[:6], ids=lambda p: Path(p).stem)
def test_cli_refuses_a_bad_study_with_exit_2_one_line_each_and_no_traceback(path, capsys,
                                                                          tmp_path):
    code = main(["study", path, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert "Traceback" not in err
    lines = [x for x in err.splitlines() if x]
    assert lines and all(x.startswith(path + ": ") for x in lines)
    assert not (tmp_path / "out").exists()  # refused before anything ran


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: Path(p).stem)
def test_shipped_study_expands_to_checked_cases(path):
    study = load_study(path)
    assert len(study.cases) == math.prod(len(a.values) for a in study.axes)
    assert len({c.key for c in study.cases}) == len(study.cases)  # one folder per case


def test_the_knockdown_study_has_at_least_100_beam_cases():
    study = load_study(ROOT / "studies" / "shipped" / "fig5-knockdown.toml")
    assert study.model == "beam" and len(study.cases) >= 100
    assert all(c.scene.beam_model.core == 1 for c in study.cases)  # the study's resolution
    # its [analysis] merged into every case: the capacities' critical loads are narrowed, and
    # the base scene's own [analysis] keys are kept
    assert all(c.scene.analysis.locate_critical_points for c in study.cases)
    assert all(c.scene.analysis.until_probe == "w_top_mid" for c in study.cases)


def test_paths_set_the_values_they_name(tmp_path):
    s = _study(tmp_path, """
[[axis]]
path = "debonds.0.start"
values = [120.0]
[[axis]]
path = "materials.core.Ex"
values = [40.0]
[[axis]]
path = "layers.core.thickness"
values = [20.0]
[[axis]]
path = "loads.0.x"
values = [140.0]
[[axis]]
path = "beam_model.elements"
values = [96]
[[axis]]
name = "until"
path = "analysis.until.value"
scale = true
values = [0.5]
""")
    (case,) = s.cases
    sc = case.scene
    assert sc.debonds[0].start == 120.0 and sc.debonds[0].end == 170.0
    assert sc.core.material.Ex == 40.0 and sc.core.material.name == "rohacell"
    assert sc.core.material.Ez == 52.5  # only the named value changes
    assert sc.core.thickness == 20.0 and sc.loads[0].x == 140.0
    assert sc.beam_model.elements == 96  # a table the base scene leaves out
    assert sc.analysis.until_value == -7.5  # -15 x 0.5


def test_ranges_include_their_stop_and_logranges_are_geometric(tmp_path):
    s = _study(tmp_path, """
[[axis]]
path = "loads.0.x"
range = { start = 100, stop = 200, step = 25 }
[[axis]]
path = "materials.core.Ex"
logrange = { start = 1, stop = 100, num = 3 }
""")
    xs, es = (a.values for a in s.axes)
    assert xs == (100.0, 125.0, 150.0, 175.0, 200.0)
    assert es == pytest.approx((1.0, 10.0, 100.0), rel=1e-12)
    assert len(s.cases) == 15


def test_debond_length_and_centre_keep_each_other(tmp_path):
    s = _study(tmp_path, """
[[axis]]
derived = "debond_length"
values = [10.0, 60.0]
[[axis]]
derived = "debond_centre"
values = [100.0]
""")
    got = [(c.scene.debonds[0].start, c.scene.debonds[0].end) for c in s.cases]
    assert got == [(95.0, 105.0), (70.0, 130.0)]


@pytest.mark.parametrize("d", [0, 10, 16, 20, 30, 40])
def test_periodic_debonds_reproduce_the_papers_fig9_scenes(tmp_path, d):
    """The derived Fig. 9 pattern against the six hand-written scene files."""
    path = tmp_path / "f9.toml"
    path.write_text(f'scene = "{ROOT / "scenes" / "paper-fig9-clamped-d20.toml"}"\n'
                    f'[[axis]]\nderived = "periodic_debonds"\nvalues = [{d}]\n')
    (case,) = load_study(path).cases
    want = load_scene(ROOT / "scenes" / f"paper-fig9-clamped-d{d}.toml")
    key = lambda db: (db.interface, round(db.start, 9), round(db.end, 9))  # noqa: E731
    assert sorted(map(key, case.scene.debonds)) == sorted(map(key, want.debonds))


def test_derived_ratios_match_the_extremes_maps_scene_transformations(tmp_path):
    """The study's derived parameters against the typed transformations of the extremes sweep."""
    from benchmarks.sweeps import extremes

    base = load_scene(FIG5)
    for derived, sweep, value in (("core_stiffness_ratio", "stiffness", 1e-3),
                                  ("thickness_ratio", "thickness", 100.0),
                                  ("slenderness", "slenderness", 20.0),
                                  ("debond_length", "debond", 0.6)):
        v = value * base.length if derived == "debond_length" else value
        s = _study(tmp_path, f'[[axis]]\nderived = "{derived}"\nvalues = [{v!r}]\n', derived)
        want = next(sc for sw, x, sc in extremes.cases(base, [sweep]) if math.isclose(x, value))
        got = s.cases[0].scene
        for f in ("length", "top", "core", "bottom", "debonds", "supports", "loads", "probes"):
            a, b = getattr(got, f), getattr(want, f)
            assert _close(a, b), (derived, f, a, b)
        assert math.isclose(got.analysis.until_value, want.analysis.until_value)


def _close(a, b):
    if dataclasses.is_dataclass(a):
        return all(_close(getattr(a, f.name), getattr(b, f.name))
                   for f in dataclasses.fields(a) if f.name != "name")
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float):
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)
    return a == b


@pytest.mark.parametrize("sweep", ["stiffness", "thickness", "slenderness", "debond", "load"])
def test_the_extremes_studies_hold_the_maps_sweeps_and_build_its_scenes(sweep):
    """The shipped extremes-<sweep> study against the map's own typed transformations."""
    from benchmarks.sweeps import extremes

    study = load_study(ROOT / "studies" / "shipped" / f"extremes-{sweep}.toml")
    assert study.check_all and study.timeout and study.max_cells
    base = load_scene(FIG5)
    want = {v: sc for sw, v, sc in extremes.cases(base, [sweep])}
    assert len(study.cases) == len(want) == len(extremes.SWEEPS[sweep])
    for case in study.cases:
        (v,) = case.values.values()
        v = v / base.length if sweep == "debond" else v
        ref = want[next(x for x in want if math.isclose(x, v))]
        for f in ("length", "top", "core", "bottom", "debonds", "supports", "loads", "probes"):
            assert _close(getattr(case.scene, f), getattr(ref, f)), (sweep, v, f)
        assert math.isclose(case.scene.analysis.until_value, ref.analysis.until_value)
        assert case.scene.beam_model.core == 1 and case.scene.beam_model.elements == 240


def test_cli_refuses_bad_workers_and_an_output_path_that_is_a_file(tmp_path, capsys):
    tiny = str(HERE / "tiny.toml")
    assert main(["study", tiny, "--workers", "0", "--out", str(tmp_path / "o")]) == 2
    assert "--workers: must be between 1 and" in capsys.readouterr().err
    (tmp_path / "file").write_text("x")
    assert main(["study", tiny, "--out", str(tmp_path / "file")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "file" in err


def test_a_bad_key_in_the_study_tables_is_reported_once_not_per_case():
    bad = HERE / "malformed" / "invalid-study-table.toml"
    with pytest.raises(StudyError) as info:
        load_study(bad)
    assert [p.key for p in info.value.problems] == ["beam_model.elements"]
