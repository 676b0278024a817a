"""Shared fixtures of the mesh tests: shipped scenes and their coarse meshes (built once)."""

from pathlib import Path

import pytest

from sandwich.meshes import build_mesh
from sandwich.scene_file import load_scene

SCENES = Path(__file__).resolve().parents[2] / "scenes"
FIG5 = SCENES / "paper-fig5-top-debond-40-load-top.toml"


@pytest.fixture(scope="session")
def fig5():
    return load_scene(FIG5)


@pytest.fixture(scope="session")
def fig5_mesh(fig5):
    return build_mesh(fig5, level="coarse")


@pytest.fixture(scope="session")
def coarse_meshes():
    """Every shipped scene meshed at level coarse: name -> (scene, mesh)."""
    out = {}
    for path in sorted(SCENES.glob("*.toml")):
        scene = load_scene(path)
        out[path.stem] = (scene, build_mesh(scene, level="coarse"))
    return out
