"""``BeamModel.correction_limit``: how far a Newton correction may carry open contact pairs.

The reference is the pairs' own linearised gaps (``contact.gap_change``, whose gradient the
tangent tests check against finite differences): the fraction α returned must put the deepest
open pair exactly at −``penetration_bound()`` along the correction, leave pairs already in the
penalty's linear range alone, and be 1 where no open pair goes that deep.
"""

import numpy as np
import pytest
from beam_scenes import Debond, sandwich_scene  # noqa: I001

from sandwich.beam import build_model
from sandwich.beam.contact import gap_change
from sandwich.beam.contact_law import SHIFT
from sandwich.beam.dofs import CONTACT_DOFS, global_dof


@pytest.fixture(scope="module", params=["closest-point", "same-x"])
def model(request):
    scene = sandwich_scene(length=60.0, elements=16, debonds=(Debond("top", 15.0, 45.0),))
    return build_model(scene, contact_search=request.param)


def _press(model, depth):
    """A correction moving every untied top-face node down by ``depth`` mm (into the core)."""
    nodes = model.pairs[0].nodes if len(model.pairs) == 1 else np.concatenate(
        [p.nodes for p in model.pairs])
    du_full = np.zeros(model.dof_map.n_full)
    du_full[global_dof(nodes, CONTACT_DOFS["top"]["w_face"])] = -depth
    free = model.dof_map.free
    du = np.zeros(model.size)
    live = free >= 0
    np.add.at(du, free[live], model.dof_map.sign[live] * du_full[live])
    return du


def _gaps(model, u, du):
    u_full, du_full = model.expand(u), model.expand(du)
    parts = [gap_change(p, u_full, du_full) for p in model.pairs]
    return np.concatenate([g for g, _ in parts]), np.concatenate([d for _, d in parts])


def test_an_open_pair_stops_at_the_penetration_bound(model):
    u = np.zeros(model.size)  # every pair at g = 0: open, on the law's tail
    du = _press(model, 0.2)
    g, dg = _gaps(model, u, du)
    assert np.all(dg < -0.1)  # the correction presses every pair 0.2 mm in
    alpha = model.correction_limit(u, du)
    bound = model.penetration_bound()
    assert 0 < alpha < 1
    assert np.min(g + alpha * dg) == pytest.approx(-bound, rel=1e-9)


def test_a_shallow_or_opening_correction_is_not_shortened(model):
    u = np.zeros(model.size)
    bound = model.penetration_bound()
    assert model.correction_limit(u, _press(model, 0.5 * bound)) == 1.0  # within the bound
    assert model.correction_limit(u, _press(model, -0.3)) == 1.0  # lifts the face off
    assert model.correction_limit(u, np.zeros(model.size)) == 1.0


def test_pairs_in_the_penalty_range_are_left_to_newton(model):
    """Pairs already pressed beyond the law's knee (g < −c s) carry the penalty stiffness in
    the tangent: a correction pressing them further is not shortened."""
    depth = 4 * SHIFT * model.smoothing
    u = _press(model, depth)  # the state: every pair pressed past the knee
    g, _ = _gaps(model, u, np.zeros(model.size))
    assert np.all(g < -SHIFT * model.smoothing)
    assert model.correction_limit(u, _press(model, 0.2)) == 1.0
