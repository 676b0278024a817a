"""Scenes: every shipped scene validates; every malformed scene is refused with file, key, reason.

The expected key and a fragment of the reason are written in each malformed file's header, by hand,
from the scene contract (issue 2) — not copied from the validator's output.
"""

import dataclasses
import glob
import re
from pathlib import Path

import pytest

from sandwich.cli import main
from sandwich.scene import Debond, SceneError
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parent.parent
SHIPPED = sorted(glob.glob(str(ROOT / "scenes" / "*.toml")))
MALFORMED = sorted(glob.glob(str(ROOT / "tests" / "scenes" / "malformed" / "*.toml")))


def _expectations(path):
    head = Path(path).read_text().splitlines()[:2]
    key = re.match(r"# expect-key: (.*)", head[0]).group(1).strip()
    reason = re.match(r"# expect-reason: (.*)", head[1]).group(1).strip()
    return key, reason


def test_corpus_is_large_enough():
    assert len(MALFORMED) >= 20


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: Path(p).stem)
def test_shipped_scene_validates(path):
    scene = load_scene(path)
    assert scene.length > 0 and scene.supports and scene.loads


def test_required_shipped_scenes_exist():
    names = {Path(p).stem for p in SHIPPED}
    required = {"default", "paper-fig4-bonded-3pb", "paper-fig5-top-debond-40-load-top",
                "paper-fig6-top-debond-20-load-bottom"}
    required |= {f"paper-fig7-cantilever-c{i}" for i in range(1, 5)}
    required |= {f"paper-fig9-clamped-d{d}" for d in (0, 10, 16, 20, 30, 40)}
    assert required <= names


@pytest.mark.parametrize("path", MALFORMED, ids=lambda p: Path(p).stem)
def test_malformed_scene_is_refused(path):
    key, reason = _expectations(path)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    problems = info.value.problems
    assert all(p.file == path for p in problems)
    hits = [p for p in problems if p.key == key and reason in p.reason]
    assert hits, f"expected a problem at {key!r} with {reason!r}; got {[str(p) for p in problems]}"


@pytest.mark.parametrize("path", MALFORMED[:5], ids=lambda p: Path(p).stem)
def test_cli_refuses_with_exit_code_2_and_no_traceback(path, capsys):
    code = main(["validate", path])
    err = capsys.readouterr().err
    assert code == 2
    assert "Traceback" not in err
    key, _ = _expectations(path)
    assert f"{path}: {key}:" in err


def test_fig9_periodic_debonds_are_symmetric_and_bonded_at_midspan():
    scene = load_scene(ROOT / "scenes" / "paper-fig9-clamped-d16.toml")
    for itf in ("top", "bottom"):
        spans = sorted((d.start, d.end) for d in scene.debonds_on(itf))
        mirrored = sorted((300 - b, 300 - a) for a, b in spans)
        assert [v for s in spans for v in s] == pytest.approx([v for s in mirrored for v in s])
        assert scene.is_bonded(itf, 150.0)
        assert all(b - a <= 16 + 1e-9 for a, b in spans)


def test_debond_reaching_a_beam_end_is_open_there_and_bonded_at_its_tip():
    """A debond that reaches a beam end has one tip (bonded) and an open mouth (not bonded)."""
    scene = load_scene(ROOT / "scenes" / "paper-fig7-cantilever-c2.toml")  # top debond 0-40
    assert not scene.is_bonded("top", 0.0)  # mouth at the clamped end
    assert not scene.is_bonded("top", 20.0)
    assert scene.is_bonded("top", 40.0)  # the tip
    assert scene.is_bonded("bottom", 0.0)
    zero = dataclasses.replace(scene, debonds=(Debond("top", 0.0, 0.0),))
    assert zero.is_bonded("top", 0.0)  # a zero-length debond is bonded


def test_the_accuracy_table_sets_the_tolerances_and_what_is_estimated(tmp_path):
    """``[accuracy] load`` is the beam's load tolerance too; ``false`` turns a kind off."""
    text = (ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml").read_text()
    path = tmp_path / "s.toml"
    path.write_text(text + "\n[accuracy]\nload = 0.02\nG = false\nstresses = 0.1\n")
    sc = load_scene(path)
    assert sc.beam_model.tolerance == 0.02
    assert (sc.accuracy.load, sc.accuracy.G, sc.accuracy.stresses) == (0.02, None, 0.1)
    assert not sc.accuracy.estimate_G and sc.accuracy.estimate_stresses
    plain = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    assert plain.accuracy.estimate_G and plain.accuracy.load is None


def test_the_digest_keeps_a_default_accuracy_out_and_a_given_one_in():
    """A scene without ``[accuracy]`` keeps the digest it had before the table existed (the
    scene's mechanical content only); a given one changes it (it decides the beam's levels)."""
    from sandwich.results import scene_digest
    from sandwich.scene import Accuracy

    sc = load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml")
    fields = [f.name for f in dataclasses.fields(sc)]
    assert fields[-2:] == ["accuracy", "source"]
    before = dataclasses.make_dataclass("Before", [(f, object) for f in fields[:-2]])
    assert scene_digest(sc) == scene_digest(before(**{f: getattr(sc, f) for f in fields[:-2]}))
    assert scene_digest(dataclasses.replace(sc, accuracy=Accuracy(G=0.05))) != scene_digest(sc)
