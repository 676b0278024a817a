"""An until probe whose target lies against the loads: the path gets there with λ < 0 and says so.

Toy: a linear spring ``f = k w`` under ``λ P`` (P = +1, so w = λ / k > 0 for λ > 0). A target
w = −0.5 is reached at λ = −k/2 (closed form); its warnings say that every force is reversed.
A target on the loads' side (w = +0.5, λ = +k/2) carries no warning.
"""

import numpy as np
import pytest
from solver_toys import ToySystem

from sandwich.solver import PathOptions, follow_path


class Spring(ToySystem):
    """``f(w) = k w``."""

    dof_names = ("w",)

    def __init__(self, k: float = 2.0) -> None:
        super().__init__()
        self.k = k

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.k * u

    def tangent(self, u: np.ndarray) -> np.ndarray:
        return np.array([[self.k]])


@pytest.mark.parametrize("control", ["load", "arc-length"])
@pytest.mark.parametrize("target", [-0.5, 0.5])
def test_a_target_against_the_loads_is_reached_with_a_warning(control, target):
    spring = Spring()
    r = follow_path(spring, PathOptions(control=control, until_probe="w", until_value=target,
                                        tol=1e-10), ["w"])
    assert r.reached_target
    assert r.states[-1].load_factor == pytest.approx(spring.k * target, rel=1e-6)
    warned = any("every load's force is reversed" in w for w in r.warnings)
    assert warned == (target < 0), r.warnings
    assert "reversed" not in r.message  # a warning, not the reason the path ended
