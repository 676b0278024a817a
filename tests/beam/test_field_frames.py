"""solve() fills Solution.fields with ParaView frames of the section (faces and core on one grid).

References: the frame must reproduce the converged state it came from (its probe displacement
equals the history's probe value, by construction of the same interpolation), cover the three
regions, and keep `extra` scalar-only (the result contract writes it to summary.json).
"""

import json

import numpy as np
from beam_scenes import sandwich_scene

from sandwich.beam import run
from sandwich.scene import Analysis, BeamModelOptions


def test_field_frames_of_last_and_every_kth_step():
    scene = sandwich_scene(elements=30, analysis=Analysis(
        kind="nonlinear", control="load", until_probe="w_top_mid", until_value=-2.0))
    scene = scene.__class__(**{**scene.__dict__, "beam_model": BeamModelOptions(
        elements=30, profile_every=2)})
    result = run(scene)
    sol = result.solution
    assert sol.converged
    steps = [f.step for f in sol.fields]
    last = sol.history[-1]
    assert steps[-1] == last.step and all(s % 2 == 0 for s in steps[:-1]) and len(steps) > 1
    frame = sol.fields[-1]
    n, m = frame.points.shape[0], frame.cells.shape[0]
    assert frame.displacement.shape == (n, 2) and frame.cells.shape[1] == 4
    assert set(np.unique(frame.cell_data["region"])) == {0.0, 1.0, 2.0}
    for name in ("sigma_x", "sigma_z", "tau", "von_mises"):
        assert frame.point_data[name].shape == (n,) and np.all(np.isfinite(frame.point_data[name]))
    assert frame.cell_data["region"].shape == (m,)
    # counter-clockwise quads: positive signed area in the reference (x, z) plane
    q = frame.points[frame.cells]
    area = 0.5 * np.sum(q[:, :, 0] * np.roll(q[:, :, 1], -1, axis=1)
                        - np.roll(q[:, :, 0], -1, axis=1) * q[:, :, 1], axis=1)
    assert np.all(area > 0)
    # the top face's mid-span section moves by the recorded probe value at its mid-surface:
    # w is linear through the face, so the mean of its inner and outer surface points
    at = np.flatnonzero(np.isclose(frame.points[:, 0], 150.0)
                        & (frame.points[:, 1] >= scene.core.thickness / 2 - 1e-12))
    z = frame.points[at, 1]
    inner, outer = at[np.argmin(z)], at[np.argmax(z)]
    assert z.max() - z.min() > 0.9 * scene.top.thickness
    mid = 0.5 * (frame.displacement[inner, 1] + frame.displacement[outer, 1])
    assert np.isclose(mid, last.probes["w_top_mid"], rtol=1e-9)
    # summary.json: every extra is plain JSON without NaN (the core block is a nested table)
    json.dumps(sol.extra, allow_nan=False)
    assert all(isinstance(v, int | float | str | bool) for k, v in sol.extra.items() if k != "core")
