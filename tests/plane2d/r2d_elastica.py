"""The elastica of a cantilever under a dead transverse tip load (reference for the tests).

EI θ'' = P cos θ on 0 ≤ s ≤ L, θ(0) = 0, θ'(L) = 0 (no tip moment); θ is the slope, negative
downwards. In s/L and α = P L²/(EI): θ'' = α cos θ. Solved by shooting on θ'(0) with scipy.
"""

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def _shoot(kappa0, alpha):
    def rhs(s, y):  # y = (θ, θ', x, z)
        th, dth, _, _ = y
        return [dth, alpha * np.cos(th), np.cos(th), np.sin(th)]

    return solve_ivp(rhs, (0.0, 1.0), [0.0, kappa0, 0.0, 0.0], rtol=1e-12, atol=1e-12)


def elastica_tip(alpha):
    """(vertical tip deflection / L (positive down), horizontal shortening / L, tip rotation)."""
    # at small α the root curvature is −α; the root curvature magnitude never exceeds α
    kappa0 = brentq(lambda k: _shoot(k, alpha).y[1, -1], -alpha * (1 + 1e-9), -1e-12,
                    xtol=1e-14)
    y = _shoot(kappa0, alpha).y[:, -1]
    return -y[3], 1.0 - y[2], y[0]
