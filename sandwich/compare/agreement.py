"""Per-scene agreement of the beam with the 2D reference, read from a gallery folder.

A ``sandwich gallery --out DIR`` run writes ``DIR/<scene>/metrics.json`` and each model's result
folder (``summary.json``, ``history.csv``); :func:`scene_row` reads one scene folder into a row,
:func:`markdown` writes the table of rows. Columns per scene: where each model stopped (|until
probe| reached, λ there, steps, wall time, converged); the end load compared at the *common* end
of the path, ``w_end`` = the largest |until probe| both monotone paths reach,
λ_beam(w_end)/λ_2D(w_end) − 1 (linear interpolation in each history); the load-curve L2 and max
relative errors of ``metrics.json`` (their common range is the same); the beam's core levels
(length of x at each level) and its own error estimate; the models' messages when they did not
converge or warned. :func:`fine_check` adds, where a finer 2D run of the scene is at hand,
both models' end loads against it (so that a 2D mesh's own error is told apart from the
beam's). Pure data handling, like :mod:`sandwich.compare.paths`.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from sandwich.compare.paths import LOAD, path_curve
from sandwich.results import Solution, load_result


def _load_at(curve_x: np.ndarray, curve_y: np.ndarray, w: float) -> float | None:
    if curve_x.size < 2 or w > curve_x.max() + 1e-9:
        return None
    return float(np.interp(w, curve_x, curve_y))


def _levels(core: object) -> str:
    if not isinstance(core, dict):
        return str(core or "")
    length: dict[int, float] = {}
    for z in core.get("levels", []):
        length[z["level"]] = length.get(z["level"], 0.0) + z["end"] - z["start"]
    return " ".join(f"L{k}:{v:.0f}mm" for k, v in sorted(length.items()))


def scene_row(folder: Path, trust: Mapping[str, str] | None = None) -> dict[str, object]:
    """One table row from a gallery scene folder (``metrics.json`` + both model folders).

    ``trust`` maps scene names to the documented reading of whether the 2D model is a
    trustworthy reference there (not computed: a sentence with its sources).
    """
    metrics = json.loads((folder / "metrics.json").read_text())
    row: dict[str, object] = {"scene": folder.name, "abscissa": metrics["abscissa"]}
    curves = {}
    for model in ("beam", "2d"):
        s = metrics["models"][model]
        row[f"{model}_origin"] = s["origin"]
        row[f"{model}_converged"] = s["converged"]
        row[f"{model}_steps"] = s["steps"]
        row[f"{model}_final_load"] = s["final_load_factor"]
        row[f"{model}_wall_s"] = s["wall_seconds"]
        lims = s.get("limit_loads") or []
        row[f"{model}_first_max"] = lims[0]["load_factor"] if lims else None
        said = [s["message"]] if not s["converged"] else []
        said += [f"WARNING: {w}" for w in s.get("warnings") or []]
        row[f"{model}_message"] = "; ".join(said)
        try:
            sol = load_result(folder / model, fields=False)
        except Exception as exc:  # a missing/failed model: the row says why
            row[f"{model}_message"] = f"{s.get('reason', '')} {exc}".strip()
            continue
        if metrics["abscissa"] == LOAD:
            continue
        curve, note = path_curve(sol, metrics["abscissa"], LOAD)
        curves[model] = curve
        row[f"{model}_reach"] = float(curve.x.max()) if curve.x.size else None
        if note:
            row[f"{model}_message"] = (str(row[f"{model}_message"]) + " " + note).strip()
        if model == "beam":
            summary = json.loads((folder / model / "summary.json").read_text())
            core = summary.get("core")
            row["beam_levels"] = _levels(core)
            row["beam_estimate"] = core.get("estimated_error") if isinstance(core, dict) else None
    if len(curves) == 2:
        w_end = min(c.x.max() for c in curves.values())
        lam = {m: _load_at(c.x, c.y, w_end) for m, c in curves.items()}
        row["w_end"] = float(w_end)
        row["beam_load_at_w_end"], row["2d_load_at_w_end"] = lam["beam"], lam["2d"]
        row["end_load_rel"] = (lam["beam"] / lam["2d"] - 1.0
                               if lam["beam"] is not None and lam["2d"] else None)
    b, r = row.get("beam_first_max"), row.get("2d_first_max")
    row["first_max_rel"] = b / r - 1.0 if b is not None and r else None
    load = next((c for c in metrics["curves"] if c["quantity"] == LOAD), None)
    row["load_l2"] = load["l2_relative"] if load else None
    row["load_max"] = load["max_relative"] if load else None
    row["trust_2d"] = (trust or {}).get(folder.name, "not assessed")
    return row


def _pct(v: object, signed: bool = False) -> str:
    return "—" if v is None else (f"{100 * v:+.2f} %" if signed else f"{100 * v:.2f} %")


def _g(v: object, fmt: str = ".4g") -> str:
    return "—" if v is None else format(v, fmt)


def markdown(rows: list[dict[str, object]], source: str, header: str) -> str:
    """The Markdown report: the agreement table, then the trust column and the messages."""
    lines = ["# Beam (scene defaults, core = auto) vs 2D on the gallery scenes", "",
             f"Written by `benchmarks/gallery_agreement.py {source}`. {header}", "",
             "end load: λ_beam/λ_2D − 1 at w_end, the largest |until probe| both monotone paths "
             "reach (interpolated in each history); L2/max: the load-curve errors of "
             "`metrics.json` over the same common range; reach: |until probe| at the end of each "
             "monotone path; first max: the first load maximum detected on each history "
             "(`metrics.json` → `limit_loads`); wall: each model's `wall_seconds`.", "",
             "| scene | w_end (mm) | λ beam | λ 2D | end load | load L2 | load max | first max λ "
             "beam / 2D | beam reach / steps / wall (s) | 2D reach / steps / wall (s) | beam "
             "core levels (estimate) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        est = r.get("beam_estimate")
        lines.append(
            f"| {r['scene'].removeprefix('paper-')} | {_g(r.get('w_end'), '.3g')} | "
            f"{_g(r.get('beam_load_at_w_end'))} | {_g(r.get('2d_load_at_w_end'))} | "
            f"{_pct(r.get('end_load_rel'), True)} | {_pct(r.get('load_l2'))} | "
            f"{_pct(r.get('load_max'))} | {_g(r.get('beam_first_max'))} / "
            f"{_g(r.get('2d_first_max'))} ({_pct(r.get('first_max_rel'), True)}) | "
            f"{_g(r.get('beam_reach'), '.3g')} / "
            f"{r['beam_steps']} / {_g(r['beam_wall_s'], '.3g')} | "
            f"{_g(r.get('2d_reach'), '.3g')} / {r['2d_steps']} / {_g(r['2d_wall_s'], '.3g')} | "
            f"{r.get('beam_levels', '')} ({_pct(est)}) |")
    checked = [r for r in rows if "2d_fine_load_at_w_end" in r]
    if checked:
        lines += ["", "## Against a finer 2D mesh", "",
                  "Both models' loads at the same w_end against a finer 2D run of the scene "
                  "(its level named): the gallery's 2D mesh error next to the beam's.", "",
                  "| scene | 2D finer level | λ 2D finer | beam vs finer | gallery 2D vs finer |",
                  "|---|---|---|---|---|"]
        lines += [f"| {r['scene'].removeprefix('paper-')} | {r.get('2d_fine_level') or '—'} | "
                  f"{_g(r.get('2d_fine_load_at_w_end'))} | "
                  f"{_pct(r.get('end_load_rel_fine'), True)} | "
                  f"{_pct(r.get('2d_rel_fine'), True)} |" for r in checked]
    lines += ["", "## Is the 2D model a trustworthy reference here?", "",
              "| scene | 2D trustworthy? |", "|---|---|"]
    lines += [f"| {r['scene'].removeprefix('paper-')} | {r['trust_2d']} |" for r in rows]
    lines += ["", "## Messages (non-converged paths, warnings, cut paths)", ""]
    for r in rows:
        for m in ("beam", "2d"):
            if r.get(f"{m}_message"):
                text = " ".join(str(r[f"{m}_message"]).split())
                lines.append(f"- {r['scene'].removeprefix('paper-')}, {m}: {text}")
    return "\n".join(lines) + "\n"


def fine_check(row: dict[str, object], fine: Solution | Path) -> dict[str, object]:
    """Add to ``row`` the end loads of both models against a finer 2D run at ``w_end``.

    ``fine`` is the finer run (a :class:`~sandwich.results.Solution` or its result folder);
    it is read on the row's abscissa. New keys: ``2d_fine_level``, ``2d_fine_load_at_w_end``,
    ``end_load_rel_fine`` (beam vs fine) and ``2d_rel_fine`` (the gallery's 2D vs fine); None
    where the finer path stops short of ``w_end``.
    """
    sol = fine if isinstance(fine, Solution) else load_result(Path(fine), fields=False)
    curve, _ = path_curve(sol, str(row["abscissa"]), LOAD)
    w_end = row.get("w_end")
    lam = _load_at(curve.x, curve.y, float(w_end)) if w_end is not None else None
    row["2d_fine_level"] = sol.extra.get("level")
    row["2d_fine_load_at_w_end"] = lam
    for key, model in (("end_load_rel_fine", "beam"), ("2d_rel_fine", "2d")):
        v = row.get(f"{model}_load_at_w_end")
        row[key] = v / lam - 1.0 if v is not None and lam else None
    return row
