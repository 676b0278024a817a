"""The closure's tie reactions from the elements next to the tips only (``closure_support``).

:func:`sandwich.beam.fracture.tip_releases` evaluates the layers of the elements whose forces
reach the tie reactions it reads (and every contact pair), not the whole beam. Reference: the
same closure on the full internal force (``full_response`` over every element), at converged
states of the fig. 5 scene (top debond, two tips, contact closed over it) at the paper's core
and with mixed core levels (several core groups, some without a tip element).
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sandwich.beam.fracture import (
    beam_tips,
    closure_elements,
    closure_from_force,
    tip_releases,
)
from sandwich.beam.solve import run
from sandwich.scene_file import load_scene

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def _state(core):
    sc = load_scene(SCENE)
    sc = dataclasses.replace(
        sc, beam_model=dataclasses.replace(sc.beam_model, core=core, elements=120),
        analysis=dataclasses.replace(sc.analysis, until_value=-6.0))
    r = run(sc)
    assert r.solution.converged, r.solution.message
    return sc, r


@pytest.mark.parametrize("core", [1, "auto"])
def test_tip_releases_equal_the_closure_on_the_full_force(core):
    sc, r = _state(core)
    model = r.model
    tips = beam_tips(sc, model)
    assert len(tips) == 2
    if core == "auto":
        assert len(model.core) > 1  # several core groups: the restriction meets each
    for st in r.states[len(r.states) // 2:]:
        u_full = model.expand(st.u)
        f_full = model.full_response(u_full, tangent=False)[0]
        full = [closure_from_force(model, u_full, f_full, t, closure_elements(model, t))
                for t in tips]
        local = tip_releases(model, st.u, tips)
        for a, b in zip(full, local, strict=True):
            assert a.G > 0.0
            assert b.closure_length == a.closure_length
            for x, y in ((a.G, b.G), (a.GI, b.GI), (a.GII, b.GII)):
                assert y == pytest.approx(x, rel=1e-10, abs=1e-12 * a.G)


def test_the_restricted_force_is_the_full_one_at_the_tip_nodes_only():
    sc, r = _state(1)
    model = r.model
    u_full = model.expand(r.states[-1].u)
    f_full = model.full_response(u_full, tangent=False)[0]
    some = np.array([10, 11, 12])
    f_some = model.full_response(u_full, tangent=False, elements=some)[0]
    from sandwich.beam.fracture import tie_dofs

    inner = tie_dofs("top", 12)[0]  # node 12: elements 11 and 12, both kept
    assert np.allclose(f_some[inner], f_full[inner], rtol=1e-12, atol=0.0)
    edge = tie_dofs("top", 13)[0]  # node 13: element 13 left out
    assert not np.allclose(f_some[edge], f_full[edge], rtol=1e-6)
    with pytest.raises(ValueError, match="force only"):
        model.full_response(u_full, tangent=True, elements=some)


def test_the_history_takes_the_paths_columns_without_evaluating_them_again(monkeypatch):
    import sandwich.beam.fracture as fracture

    calls = []
    real = fracture.tip_releases

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(fracture, "tip_releases", counting)
    sc, r = _state(1)
    assert len(calls) == len(r.states)  # once per accepted state (the follower's columns)
    monkeypatch.undo()
    tips = beam_tips(sc, r.model)
    for s, record in zip(r.states, r.solution.history, strict=True):
        for g in tip_releases(r.model, s.u, tips):
            name = f"G_{g.debond}_{g.tip}"
            assert record.extra[name] == pytest.approx(g.G, rel=1e-12, abs=1e-300)
