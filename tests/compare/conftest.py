"""Fixtures of the comparison tests: a private fig5 scene and the synthetic factories.

The synthetic solutions themselves are in ``cmp_synthetic.py`` (a plain module the tests import).
"""

import dataclasses
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest
from cmp_synthetic import (
    ROOT,
    TIPS,
    W_END,
    C,
    K,
    analytic_limit,
    fake_solvers,
    load_of,
    make_solution,
    scene_copy,
)

from sandwich.models import registry
from sandwich.scene_file import load_scene


@pytest.fixture
def scene_file(tmp_path: Path) -> Path:
    """A private copy of the fig5 scene (its mtime is the test's to control)."""
    dst = tmp_path / "scene.toml"
    shutil.copy(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml", dst)
    return dst


@pytest.fixture
def scene(scene_file: Path):
    return load_scene(scene_file)


@pytest.fixture
def synth():
    """The synthetic factories of this module."""
    return SimpleNamespace(make_solution=make_solution, scene_copy=scene_copy,
                           fake_solvers=fake_solvers,
                           analytic_limit=analytic_limit, load_of=load_of, K=K, C=C,
                           W_END=W_END, TIPS=TIPS)


@pytest.fixture
def fake_models(monkeypatch, synth):
    """Registry models answering with the synthetic solutions; returns the list of calls."""
    calls = []
    solvers = synth.fake_solvers(0.03, calls=calls)
    for name in ("beam", "2d"):
        monkeypatch.setitem(registry.MODELS, name,
                            dataclasses.replace(registry.MODELS[name], solve=solvers[name]))
    return calls
