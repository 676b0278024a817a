"""The registry's code digest covers real sources: every path a model names exists."""

from pathlib import Path

import pytest

from sandwich.models.registry import MODELS

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_package_a_model_names_exists(name):
    missing = [p for p in MODELS[name].packages if not (ROOT / p).exists()]
    assert not missing, missing
