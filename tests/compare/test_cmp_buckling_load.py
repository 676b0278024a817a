"""The local-buckling load of a path (:func:`sandwich.compare.claims.buckling_load`): the first
reported critical point, else the first load maximum, else the knee where the step stiffness
falls below 20 % of the first.

Reference values by construction: piecewise-linear load paths whose kink is known exactly.
"""

from types import SimpleNamespace as NS

import numpy as np

from sandwich.compare.claims import KNEE_FRACTION, buckling_load


def _cmp(w, lam, limits=(), critical=()):
    history = [NS(load_factor=float(a), probes={"w_tip": -float(b)})
               for b, a in zip(w, lam, strict=True)]
    model = NS(limit_loads=[NS(load_factor=v) for v in limits], critical_loads=list(critical))
    return NS(scene=NS(analysis=NS(until_probe="w_tip")),
              solutions={"beam": NS(history=history)},
              metrics=NS(models={"beam": model}))


def test_knee_of_a_bilinear_path_is_its_kink():
    w = np.linspace(0.0, 10.0, 21)  # kink at w = 4 is a state
    lam = np.where(w <= 4.0, 10.0 * w, 40.0 + 1.0 * (w - 4.0))  # 10 % of the first stiffness
    assert buckling_load(_cmp(w, lam), "beam") == (40.0, "knee")


def test_no_knee_when_the_softening_stays_above_the_fraction():
    w = np.linspace(0.0, 10.0, 21)
    soft = 2.0 * KNEE_FRACTION * 10.0  # stiffness after the kink: twice the threshold
    lam = np.where(w <= 4.0, 10.0 * w, 40.0 + soft * (w - 4.0))
    value, why = buckling_load(_cmp(w, lam), "beam")
    assert value is None and "no knee" in why


def test_a_load_maximum_takes_precedence():
    w = np.linspace(0.0, 10.0, 21)
    lam = np.where(w <= 4.0, 10.0 * w, 40.0 + 1.0 * (w - 4.0))
    assert buckling_load(_cmp(w, lam, limits=(55.0,)), "beam") == (55.0, "max")


def test_a_probe_that_turns_back_gives_no_knee():
    w = np.array([0.0, 1.0, 2.0, 1.5, 3.0])
    lam = np.array([0.0, 10.0, 20.0, 21.0, 22.0])
    value, why = buckling_load(_cmp(w, lam), "beam")
    assert value is None and "not monotonic" in why


def test_a_reported_critical_point_takes_precedence_the_earliest_first():
    w = np.linspace(0.0, 10.0, 21)
    lam = np.where(w <= 4.0, 10.0 * w, 40.0 + 1.0 * (w - 4.0))
    critical = (NS(kind="max", step=12, load_factor=47.0), NS(kind="bifurcation", step=8,
                                                             load_factor=38.5))
    got = buckling_load(_cmp(w, lam, limits=(55.0,), critical=critical), "beam")
    assert got == (38.5, "bifurcation")
