"""``compare``: both models on one scene, written into one folder.

Overlay figures (PNG + CSV each), G at every debond tip along the path (``G_<tip>.png``,
``energy_release.csv``), the interface tractions ahead of each tip (``tip_tractions.csv``),
deformed pictures and ``metrics.json``; where debonds grow, the growth envelopes
(:mod:`sandwich.compare.growth`).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sandwich.compare.deformed import draw_face_lines, draw_picture, last_picture, shared_view
from sandwich.compare.face_lines import face_lines
from sandwich.compare.growth import growth_figures
from sandwich.compare.metrics import Metrics, compute_metrics
from sandwich.compare.pair import BEAM, PAIR, REFERENCE
from sandwich.compare.paths import LOAD, Curve, limit_loads, path_parameter, series
from sandwich.compare.plots import Panel, overlay
from sandwich.compare.profiles import ChosenProfile, choose_common
from sandwich.compare.releases import release_curve, tips
from sandwich.compare.tip_tractions import write_tip_tractions
from sandwich.models import ModelRun, Progress, Solver, obtain
from sandwich.results import Solution, atomic_write_text
from sandwich.scene import Scene
from sandwich.scene_file import load_scene


@dataclass
class Comparison:
    """The outcome of :func:`compare` on one scene."""

    scene: Scene
    out_dir: Path
    runs: dict[str, ModelRun]
    metrics: Metrics
    figures: list[Path] = field(default_factory=list)
    tables: list[Path] = field(default_factory=list)
    chosen_profiles: dict[str, ChosenProfile] = field(default_factory=dict)

    @property
    def solutions(self) -> dict[str, Solution]:
        """The solutions that exist, by model."""
        return {m: r.solution for m, r in self.runs.items() if r.solution is not None}

    @property
    def missing(self) -> dict[str, str]:
        """Models without a solution, with the reason."""
        return {m: r.reason for m, r in self.runs.items() if r.solution is None}


def model_folder(scene: Scene, model: str, out_dir: Path,
                 results_root: str | Path | None = None) -> Path:
    """Where ``model``'s result of ``scene`` lives.

    ``<results_root>/<scene>/<model>/``, or ``<out_dir>/<model>/`` without a results root.
    """
    if results_root is None:
        return Path(out_dir) / model
    return Path(results_root) / scene.name / model


def total_force(scene: Scene) -> float:
    """Σ|force| of the scene's loads (N): the load is P = λ · Σ|F|."""
    return float(sum(abs(ld.force) for ld in scene.loads)) or 1.0


def _debond_spans(scene: Scene, interface: str | None = None) -> list[tuple[float, float]]:
    return [(d.start, d.end) for d in scene.debonds
            if (interface is None or d.interface == interface) and d.length > 0]


def _critical_markers(cmp: Comparison, model: str, probe: str, scale: float
                      ) -> list[tuple[str, float, float]]:
    """Markers (label, probe value, load in N) at the first bifurcation and maximum of ``model``."""
    summary = cmp.metrics.models.get(model)
    if summary is None:
        return []
    firsts = [c for kind in ("bifurcation", "max")
              if (c := summary.first_critical(kind)) is not None and probe in c.probes]
    return [(f"{model} first {c.kind} {scale * c.load_factor:.4g} N", float(c.probes[probe]),
             scale * c.load_factor) for c in firsts]


def _path_figures(cmp: Comparison) -> None:
    scale = total_force(cmp.scene)
    sols = cmp.solutions
    for probe in cmp.scene.probes:
        curves, markers = [], []
        for model in (REFERENCE, BEAM):
            s = sols.get(model)
            if s is None or not s.history or probe.name not in s.history[0].probes:
                continue
            load = series(s, LOAD) * scale
            w = series(s, probe.name)
            curves.append(Curve(f"{model}", w, load))
            markers += _critical_markers(cmp, model, probe.name, scale)
            if not cmp.metrics.models[model].critical_loads:  # maxima seen on the history only
                markers += [(f"{model} max", float(w[i]), float(load[i]))
                            for i in limit_loads(load)]
        until = " (path parameter)" if probe.name == cmp.scene.analysis.until_probe else ""
        panel = Panel("load P (N)", curves, markers=markers)
        png, csv_ = overlay(cmp.out_dir / f"load_{probe.name}.png", [panel],
                            f"{probe.name} (mm)", f"{cmp.scene.name}: load vs {probe.name}{until}")
        cmp.figures.append(png)
        cmp.tables.append(csv_)


def _release_figures(cmp: Comparison, abscissa: str) -> None:
    """Per debond tip: G and its split in both models against |path parameter|, + a table."""
    sols = cmp.solutions
    found = sorted({t for m in (REFERENCE, BEAM) for t in tips(sols.get(m))})
    for tip in found:
        total, parts = [], []
        for model in (REFERENCE, BEAM):
            s = sols.get(model)
            if s is None or not s.history or tip not in tips(s):
                continue
            total.append(dataclasses.replace(release_curve(s, abscissa, tip), label=model))
            parts += [dataclasses.replace(release_curve(s, abscissa, tip, p), label=f"{model} {p}")
                      for p in ("GI", "GII")]
        debond, end = tip.split("_")
        panels = [Panel("G (N/mm)", total, title=f"debond {debond}, {end} tip"),
                  Panel("G_I, G_II (N/mm)", parts, title="split (each model's own partition)")]
        unit = "" if abscissa == LOAD else " (mm)"  # a probe (mm) or the load factor
        png, csv_ = overlay(cmp.out_dir / f"G_{tip}.png", panels, f"|{abscissa}|{unit}",
                            f"{cmp.scene.name}: energy release rate vs |{abscissa}|")
        cmp.figures.append(png)
        cmp.tables.append(csv_)
    if cmp.metrics.releases:
        cmp.tables.append(_release_table(cmp))


def _release_table(cmp: Comparison) -> Path:
    """``energy_release.csv``: the agreement of G per tip (the numbers of metrics.json)."""
    def num(v: object) -> str:
        return "" if v is None else repr(float(v))  # type: ignore[arg-type]

    rows = ["tip,abscissa,common_from,common_to,l2_relative,max_relative,ratio_beam_over_2d,"
            "G_2d_at_end,G_beam_at_end,GII_over_G_2d,GII_over_G_beam,note"]
    for r in cmp.metrics.releases:
        lo, hi = r.common_range or (None, None)
        rows.append(",".join([r.tip, r.abscissa, num(lo), num(hi), num(r.l2_relative),
                              num(r.max_relative), num(r.ratio_at_end),
                              num(r.G_at_end.get(REFERENCE)), num(r.G_at_end.get(BEAM)),
                              num(r.mode_ii_share_at_end.get(REFERENCE)),
                              num(r.mode_ii_share_at_end.get(BEAM)),
                              '"' + r.note.replace('"', "'") + '"']))
    path = cmp.out_dir / "energy_release.csv"
    atomic_write_text(path, "\n".join(rows) + "\n")
    return path


def _profile_curves(chosen: Mapping[str, ChosenProfile], column: str, suffix: str = ""
                    ) -> list[Curve]:
    out = []
    for model in (REFERENCE, BEAM):
        c = chosen.get(model)
        if c is None or column not in c.profile.columns:
            continue
        x = np.asarray(c.profile.columns["x"], dtype=float)
        order = np.argsort(x, kind="stable")
        out.append(Curve(f"{model}{suffix}", x[order],
                         np.asarray(c.profile.columns[column], dtype=float)[order]))
    return out


def _level_text(chosen: Mapping[str, ChosenProfile], abscissa: str) -> str:
    return "; ".join(f"{m}: step {c.profile.step}, |{abscissa}|={c.level:.4g}, "
                     f"λ={c.load_factor:.4g}" for m, c in chosen.items())


def _profile_figures(cmp: Comparison, abscissa: str) -> None:
    chosen = cmp.chosen_profiles
    if not chosen:
        return
    sub = _level_text(chosen, abscissa)
    all_spans = _debond_spans(cmp.scene)
    figures = {
        "face_deflections": [
            Panel("w (mm)", _profile_curves(chosen, "w_top", " w_top")
                  + _profile_curves(chosen, "w_bottom", " w_bottom"), spans=all_spans)],
        "interface_stress": [
            Panel("σzz top (MPa)", _profile_curves(chosen, "sigma_zz_top"),
                  title="top face/core interface", spans=_debond_spans(cmp.scene, "top")),
            Panel("σzz bottom (MPa)", _profile_curves(chosen, "sigma_zz_bottom"),
                  title="bottom face/core interface", spans=_debond_spans(cmp.scene, "bottom"))],
        "core_shear": [Panel("τ core (MPa)", _profile_curves(chosen, "tau_core"),
                             spans=all_spans)],
    }
    for stem, panels in figures.items():
        png, csv_ = overlay(cmp.out_dir / f"{stem}.png", panels, "x (mm)",
                            f"{cmp.scene.name}: {stem.replace('_', ' ')}\n{sub}")
        cmp.figures.append(png)
        cmp.tables.append(csv_)


def _deformed_figures(cmp: Comparison) -> None:
    pictures = {model: last_picture(run.solution) for model in (REFERENCE, BEAM)
                if (run := cmp.runs.get(model)) is not None and run.solution is not None}
    drawn = {model: pic for model, pic in pictures.items() if pic is not None}
    view = shared_view(list(drawn.values()))  # one scale and colour range for both models
    for model, pic in drawn.items():
        cmp.figures.append(draw_picture(pic, cmp.out_dir / f"deformed_{model}.png", view))
    lines, titles = [], []
    for model in pictures:
        if model not in drawn and model in cmp.chosen_profiles:
            c = cmp.chosen_profiles[model]
            lines.append(face_lines(cmp.scene, c.profile, model))
            titles.append(f"{model} (faces from profiles): step {c.profile.step}, "
                          f"λ = {c.load_factor:.4g}")
    if lines:
        cmp.figures.append(draw_face_lines(lines, titles, cmp.out_dir / "deformed_faces.png"))


def compare(scene: Scene | str | Path, out_dir: str | Path, *, reuse: bool = True,
            progress: Progress | None = None, results_root: str | Path | None = None,
            solvers: Mapping[str, Solver] | None = None) -> Comparison:
    """Run (or reuse) both models on ``scene`` and write the comparison into ``out_dir``.

    Parameters
    ----------
    scene
        A :class:`~sandwich.scene.Scene` or the path of a scene file.
    out_dir
        Folder for figures (PNG + CSV each), deformed pictures and ``metrics.json``.
    reuse
        Reuse a model's result folder when the identity it records (scene content, the
        model's options and resolution, code) is the one asked now; else solve again.
    progress
        Receives a :class:`~models.ProgressEvent` per phase and converged step.
    results_root
        Root of the models' result folders (``<root>/<scene>/<model>/``); ``None``: inside
        ``out_dir`` (``<out_dir>/<model>/``), so that nothing is written outside it.
    solvers
        Replacement ``solve`` callables by model name (tests, benchmarks).

    Returns
    -------
    Comparison
        The runs, metrics and files written. A model that is missing or failed is listed in
        :attr:`Comparison.missing` and in ``metrics.json``; figures show what exists.
    """
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    solvers = dict(solvers or {})
    runs = {m: obtain(scene, m, model_folder(scene, m, out_dir, results_root), reuse=reuse,
                      progress=progress, solver=solvers.get(m)) for m in PAIR}
    present = [r.solution for r in runs.values() if r.solution is not None and r.solution.history]
    abscissa = path_parameter(scene.analysis.until_probe, present)
    metrics = compute_metrics(scene.name, runs, abscissa)
    cmp = Comparison(scene, out_dir, runs, metrics)
    if present:
        chosen = choose_common(present, abscissa)
        cmp.chosen_profiles = {c.model: c for c in chosen or []}
    _path_figures(cmp)
    _release_figures(cmp, abscissa)
    cmp.tables += write_tip_tractions(scene, cmp.chosen_profiles, out_dir)
    _profile_figures(cmp, abscissa)
    _deformed_figures(cmp)
    figures, tables = growth_figures(scene, cmp.solutions, out_dir, total_force(scene))
    cmp.figures += figures
    cmp.tables += tables
    atomic_write_text(out_dir / "metrics.json",
                      json.dumps(metrics.to_dict(), indent=2, allow_nan=False) + "\n")
    return cmp
