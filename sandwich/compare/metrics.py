"""``metrics.json``: how far the beam model is from the 2D reference on one scene, and at what cost.

Definitions (all relative errors are of the beam against the 2D reference):

- path curves: the load factor and every probe other than the abscissa, as functions of the
  magnitude of the path parameter (:func:`sandwich.compare.paths.path_parameter`), compared over the
  common range with :func:`sandwich.compare.paths.curve_error` (L2 and max, both relative);
- profiles: face deflections, interface σzz and core τ along x at the last common path level
  (:func:`sandwich.compare.profiles.choose_common`), same two errors over the common x range;
- peaks: the largest-magnitude value of each stress profile, error of its magnitude, sign, shift;
  at crack tips and at a clamped face over a free core the 2D stress is singular, so its raw peak
  depends on the mesh: ``peaks_windowed`` compares the peaks of the stresses averaged over
  ``PEAK_WINDOW`` mm (a force per unit length over that window, which converges);
- limit loads: maxima of the load factor that the path falls from (detected on each history), and
  those the model itself reported;
- critical loads: the first load maximum and the first bifurcation each model reported (located
  within their step where the model located them), and the beam's error on each kind that both
  models reached (:class:`CriticalLoadError`);
- energy release rate: G along the path at every debond tip both models report
  (:mod:`sandwich.compare.releases`: L2/max error of G, beam/2D ratio and each model's G_II/G at the
  end of the common range);
- cost: wall time and DOFs of each model, and the 2D / beam ratios.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, is_dataclass

from sandwich.compare.pair import BEAM, REFERENCE
from sandwich.compare.paths import (
    LOAD,
    CurveError,
    crushed_state,
    curve_error,
    limit_loads,
    path_curve,
    series,
)
from sandwich.compare.profiles import (
    DEFLECTIONS,
    STRESSES,
    ChosenProfile,
    PeakError,
    choose_common,
    peak_error,
    profile_error,
)
from sandwich.compare.releases import ReleaseAgreement, release_agreements
from sandwich.models import ModelRun
from sandwich.results import Solution
from sandwich.results.peaks import PEAK_WINDOW

CRITICAL_KINDS = ("bifurcation", "max")  # the critical points compared, in this order


@dataclass(frozen=True)
class LimitLoad:
    """A load maximum on a path: step, load factor, probes there."""

    step: int
    load_factor: float
    probes: dict[str, float]


@dataclass(frozen=True)
class CriticalLoad:
    """A critical point a model reported: a load maximum or a bifurcation of its path."""

    kind: str  # "max" | "bifurcation"
    step: int
    load_factor: float
    probes: dict[str, float]
    located: bool  # located within its step (else: the converged state that ends the step)


@dataclass(frozen=True)
class CriticalLoadError:
    """The first critical load of one kind in both models, and the beam's relative error."""

    kind: str  # "max" | "bifurcation"
    load_factor: dict[str, float]  # by model
    relative_error: float  # (beam − 2D) / |2D|


@dataclass(frozen=True)
class ModelSummary:
    """What one model did on the scene."""

    model: str
    origin: str  # "run" | "reused" | "missing" | "failed"
    reason: str
    converged: bool | None
    message: str
    steps: int
    final_load_factor: float | None
    wall_seconds: float | None
    dofs: int | None
    limit_loads: list[LimitLoad]  # detected on the history
    reported_limit_loads: list[LimitLoad]  # as the model reported them (kind "max")
    critical_loads: list[CriticalLoad] = field(default_factory=list)  # maxima and bifurcations
    warnings: list[str] = field(default_factory=list)  # the model's, as its summary.json has them

    def first_critical(self, kind: str) -> CriticalLoad | None:
        """The first reported critical point of ``kind`` ("max" or "bifurcation") on the path."""
        return next((c for c in self.critical_loads if c.kind == kind), None)


@dataclass
class Metrics:
    """Everything ``metrics.json`` holds; ``None`` marks what could not be computed."""

    scene: str
    abscissa: str
    models: dict[str, ModelSummary]
    curves: list[CurveError] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    profile_levels: dict[str, dict[str, float]] = field(default_factory=dict)
    profiles: list[CurveError] = field(default_factory=list)
    peaks: list[PeakError] = field(default_factory=list)
    peaks_windowed: list[PeakError] = field(default_factory=list)
    peak_window: float = 0.0  # mm, width of the averaging window of ``peaks_windowed``
    releases: list[ReleaseAgreement] = field(default_factory=list)  # G per debond tip
    first_limit_load_error: float | None = None
    critical_loads: list[CriticalLoadError] = field(default_factory=list)  # first of each kind
    wall_ratio: float | None = None  # 2D wall time / beam wall time
    dofs_ratio: float | None = None  # 2D DOFs / beam DOFs

    @property
    def complete(self) -> bool:
        """True when both models gave a solution."""
        return all(m.origin in ("run", "reused") for m in self.models.values())

    def curve(self, quantity: str) -> CurveError | None:
        """The path-curve error of ``quantity`` (``"load_factor"`` or a probe name)."""
        return next((c for c in self.curves if c.quantity == quantity), None)

    def release(self, tip: str) -> ReleaseAgreement | None:
        """The G agreement at ``tip`` (``"<debond>_<tip>"``)."""
        return next((r for r in self.releases if r.tip == tip), None)

    def profile(self, column: str) -> CurveError | None:
        """The profile error of ``column``."""
        return next((c for c in self.profiles if c.quantity == column), None)

    def to_dict(self) -> dict[str, object]:
        """A JSON-ready dict (non-finite numbers become ``None``)."""
        out = _clean(asdict(self))
        out["complete"] = self.complete
        return out  # type: ignore[return-value]


def _clean(value: object) -> object:
    if is_dataclass(value):
        value = asdict(value)  # type: ignore[arg-type]
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return value


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def summarize(run: ModelRun) -> ModelSummary:
    """Summarise one model's run (with or without a solution)."""
    s = run.solution
    if s is None:
        return ModelSummary(run.model, run.origin, run.reason, None, "", 0, None, None, None, [],
                            [])
    load = series(s, LOAD)
    detected = [LimitLoad(s.history[i].step, float(load[i]), dict(s.history[i].probes))
                for i in limit_loads(load)]
    reported = [LimitLoad(lp.step, lp.load_factor, dict(lp.probes))
                for lp in s.limit_points if lp.kind == "max"]
    critical = [CriticalLoad(lp.kind, lp.step, float(lp.load_factor), dict(lp.probes),
                             lp.located_at is not None)
                for lp in s.limit_points
                if lp.kind in CRITICAL_KINDS and math.isfinite(lp.load_factor)]
    return ModelSummary(run.model, run.origin, run.reason, s.converged, s.message,
                        len(s.history), _finite(s.final_load_factor), _finite(s.wall_seconds),
                        s.dofs, detected, reported, critical, list(s.warnings))


def crushed_note(model: str, sol: Solution) -> str:
    """A note where ``sol``'s core crushed as a material (:func:`crushed_state`), else ""."""
    r = crushed_state(sol)
    if r is None:
        return ""
    return (f"{model}: its core crushed as a material at step {r.step} "
            f"(λ {r.load_factor:.6g}; the St Venant-Kirchhoff core lost ellipticity): a "
            "limit load at or after it is that material limit, not the structure's, and "
            "a model whose core does not localise (the beam) goes on "
            "(docs/reference2d.md, \"Where the core crushes\")")


def _ratio(num: float | None, den: float | None) -> float | None:
    if num is None or den is None or den == 0 or not math.isfinite(num / den):
        return None
    return num / den


def compute_metrics(scene_name: str, runs: dict[str, ModelRun], abscissa: str) -> Metrics:
    """Build the :class:`Metrics` of the beam run against the 2D run on one scene."""
    metrics = Metrics(scene_name, abscissa, {m: summarize(r) for m, r in runs.items()})
    beam, ref = runs[BEAM].solution, runs[REFERENCE].solution
    if beam is None or ref is None or not beam.history or not ref.history:
        for m, r in runs.items():
            if r.solution is None:
                metrics.notes.append(f"{m}: {r.reason}")
            elif not r.solution.history:
                metrics.notes.append(f"{m}: no converged step")
        return metrics
    quantities = [LOAD, *[p for p in ref.history[0].probes if p in beam.history[0].probes]]
    for q in quantities:
        if q == abscissa:
            continue
        c_ref, note_ref = path_curve(ref, abscissa, q)
        c_beam, note_beam = path_curve(beam, abscissa, q)
        metrics.notes.extend(n for n in (note_ref, note_beam) if n and n not in metrics.notes)
        metrics.curves.append(curve_error(c_ref, c_beam, q, f"|{abscissa}|"))
    _profile_metrics(metrics, beam, ref, abscissa)
    metrics.notes.extend(n for n in (crushed_note(REFERENCE, ref), crushed_note(BEAM, beam)) if n)
    metrics.releases = release_agreements(beam, ref, abscissa)
    lb, lr = metrics.models[BEAM].limit_loads, metrics.models[REFERENCE].limit_loads
    if lb and lr:
        metrics.first_limit_load_error = (lb[0].load_factor - lr[0].load_factor) / abs(
            lr[0].load_factor)
    mb, mr = metrics.models[BEAM], metrics.models[REFERENCE]
    metrics.critical_loads = critical_load_errors(mb, mr)
    metrics.wall_ratio = _ratio(mr.wall_seconds, mb.wall_seconds)
    metrics.dofs_ratio = _ratio(mr.dofs, mb.dofs)
    return metrics


def critical_load_errors(beam: ModelSummary, ref: ModelSummary) -> list[CriticalLoadError]:
    """The first bifurcation and the first load maximum of both models, where both reached one."""
    out = []
    for kind in CRITICAL_KINDS:
        b, r = beam.first_critical(kind), ref.first_critical(kind)
        if b is None or r is None or r.load_factor == 0:
            continue
        out.append(CriticalLoadError(kind, {BEAM: b.load_factor, REFERENCE: r.load_factor},
                                     (b.load_factor - r.load_factor) / abs(r.load_factor)))
    return out


def critical_lines(metrics: Metrics, total_force: float) -> list[str]:
    """One console line per critical kind that a model reported: loads in N and the error."""
    names = {"bifurcation": "first bifurcation", "max": "first load maximum"}
    lines = []
    for kind in CRITICAL_KINDS:
        found = {m: s.first_critical(kind) for m, s in metrics.models.items()}
        if not any(found.values()):
            continue
        parts = [f"{m} {total_force * c.load_factor:.5g} N (λ {c.load_factor:.5g})"
                 if c is not None else f"{m} none" for m, c in found.items()]
        err = next((e for e in metrics.critical_loads if e.kind == kind), None)
        tail = f": beam {100 * err.relative_error:+.2f} % on 2D" if err is not None else ""
        lines.append(f"{names[kind]}: " + ", ".join(parts) + tail)
    return lines


def _profile_metrics(metrics: Metrics, beam: Solution, ref: Solution, abscissa: str) -> None:
    chosen = choose_common([ref, beam], abscissa)
    if chosen is None:
        metrics.notes.append("profiles: a model wrote no profile; no profile comparison")
        return
    c_ref, c_beam = chosen
    metrics.profile_levels = {c.model: _level_dict(c) for c in chosen}
    for col in (*DEFLECTIONS, *STRESSES):
        metrics.profiles.append(profile_error(c_ref.profile, c_beam.profile, col))
    metrics.peak_window = PEAK_WINDOW
    for col in STRESSES:
        pe = peak_error(c_ref.profile, c_beam.profile, col)
        if pe is not None:
            metrics.peaks.append(pe)
        pw = peak_error(c_ref.profile, c_beam.profile, col, window=PEAK_WINDOW)
        if pw is not None:
            metrics.peaks_windowed.append(pw)


def _level_dict(c: ChosenProfile) -> dict[str, float]:
    return {"step": float(c.profile.step), "level": c.level, "load_factor": c.load_factor}
