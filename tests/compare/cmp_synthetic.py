"""Synthetic solutions with known answers, for testing the harness without any model.

The 2D "reference" path: the until probe w goes 0 → −15 mm and the load factor follows
λ(w) = K|w| − C|w|³, which rises to a maximum at |w| = sqrt(K / 3C) of λ = (2K/3) sqrt(K / 3C)
and then falls. The "beam" is the same analytic path scaled by (1 + ε), sampled on other steps.
"""

import math
import shutil
from pathlib import Path

import numpy as np

from sandwich.results import LimitPoint, Profile, Solution, StepRecord
from sandwich.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[2]
K, C = 10.0, 0.02  # N/mm, N/mm³
W_END = -15.0
LENGTH = 300.0
TIPS = (130.0, 170.0)  # the fig5 scene's top debond


def analytic_limit() -> tuple[float, float]:
    """(|w|, λ) at the analytic maximum of λ(w) = K|w| − C|w|³."""
    w = math.sqrt(K / (3 * C))
    return w, 2 * K / 3 * w


def load_of(w: np.ndarray) -> np.ndarray:
    a = np.abs(w)
    return K * a - C * a**3


def profile_columns(n_x: int, w_end: float, scale: float) -> dict[str, np.ndarray]:
    x = np.linspace(0.0, LENGTH, n_x)
    bump = lambda x0: np.exp(-(((x - x0) / 3.0) ** 2))  # noqa: E731
    return {
        "x": x,
        "w_top": scale * w_end * np.sin(np.pi * x / LENGTH),
        "w_bottom": scale * 0.9 * w_end * np.sin(np.pi * x / LENGTH),
        "sigma_zz_top": scale * (2.0 * bump(TIPS[0]) + 2.0 * bump(TIPS[1])
                                 - 0.5 * np.exp(-(((x - 150.0) / 10.0) ** 2))),
        "sigma_zz_bottom": scale * -0.3 * np.sin(np.pi * x / LENGTH),
        "tau_core": scale * 0.1 * np.cos(np.pi * x / LENGTH),
        "p_contact_top": np.zeros_like(x),
    }


def make_solution(model: str, *, eps: float = 0.0, n_steps: int = 150, n_x: int = 301,
                  wall: float = 1.0, dofs: int = 100, probe_eps: float | None = None,
                  profile_steps: tuple[int, ...] = (-1,), scene: str = "synthetic",
                  progress=None, load_fn=None, columns: dict | None = None,
                  drop: tuple[str, ...] = ()) -> Solution:
    """A synthetic path and profiles; ``eps`` scales load and profiles by (1 + eps).

    ``load_fn(|w|)`` replaces λ(w); ``columns`` maps profile names to functions of x that
    replace (or add) columns; ``drop`` removes optional columns.
    """
    probe_eps = eps if probe_eps is None else probe_eps
    w = np.linspace(0.0, W_END, n_steps + 1)[1:]
    lam = (1 + eps) * (load_of(w) if load_fn is None else load_fn(np.abs(w)))
    history = []
    for i, (wi, li) in enumerate(zip(w, lam, strict=True)):
        rec = StepRecord(step=i + 1, load_factor=float(li),
                         probes={"w_top_mid": float(wi),
                                 "w_bottom_mid": float((1 + probe_eps) * 0.9 * wi)},
                         iterations=3 + i % 2, extra={"cuts": float(i % 3 == 0)})
        history.append(rec)
        if progress is not None:
            progress(rec)
    profiles = []
    for k in profile_steps:
        cols = profile_columns(n_x, history[k].probes["w_top_mid"], 1 + eps)
        for name, fn in (columns or {}).items():
            cols[name] = fn(cols["x"])
        for name in drop:
            cols.pop(name)
        profiles.append(Profile(step=history[k].step, columns=cols))
    # every interior load maximum, as a model reports them (none on a path still rising)
    peaks = [i for i in range(1, len(lam) - 1) if lam[i - 1] < lam[i] >= lam[i + 1]]
    limits = [LimitPoint("max", history[i].step, float(lam[i]), dict(history[i].probes))
              for i in peaks]
    return Solution(model=model, scene=scene, history=history, profiles=profiles,
                    converged=True, message="reached until probe", limit_points=limits,
                    wall_seconds=wall, dofs=dofs, extra={"level": "medium"})


def scene_copy(stem: str, folder: Path):
    """Load a private copy of ``scenes/<stem>.toml`` from ``folder``."""
    dst = folder / f"{stem}.toml"
    shutil.copy(ROOT / "scenes" / f"{stem}.toml", dst)
    return load_scene(dst)


def fake_solvers(eps: float, *, wall_beam: float = 0.5, wall_2d: float = 20.0,
                 dofs_beam: int = 2400, dofs_2d: int = 96000, calls: list | None = None,
                 per_scene=None):
    """Solve functions returning the synthetic solutions (beam = 2D × (1 + eps)).

    The beam profiles are sampled every 0.5 mm, a refinement of the 2D 1 mm stations, so that
    interpolating them onto the 2D stations is exact and the profile errors are exactly eps.
    """

    def solve_2d(scene, progress=None):
        if calls is not None:
            calls.append("2d")
        return make_solution("2d", n_steps=150, n_x=301, wall=wall_2d, dofs=dofs_2d,
                             scene=scene.name, progress=progress,
                             **(per_scene(scene) if per_scene else {}))

    def solve_beam(scene, progress=None):
        if calls is not None:
            calls.append("beam")
        return make_solution("beam", eps=eps, n_steps=97, n_x=601, wall=wall_beam,
                             dofs=dofs_beam, scene=scene.name, progress=progress,
                             **(per_scene(scene) if per_scene else {}))

    return {"2d": solve_2d, "beam": solve_beam}
