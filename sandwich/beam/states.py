"""A converged equilibrium state of a beam model, as the analyses hand them on."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ConvergedState:
    """A converged equilibrium state on the free DOFs."""

    step: int
    load_factor: float
    u: np.ndarray
    iterations: int
    probes: dict[str, float]
    extra: dict[str, float | None] = field(default_factory=dict)  # the path's state columns
