"""Per-scene agreement of the beam (scene defaults, ``core = "auto"``) with the 2D reference.

Reads the folder a ``sandwich gallery --out DIR`` run wrote (``DIR/<scene>/metrics.json`` and
each model's ``summary.json`` / ``history.csv``) and writes one table:

Run: ``.venv/bin/python benchmarks/gallery_agreement.py DIR`` → writes
``benchmarks/results/comparisons/gallery_agreement.{md,csv}`` (``--out`` to change the stem).

Columns per scene: where each model stopped (|until probe| reached, λ there, steps, wall time,
converged); the end load compared at the *common* end of the path, ``w_end`` = the largest
|until probe| both monotone paths reach, λ_beam(w_end)/λ_2D(w_end) − 1 (linear interpolation in
each history); the load-curve L2 and max relative errors of ``metrics.json`` (their common range
is the same); the beam's core levels (length of x at each level) and its own error estimate; the
models' messages when they did not converge or warned. The trust column is not computed: it is
the documented reading of each scene (``TRUST`` below, sources named there).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from comparisons.paths import LOAD, path_curve  # noqa: E402
from sandwich.results import load_result  # noqa: E402

# Where the 2D model is (not) a trustworthy reference, per scene, and why. Sources: README "How
# far to trust it" (Green-strain core crushing under concentrated loads), docs/comparisons.md
# (gallery of 2026-11-22), benchmarks/results/beam/core_levels.md (2D mesh levels),
# benchmarks/results/comparisons/tradeoff.md (2D coarse/medium/fine on fig4/fig5).
TRUST: dict[str, str] = {
    "paper-fig4-bonded-3pb": (
        "up to its load maximum only (λ ≈ 1912 at w ≈ −13.4 mm, where its arc step turns "
        "back): the St. Venant–Kirchhoff core crushes under the 10 mm patch; the beam at "
        "core = 3 crushes there too (max 1921.6 at −12.9 mm, then w snaps back to −8.4 mm; "
        "docs/comparisons.md), so neither model past it"),
    "paper-fig5-top-debond-40-load-top": (
        "yes: 2D coarse→fine within 1.7 % at −15 mm (tradeoff.md)"),
    "paper-fig6-top-debond-20-load-bottom": (
        "yes along this path (both models on the same branch: first maximum within 0.7 %); "
        "the core corners at the pins crush in 2D under larger loads (README); no 2D mesh "
        "check"),
    "paper-fig7-cantilever-c1": (
        "up to its maximum (713) only: after it an element inverts in the core near the clamp "
        "(x = 15.4, z = −11.8 mm) and the path creeps back; the beam crushes there too, with "
        "its core estimate 4.9 % (zones at max_core_level 3)"),
    "paper-fig7-cantilever-c2": (
        "up to its maximum (656) only: then the path snaps back and wanders to λ < 0, an "
        "element inverted at the clamp corner (x = 0, z = −12.5 mm); no mesh check"),
    "paper-fig7-cantilever-c3": (
        "yes, not mesh-converged: its G changes 17 % coarse→medium; the beam's L2→L3 move "
        "0.8 % away from it (README)"),
    "paper-fig7-cantilever-c4": "as c3 (the same clamp, both faces debonded): no mesh check",
    "paper-fig9-clamped-d0": "no mesh check, no crushing seen on the path to −10 mm",
}
for _d in (10, 16, 20, 30, 40):
    TRUST[f"paper-fig9-clamped-d{_d}"] = TRUST["paper-fig9-clamped-d0"]


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


def scene_row(folder: Path) -> dict[str, object]:
    """One table row from a gallery scene folder (``metrics.json`` + both model folders)."""
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
        row[f"{model}_message"] = s["message"] if (not s["converged"] or "WARNING" in
                                                   (s["message"] or "")) else ""
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
    row["trust_2d"] = TRUST.get(folder.name, "not assessed")
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


def main(argv: list[str] | None = None) -> int:
    """Read a gallery folder and write the agreement table (Markdown + CSV)."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("gallery", type=Path, help="the --out folder of a `sandwich gallery` run")
    p.add_argument("--out", type=Path,
                   default=ROOT / "benchmarks/results/comparisons/gallery_agreement")
    p.add_argument("--header", default="", help="run conditions (commit, date, load, times)")
    a = p.parse_args(argv)
    folders = sorted(f for f in a.gallery.iterdir() if (f / "metrics.json").is_file())
    if not folders:
        print(f"{a.gallery}: no <scene>/metrics.json", file=sys.stderr)
        return 2
    rows = [scene_row(f) for f in folders]
    a.out.with_suffix(".md").write_text(markdown(rows, str(a.gallery), a.header))
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with a.out.with_suffix(".csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)
    print(a.out.with_suffix(".md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
