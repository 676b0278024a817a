"""Interface tractions near every debond tip, from a model's profiles: ``tip_tractions.csv``.

What decides whether a debond grows is the interface just ahead of its tip: the normal traction
σzz (peel, positive = tension pulling the face off the core) and the shear traction τ that the
core carries there. Both models write them in their profiles (``sigma_zz_top``/``_bottom``: the
core's S_zz at its top/bottom boundary; ``tau_top``/``_bottom``: the core's S_xz there; MPa,
second Piola–Kirchhoff, reference frame). This module cuts them out around each tip, as a
function of the distance ``s`` ahead of the tip (s > 0 bonded, s < 0 on the debond, behind the
tip), for every step the model wrote a profile at (``profile_every``; the last step always).

Columns: ``step, debond, tip, interface, s, x, sigma_zz, tau`` (mm, MPa). Window:
``AHEAD`` × the core thickness ahead and ``BEHIND`` × it behind. The stresses at the tip itself
are singular in 2D (they grow with mesh refinement) and finite in the beam: compare them a few
face thicknesses ahead, or averaged (docs/fracture.md).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass

import numpy as np

from sandwich.results.types import Profile

AHEAD = 1.0  # window ahead of the tip, in core thicknesses
BEHIND = 0.0  # window behind it (on the debond): none, the core boundary is no interface there
HEADER = ("step", "debond", "tip", "interface", "s", "x", "sigma_zz", "tau")


@dataclass(frozen=True)
class SceneTip:
    """A debond tip of a scene: where it is and which way the bonded interface lies (+1/−1)."""

    debond: int
    tip: str
    interface: str
    x: float
    ahead: int


def scene_tips(scene: object) -> list[SceneTip]:
    """Every debond end inside the beam (an end at a beam end is an open mouth, not a tip)."""
    tol = 1e-9 * scene.length
    out = []
    for i, d in enumerate(scene.debonds):
        if d.end - d.start <= tol:
            continue
        for tip, xt, ahead in (("start", d.start, -1), ("end", d.end, 1)):
            if tol < xt < scene.length - tol:
                out.append(SceneTip(i, tip, d.interface, float(xt), ahead))
    return out


def tip_rows(scene: object, profile: Profile, model: str | None = None) -> list[list[object]]:
    """The rows of one profile: every station within the window of every tip."""
    x = np.asarray(profile.columns["x"], dtype=float)
    h = float(scene.core.thickness)
    rows: list[list[object]] = []
    for t in scene_tips(scene):
        sz, tau = profile.columns.get(f"sigma_zz_{t.interface}"), profile.columns.get(
            f"tau_{t.interface}")
        if sz is None:
            continue
        s = (x - t.x) * t.ahead
        pick = np.flatnonzero((s >= -BEHIND * h) & (s <= AHEAD * h))
        pick = pick[np.argsort(s[pick], kind="stable")]
        for k in pick:
            dist = float(s[k]) + 0.0  # no "-0.0" at the tip
            row: list[object] = [profile.step, t.debond, t.tip, t.interface, repr(dist),
                                 repr(float(x[k])), _num(sz[k]),
                                 "" if tau is None else _num(tau[k])]
            rows.append(row if model is None else [model, *row])
    return rows


def _num(v: object) -> str:
    f = float(v)  # type: ignore[arg-type]
    return repr(f) if np.isfinite(f) else ""


def tip_tractions_csv(scene: object, profiles: list[Profile]) -> str:
    """``tip_tractions.csv`` of one model's profiles (header only if the scene has no tip)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(HEADER)
    for p in profiles:
        w.writerows(tip_rows(scene, p))
    return buf.getvalue()
