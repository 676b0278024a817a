"""A bifurcation is located within its step, to second order in the step (sandwich.solver.critical).

References: closed forms. A synthetic family K(s) = Q diag(μ_i(s)) Qᵀ (Q a fixed random
orthogonal matrix) whose eigenvalue μ_1(s) = 1 − s − s²/2 crosses zero at s* = √3 − 1; the
pitchfork toys of solver_toys.py (λ_c = k1 k2 / P with the critical eigenvalue linear in λ,
λ_c = (k1 k2 + a k2²) / P with it curved).
"""

import math
from pathlib import Path

import numpy as np
import pytest
from solver_toys import CurvedPitchfork, Pitchfork, VonMisesTruss

from sandwich.solver import PathOptions, SparseFactorization, follow_path
from sandwich.solver.critical import locate_crossing

ROOT = Path(__file__).resolve().parents[2]
S_STAR = math.sqrt(3.0) - 1.0  # the zero of 1 − s − s²/2


def _family(n: int = 12, falling: bool = True, seed: int = 3):
    Q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((n, n)))
    others = np.concatenate([[-4.0], np.linspace(2.0, 9.0, n - 2)])  # one already negative

    def K(s: float) -> np.ndarray:
        mu1 = 1.0 - s - 0.5 * s * s
        mu = np.concatenate([[mu1 if falling else -mu1], others + 0.3 * s])
        return (Q * mu) @ Q.T

    return K


def _dot(a, b):
    return float(a @ b)


def _located(K, s_a: float, s_b: float, change: int) -> float | None:
    fa, fb = SparseFactorization(K(s_a)), SparseFactorization(K(s_b))
    assert fb.negative_pivots - fa.negative_pivots == change
    c = locate_crossing(fa, fb, change, K(s_a).shape[0], _dot)
    return None if c is None else s_a + c.t * (s_b - s_a)


@pytest.mark.parametrize("falling", [True, False])
def test_the_crossing_is_located_to_second_order_in_the_step(falling):
    K = _family(falling=falling)
    change = 1 if falling else -1
    errors = []
    for h in (0.4, 0.2, 0.1, 0.05):
        s_a = S_STAR - 0.3 * h  # the crossing at 0.3 of every step
        s = _located(K, s_a, s_a + h, change)
        assert s is not None
        errors.append(abs(s - S_STAR))
        assert errors[-1] < 0.1 * 0.7 * h  # reporting at the step's end is 0.7 h off
    rates = [math.log2(e0 / e1) for e0, e1 in zip(errors[:-1], errors[1:], strict=True)]
    assert all(1.8 < r < 2.2 for r in rates), (errors, rates)


def test_a_count_changed_by_three_is_not_located():
    K = _family()
    fa, fb = SparseFactorization(K(0.0)), SparseFactorization(K(1.0))
    assert locate_crossing(fa, fb, 3, 12, _dot) is None


def test_the_crossed_eigenvalue_must_change_sign_across_the_step():
    # told the count rose where it did not (both ends before the crossing): nothing located
    K = _family()
    fa, fb = SparseFactorization(K(0.0)), SparseFactorization(K(0.3))
    assert locate_crossing(fa, fb, 1, 12, _dot) is None


def _bifurcation(system, step: float):
    lam_c = system.critical_load_factor
    opts = PathOptions(control="load", until_load_factor=2.5 * lam_c, tol=1e-10,
                       initial_increment=step * lam_c, max_increment=step * lam_c,
                       min_increment=0.999 * step * lam_c)
    result = follow_path(system, opts, ["x", "y"])
    assert result.reached_target, result.message
    lp, = [p for p in result.limit_points if p.kind == "bifurcation"]
    return lam_c, lp, result


def test_a_pitchfork_whose_eigenvalue_is_linear_in_the_load_is_located_exactly():
    lam_c, lp, result = _bifurcation(Pitchfork(), 0.8)
    low, high = lp.between
    assert low < lam_c < high and high - low > 0.5 * lam_c  # a long step across it
    assert lp.load_factor == pytest.approx(lam_c, rel=1e-9)
    assert 0.0 < lp.located_at < 1.0
    # probes interpolated on the fundamental path: x = λ P / k1, y = 0
    assert lp.probes["x"] == pytest.approx(lam_c / 2.0, rel=1e-9)
    assert lp.probes["y"] == 0.0


@pytest.mark.parametrize("step", [0.8, 0.4])
def test_a_curved_pitchfork_is_located_far_inside_its_step(step):
    lam_c, lp, result = _bifurcation(CurvedPitchfork(), step)
    low, high = lp.between
    assert low < lp.load_factor < high
    at_state = abs(high - lam_c)  # where it was reported before: the state after the crossing
    assert abs(lp.load_factor - lam_c) < 0.1 * at_state  # measured: 0.04 at both steps
    assert result.states[lp.step].crossing is not None


def _follow(system, step: float, locate: bool):
    lam_c = system.critical_load_factor
    opts = PathOptions(control="arc-length", until_load_factor=2.5 * lam_c, tol=1e-10,
                       initial_increment=step * lam_c, max_increment=step * lam_c,
                       locate_critical_points=locate)
    return lam_c, follow_path(system, opts, ["x", "y"])


def test_narrowing_solves_inside_the_step_and_leaves_the_path_as_it_was():
    lam_c, plain = _follow(CurvedPitchfork(), 0.8, False)
    _, narrowed = _follow(CurvedPitchfork(), 0.8, True)
    # the same path state for state, bit for bit: the equilibria inside the step are not states
    assert len(plain.states) == len(narrowed.states)
    for a, b in zip(plain.states, narrowed.states, strict=True):
        assert a.load_factor == b.load_factor and np.array_equal(a.u, b.u)
    p, = [lp for lp in plain.limit_points if lp.kind == "bifurcation"]
    n, = [lp for lp in narrowed.limit_points if lp.kind == "bifurcation"]
    k = n.step
    assert narrowed.states[k].crossing.substeps >= 1
    low, high = n.between  # a bracket of equilibria either side, inside the step
    assert plain.states[k - 1].load_factor <= low < lam_c < high <= plain.states[k].load_factor
    assert high - low < 0.5 * (p.between[1] - p.between[0])
    assert abs(n.load_factor - lam_c) < 0.2 * abs(p.load_factor - lam_c)
    assert abs(n.load_factor - lam_c) < 2e-3 * lam_c


def test_the_scene_key_reaches_the_path_follower(tmp_path):
    from sandwich.scene_file import load_scene

    src = (ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml").read_text()
    assert load_scene(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml") \
        .analysis.locate_critical_points is False  # off by default
    path = tmp_path / "s.toml"
    path.write_text(src.replace("[analysis]", "[analysis]\nlocate_critical_points = true"))
    analysis = load_scene(path).analysis
    assert analysis.locate_critical_points is True
    assert PathOptions.from_analysis(analysis).locate_critical_points is True


def test_a_load_maximum_inside_one_step_is_located_and_narrowed():
    # one displacement step from the unloaded truss to w = 0.2, past its maximum at
    # w = 0.175 (closed form, solver_toys.VonMisesTruss.limit_points): the states (λ 0 and
    # 20.8, 1.7 % below the top) never show the maximum. The load curve's slopes at the two
    # states (sandwich.solver.extrema) turn over: the maximum is located inside the step
    # (measured: 5.9e-4 below); narrowed by equilibria inside it, to 4.8e-7
    truss = VonMisesTruss()
    (w_max, lam_max), _ = truss.limit_points()
    assert 0.0 < w_max < 0.2

    def follow(locate):
        opts = PathOptions(control="displacement", until_probe="w", until_value=0.2,
                           initial_increment=0.2, max_increment=0.2, tol=1e-10,
                           locate_critical_points=locate)
        return follow_path(VonMisesTruss(), opts, ["w"])

    plain, narrowed = follow(False), follow(True)
    assert [s.load_factor for s in plain.states] == [s.load_factor for s in narrowed.states]
    assert len(plain.states) == 2 and plain.states[1].load_factor < (1 - 0.01) * lam_max
    p, = plain.limit_points
    assert p.kind == "max" and p.step == 1 and 0.0 < p.located_at < 1.0
    assert p.load_factor == pytest.approx(lam_max, rel=2e-3)
    assert p.probes["w"] == pytest.approx(w_max, rel=0.02)
    n, = narrowed.limit_points
    assert n.kind == "max"
    assert n.load_factor == pytest.approx(lam_max, rel=1e-5)
    assert n.probes["w"] == pytest.approx(w_max, rel=1e-3)
    # the fraction of the step's probe change (w from 0 to 0.2)
    assert p.located_at == pytest.approx(w_max / 0.2, rel=0.02)
    assert n.located_at == pytest.approx(w_max / 0.2, rel=1e-3)
    assert abs(n.load_factor - lam_max) < 0.01 * abs(p.load_factor - lam_max)
