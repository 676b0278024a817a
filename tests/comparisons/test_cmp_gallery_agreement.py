"""``benchmarks/gallery_agreement.py`` on a synthetic gallery whose answer is known by design.

The synthetic beam is the 2D path × (1 + eps) (``cmp_synthetic.fake_solvers``), so its end load
at the common path end is +eps exactly; its load-curve L2 and max errors are eps up to the linear
interpolation, and its first maximum (near the analytic maximum of ``cmp_synthetic.load_of``) is
+eps up to the sampling (the beam's 97 steps are not the 2D's 150).
"""

import importlib.util

import pytest

from comparisons import gallery

EPS = 0.02


def _script(root):
    spec = importlib.util.spec_from_file_location("gallery_agreement",
                                                  root / "benchmarks" / "gallery_agreement.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_agreement_table_from_a_gallery_folder(tmp_path, synth):
    from cmp_synthetic import ROOT

    scenes = [synth.scene_copy("paper-fig5-top-debond-40-load-top", tmp_path)]
    gallery(scenes, tmp_path / "out", solvers=synth.fake_solvers(EPS))
    mod = _script(ROOT)
    assert mod.main([str(tmp_path / "out"), "--out", str(tmp_path / "agreement")]) == 0
    row = mod.scene_row(tmp_path / "out" / scenes[0].name)
    assert row["end_load_rel"] == pytest.approx(EPS, rel=1e-6)
    # the L2/max are metrics.json's: the beam, sampled at other |w|, is interpolated linearly
    # onto the 2D samples, which costs ~0.2 % of eps on this curved path
    assert row["load_l2"] == pytest.approx(EPS, rel=1e-2)
    assert row["load_max"] == pytest.approx(EPS, rel=1e-2)
    # the first maxima are the histories' largest sampled steps near the analytic maximum
    assert row["first_max_rel"] == pytest.approx(EPS, rel=1e-2)
    text = (tmp_path / "agreement.md").read_text()
    assert f"{100 * EPS:+.2f} %" in text and "2D trustworthy?" in text


def test_agreement_refuses_a_folder_without_comparisons(tmp_path, synth):
    from cmp_synthetic import ROOT

    assert _script(ROOT).main([str(tmp_path), "--out", str(tmp_path / "a")]) == 2
