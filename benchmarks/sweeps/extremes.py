"""Stability at the extremes: both models over sweeps from the Fig 5 scene, as five studies.

The sweeps are of stiffness, thickness, slenderness, debond length and load level, from the
Fig 5 scene (top debond, load on top). Each is a shipped study file,
``studies/shipped/extremes-<sweep>.toml`` (one axis, the beam at 240 graded elements and core
level 1, ``check = "all"``: the 2D model at level coarse on every case, a wall-time cap per case
and a 2D cell budget), run by the one study engine (:mod:`sandwich.studies.study`, ``sandwich
study``);
this module only turns the studies' stored cases into the map (it has no runner of its own).

Every case gets a row, whether its models ran or not. Per case and model: status (converged,
stopped before the target, failed, timeout, skipped with the reason), how far along the path it
got (|until probe| reached / |target|), steps, Newton iterations, step cuts (``cuts`` recorded in
the history, when a model records it) and wall time. Per case the agreement of the two load
curves, beam against 2D, as functions of |until probe| (:mod:`sandwich.compare.paths`):

- ``load_l2``: relative L2 over the common range of both paths (``common`` = its end / |target|;
  below 1 when a model stopped early, and the note says which);
- ``load_l2_lin``: the same over the first 10 % of the target (the linear range);
- ``end_error``: (λ_beam − λ_2D) / |λ_2D| at the end of the common range.

Writes ``extremes.csv``, ``extremes.md`` and ``extremes.png`` into
``benchmarks/results/comparisons/`` (or ``--out DIR``) after every sweep, each row with the
machine and date it was measured on (the cases themselves are kept in the studies' folders: an
interrupted map resumes with every finished case reused).

Usage, from the project root: ``python -m benchmarks.extremes [--sweeps stiffness ...] [--workers
N] [--scheduler ADDRESS] [--studies DIR] [--out DIR] [--render]``
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import re
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.provenance import (  # noqa: E402
    RESULTS,
    ROOT,
    add_out_argument,
    machine_and_date,
    measured_line,
    measured_on,
)
from sandwich.compare.paths import LOAD, curve_error, path_curve, path_parameter  # noqa: E402
from sandwich.results import Solution, load_result  # noqa: E402
from sandwich.scene import Debond, Layer, Load, Probe, Scene, Support  # noqa: E402
from sandwich.studies.study import run_study  # noqa: E402
from sandwich.studies.study_file import Study, load_study  # noqa: E402
from sandwich.studies.study_run import case_folder  # noqa: E402

OUT = RESULTS / "comparisons"
BASE = "paper-fig5-top-debond-40-load-top"
STUDIES = ROOT / "studies" / "shipped"  # extremes-<sweep>.toml
STUDY_OUT = ROOT / "results" / "studies"  # the studies' own folders (cases, tables)
SWEEPS = {  # the values of the study files' axes (tests/study checks they agree)
    "stiffness": [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6],  # E_core / E_face
    "thickness": [10, 50, 100, 500],  # t_core / t_face
    "slenderness": [5, 20, 100, 1000],  # L / h
    # debond length / span; 1.0 (the whole top face debonded, load on it) is a mechanism the
    # scene checks refuse before any solve (both models failed on it at step 1 before)
    "debond": [0.0, 0.1, 0.3, 0.6, 0.9],
    "load": [0.25, 0.5, 1.0, 2.0],  # until value / the scene's
}
LINEAR_FRACTION = 0.1  # the "linear range": the first 10 % of the until target
MODELS = ("beam", "2d")
CHECK = "2d_check"  # the optional finer 2D run


def _core_stiffness(scene: Scene, ratio: float) -> Scene:
    c, f = scene.core.material, scene.top.material
    E = ratio * f.Ex
    mat = dataclasses.replace(c, Ex=E, Ez=E, Gzx=E * c.Gzx / c.Ex)
    return dataclasses.replace(scene, core=Layer(scene.core.thickness, mat))


def _thickness(scene: Scene, ratio: float) -> Scene:
    t = scene.core.thickness / ratio
    return dataclasses.replace(scene, top=Layer(t, scene.top.material),
                               bottom=Layer(t, scene.bottom.material))


def _scale_x(scene: Scene, length: float) -> Scene:
    s = length / scene.length
    return dataclasses.replace(
        scene, length=length,
        debonds=tuple(Debond(d.interface, d.start * s, d.end * s) for d in scene.debonds),
        supports=tuple(Support(p.x * s, p.on, p.type) for p in scene.supports),
        loads=tuple(Load(ld.on, ld.x * s, ld.width * s, ld.force) for ld in scene.loads),
        probes=tuple(Probe(p.name, p.on, p.x * s) for p in scene.probes),
        analysis=dataclasses.replace(scene.analysis, until_value=scene.analysis.until_value * s))


def _debond(scene: Scene, fraction: float) -> Scene:
    L, half = scene.length, 0.5 * fraction * scene.length
    return dataclasses.replace(scene, debonds=(Debond("top", L / 2 - half, L / 2 + half),))


def _load(scene: Scene, factor: float) -> Scene:
    a = scene.analysis
    return dataclasses.replace(scene, analysis=dataclasses.replace(
        a, until_value=a.until_value * factor))


def cases(base: Scene, sweeps: list[str]) -> Iterator[tuple[str, float, Scene]]:
    """Every (sweep, value, scene) of ``sweeps`` made from ``base`` (no file, renamed)."""
    make: dict[str, Callable[[Scene, float], Scene]] = {
        "stiffness": _core_stiffness, "thickness": _thickness, "debond": _debond,
        "slenderness": lambda s, r: _scale_x(s, r * s.total_height), "load": _load}
    for sweep in sweeps:
        for value in SWEEPS[sweep]:
            sc = make[sweep](base, value)
            yield sweep, value, dataclasses.replace(sc, name=f"{base.name}-{sweep}-{value:g}",
                                                    source=None)


# -- running one model with a budget --------------------------------------------------------------

@dataclasses.dataclass
class Outcome:
    """One model on one case.

    ``status`` is converged | stopped | failed | timeout | skipped | missing; ``solution`` holds
    the converged path (possibly partial), ``None`` if no state.
    """

    model: str
    status: str
    solution: Solution | None
    reason: str = ""
    seconds: float = 0.0
    cuts: int = 0
    info: dict = dataclasses.field(default_factory=dict)  # what a solver told before solving


def _label(r: dict[str, object], model: str) -> str:
    """The status of the map: a stopped path that got past the target only missed hitting it."""
    st = str(r.get(f"{model}_status", "missing"))
    reached = r.get(f"{model}_reached")
    if st == "stopped" and reached not in (None, "") and float(reached) >= 1.0:
        return "crossed"
    return st


def _history_cuts(sol: Solution) -> int:
    if "step_cuts" in sol.extra:
        return int(sol.extra["step_cuts"])
    return int(sum(r.extra.get("cuts", r.extra.get("step_cuts", 0.0)) for r in sol.history))


# -- one row of the map ---------------------------------------------------------------------------

def _backsteps(scene: Scene, sol: Solution | None) -> int:
    """Steps at which |until probe| goes back, plus steps with a reversed load (λ < 0).

    Going back is a snap-back of the probe, or a path retracing itself.
    """
    a = scene.analysis
    if sol is None or len(sol.history) < 2 or a.until_probe not in sol.history[0].probes:
        return 0
    w = np.abs([r.probes[a.until_probe] for r in sol.history])
    return int(np.sum(np.diff(w) < 0) + sum(r.load_factor < 0 for r in sol.history))


def _fraction(scene: Scene, sol: Solution | None) -> float | None:
    """|until probe| reached (largest along the path) / |target|; λ / target if load-driven."""
    a = scene.analysis
    if sol is None or not sol.history:
        return None
    if a.until_probe is not None and a.until_probe in sol.history[0].probes:
        return max(abs(r.probes[a.until_probe]) for r in sol.history) / abs(a.until_value)
    if a.until_load_factor:
        return max(abs(r.load_factor) for r in sol.history) / abs(a.until_load_factor)
    return None


def _upto(c, cut: float):
    """The curve ``c`` on [0, cut], with an interpolated sample at ``cut`` itself."""
    inside = c.x < cut
    return dataclasses.replace(c, x=np.append(c.x[inside], cut),
                               y=np.append(c.y[inside], float(np.interp(cut, c.x, c.y))))


def agreement(scene: Scene, beam: Solution | None, ref: Solution | None) -> dict[str, object]:
    """Load-curve agreement of ``beam`` against ``ref`` (see the module docstring)."""
    out: dict[str, object] = {"load_l2": None, "load_l2_lin": None, "end_error": None,
                              "common": None, "agree_note": ""}
    if beam is None or ref is None or not beam.history or not ref.history:
        out["agree_note"] = "no comparison: " + ("beam" if not (beam and beam.history) else
                                                 "2D") + " has no converged state"
        return out
    absc = path_parameter(scene.analysis.until_probe, [beam, ref])
    c_ref, n_ref = path_curve(ref, absc, LOAD)
    c_beam, n_beam = path_curve(beam, absc, LOAD)
    err = curve_error(c_ref, c_beam, LOAD, absc)
    notes = [n for n in (n_ref, n_beam) if n]
    if err.common_range is None:
        out["agree_note"] = "; ".join([*notes, err.note])
        return out
    lo, hi = err.common_range
    target = (abs(scene.analysis.until_value) if absc == scene.analysis.until_probe
              else abs(scene.analysis.until_load_factor or 1.0))
    out["load_l2"] = err.l2_relative
    out["common"] = hi / target
    lam_ref = float(np.interp(hi, c_ref.x, c_ref.y))
    lam_beam = float(np.interp(hi, c_beam.x, c_beam.y))
    if lam_ref != 0.0:
        out["end_error"] = (lam_beam - lam_ref) / abs(lam_ref)
    cut = LINEAR_FRACTION * target
    if hi >= cut:
        lin = curve_error(_upto(c_ref, cut), _upto(c_beam, cut), LOAD, absc)
        out["load_l2_lin"] = lin.l2_relative
    if out["common"] is not None and out["common"] < 1 - 1e-3:
        short = [m for m, s in (("beam", beam), ("2D", ref))
                 if (_fraction(scene, s) or 0.0) < 1 - 1e-3]
        why = (f"{' and '.join(short)} stopped early" if short else
               "a path turns back in the compared quantity")
        notes.append(f"compared up to {100 * out['common']:.0f} % of the target ({why})")
    out["agree_note"] = "; ".join(notes)
    return out


def row(sweep: str, value: float, scene: Scene, runs: dict[str, Outcome]) -> dict[str, object]:
    """The map's row of one case."""
    out: dict[str, object] = {"sweep": sweep, "value": value}
    for model in (*MODELS, *([CHECK] if CHECK in runs else [])):
        r = runs.get(model) or Outcome(model, "missing", None, "not run")
        s = r.solution
        out[f"{model}_status"] = r.status
        out[f"{model}_converged"] = r.status == "converged"
        frac = _fraction(scene, s)
        out[f"{model}_reached"] = None if frac is None else round(frac, 4)
        out[f"{model}_steps"] = max(len(s.history) - 1, 0) if s else 0  # state 0 not a step
        out[f"{model}_iterations"] = sum(h.iterations for h in s.history) if s else 0
        out[f"{model}_cuts"] = r.cuts
        out[f"{model}_backsteps"] = _backsteps(scene, s)
        out[f"{model}_seconds"] = round(r.seconds, 2)  # the child process: imports, mesh, solve
        out[f"{model}_solve_seconds"] = (round(s.wall_seconds, 2) if s and r.status in
                                         ("converged", "stopped") else None)
        cells = (s.extra.get("cells") if s else None) or r.info.get("cells")
        if model != "beam":
            out[f"{model}_cells"] = cells
        out[f"{model}_note"] = " ".join((r.reason or (s.message if s else "")).split()
                                        ).replace("|", "/")
    agree = agreement(scene, *(runs[m].solution if m in runs else None for m in MODELS))
    out.update(agree)
    if CHECK in runs:
        chk = agreement(scene, runs["beam"].solution if "beam" in runs else None,
                        runs[CHECK].solution)
        out["beam_vs_check_l2"] = chk["load_l2"]
        out["beam_vs_check_end"] = chk["end_error"]
        ref = agreement(scene, runs["2d"].solution if "2d" in runs else None,
                        runs[CHECK].solution)
        out["check_end_error"] = ref["end_error"]
        out["check_common"] = ref["common"]
    return out


# -- the map --------------------------------------------------------------------------------------

def _pct(v: object, digits: int = 1) -> str:
    return "—" if v is None or v == "" else f"{100 * float(v):.{digits}f} %"


def _signed(v: object) -> str:
    return "—" if v is None or v == "" else f"{100 * float(v):+.1f} %"


MARK = {"converged": "✓", "crossed": "✓✗", "stopped": "✗", "failed": "✗!", "timeout": "⏱",
        "skipped": "–", "missing": "–"}


def _short(note: str, n: int = 170) -> str:
    """A note for the table: its start and, for a failed step, the solver's last reason."""
    head, sep, reason = note.partition("; last reason: ")
    head = head if len(head) <= n else head[:n] + " …"
    first = re.split(r"[.](?:\s|$)", reason)[0][:n]  # up to the end of its first sentence
    return head + (f"; last reason: {first}" if sep else "")


def _status_cell(r: dict[str, object], model: str) -> str:
    if r.get(f"{model}_status") in (None, ""):
        return "—"
    st = _label(r, model)
    reached = r.get(f"{model}_reached")
    back = r.get(f"{model}_backsteps")
    turn = f" ↺{back}" if back not in (None, "", 0) else ""
    if st == "converged" or reached in (None, ""):
        return MARK.get(st, st) + turn
    return f"{MARK.get(st, st)} {100 * float(reached):.0f} %{turn}"


def write(rows: list[dict[str, object]], out: Path, header: list[str] | None = None) -> None:
    """Write ``extremes.csv``, ``extremes.md`` and ``extremes.png`` of ``rows`` into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with (out / "extremes.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, keys, lineterminator="\n")
        w.writeheader()
        w.writerows({k: ("" if r.get(k) is None else r.get(k)) for k in keys} for r in rows)
    check = any(f"{CHECK}_status" in r for r in rows)
    md = ["# Stability at the extremes (benchmarks/extremes.py)", "", measured_line(rows), "",
          *(header or []),
          f"Base scene: {BASE}. Status: ✓ reached the target; ✗ N % stopped before it (N = "
          "|until probe| reached / target); ✓✗ N % passed the target but could not hit it "
          "within the solver's target_tol (a converged path past the target); ✗! the solve "
          "raised; ⏱ wall-time cap; – not run; ↺N: N steps went back in |until probe| or had "
          "λ < 0 (a snap-back or a path retracing itself) "
          "(reason in the notes / CSV). Agreement: beam load curve against the 2D one as a "
          "function of |until probe|, over the common range (`common` = its end / target), "
          "over the first 10 % of the target (`lin`), and the load error at the end of the "
          "common range (`end`, signed: + means the beam is stiffer).", "",
          "| sweep | value | beam | 2D | steps beam/2D | iterations beam/2D | cuts beam/2D | "
          "time beam/2D (s) | 2D cells | L2 (common) | common | L2 lin | end |"
          + (" 2D check | beam vs check end | coarse vs check end |" if check else ""),
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|---|---|" if check
                                                                     else "")]
    for r in rows:
        line = (f"| {r['sweep']} | {r['value']:g} | {_status_cell(r, 'beam')} | "
                f"{_status_cell(r, '2d')} | {r.get('beam_steps')}/{r.get('2d_steps')} | "
                f"{r.get('beam_iterations')}/{r.get('2d_iterations')} | "
                f"{r.get('beam_cuts')}/{r.get('2d_cuts')} | "
                f"{float(r.get('beam_seconds') or 0):.0f}/{float(r.get('2d_seconds') or 0):.0f} | "
                f"{r.get('2d_cells') or '—'} | {_pct(r.get('load_l2'))} | "
                f"{_pct(r.get('common'), 0)} | {_pct(r.get('load_l2_lin'))} | "
                f"{_signed(r.get('end_error'))} |")
        if check:
            line += (f" {_status_cell(r, CHECK)} | {_pct(r.get('beam_vs_check_end'))} | "
                     f"{_pct(r.get('check_end_error'))} |")
        md.append(line)
    md += ["", "Notes (why a model stopped or was not run, what was compared):", ""]
    caps = [r.get("cap_s") for r in rows if r.get("cap_s") not in (None, "")]
    usual = max(set(caps), key=caps.count) if caps else None
    for r in rows:
        parts = []
        if r.get("cap_s") not in (None, "", usual):
            parts.append(f"run with a wall-time cap of {float(r['cap_s']):g} s")
        for model, label in (("beam", "beam"), ("2d", "2D"), (CHECK, "2D check")):
            st = r.get(f"{model}_status")
            if st is not None and st != "converged":
                parts.append(f"{label} {st}: {_short(str(r.get(f'{model}_note')))}")
        if r.get("agree_note"):
            parts.append(str(r["agree_note"]))
        if parts:
            md.append(f"- {r['sweep']} = {r['value']:g}: " + " — ".join(parts))
    md += ["", "![map](extremes.png)", ""]
    (out / "extremes.md").write_text("\n".join(md))
    _plot(rows, out / "extremes.png")


COLOURS = {"converged": "tab:green", "crossed": "yellowgreen", "stopped": "tab:orange",
           "failed": "tab:red", "timeout": "tab:purple", "skipped": "lightgrey",
           "missing": "lightgrey"}


def _plot(rows: list[dict[str, object]], path: Path) -> None:
    sweeps = list(dict.fromkeys(r["sweep"] for r in rows))
    n = max(len(sweeps), 1)
    fig, axes = plt.subplots(1, n, figsize=(3.3 * n, 3.8), squeeze=False)
    for ax, sweep in zip(axes[0], sweeps, strict=False):
        rs = [r for r in rows if r["sweep"] == sweep]
        for i, model in enumerate(MODELS):
            ax.scatter(range(len(rs)), [i] * len(rs), s=260, marker="s",
                       c=[COLOURS.get(_label(r, model), "black") for r in rs])
            for j, r in enumerate(rs):
                fr = r.get(f"{model}_reached")
                text = (f"{100 * float(fr):.0f}%" if _label(r, model) != "converged"
                        and fr not in (None, "") else "")
                if r.get(f"{model}_backsteps") not in (None, "", 0):
                    text += "↺"
                if text:
                    ax.annotate(text, (j, i), ha="center", va="center", fontsize=6)
        for j, r in enumerate(rs):
            if r.get("load_l2") is not None:
                e = float(r["load_l2"])
                colour = "green" if e <= 0.03 else "darkorange" if e <= 0.10 else "red"
                c = r.get("common")
                short = c not in (None, "") and float(c) < 0.99
                upto = f"\n(to {100 * float(c):.0f}%)" if short else ""
                ax.annotate(f"{100 * e:.1f}%{upto}", (j, 0.5), ha="center", va="center",
                            fontsize=7, color=colour)
        ax.set_xticks(range(len(rs)), [f"{r['value']:g}" for r in rs], fontsize=7)
        ax.set_yticks([0, 1], ["beam", "2D"])
        ax.set_ylim(-0.6, 1.6)
        ax.set_xlim(-0.6, len(rs) - 0.4)
        ax.set_title({"stiffness": "E_core / E_face", "thickness": "t_core / t_face",
                      "slenderness": "L / h", "debond": "debond / span",
                      "load": "until × (load level)"}.get(sweep, sweep), fontsize=9)
    handles = [plt.Line2D([], [], marker="s", ls="", color=c, label=k)
               for k, c in COLOURS.items() if k != "missing"]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=7, frameon=False)
    fig.suptitle("squares: model status (% = path reached when short); numbers: load-curve L2 "
                 "beam vs 2D over the common range, (to N%) when it ends before the target; "
                 "↺ path went back (green ≤ 3 %, orange ≤ 10 %, red > 10 %)",
                 fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 0.95))
    fig.savefig(path, dpi=120)
    plt.close(fig)


# -- the map from the studies' cases ---------------------------------------------------------------

STATUS = {"done": "converged", "stopped": "stopped", "failed": "failed", "timeout": "timeout",
          "skipped": "skipped"}


def outcome(model: str, record: dict | None, folder: Path) -> Outcome:
    """A study case's record and stored result set as the map's :class:`Outcome`."""
    if record is None:
        return Outcome(model, "missing", None, "not run")
    sol = None
    if (folder / "summary.json").is_file():
        try:
            sol = load_result(folder)
        except (OSError, ValueError, KeyError):
            sol = None
    status = STATUS.get(str(record.get("status")), "failed")
    seconds = float(record.get("wall_seconds") or 0.0)
    return Outcome(model, status, sol, str(record.get("reason") or (sol.message if sol else "")),
                   seconds, _history_cuts(sol) if sol else 0)


def map_rows(sweep: str, study: Study, result, out: Path) -> list[dict[str, object]]:
    """The map's rows of one sweep's study run (a :class:`~sandwich.studies.study.StudyResult`)."""
    rows = []
    axis = study.axes[0]
    for case in study.cases:
        value = float(case.values[axis.name])
        if sweep == "debond":
            value = value / case.scene.length
        beam = outcome("beam", result.cases.records.get(case.index),
                       case_folder(out, case, "beam"))
        checks = result.checks.records if result.checks else {}
        ref = outcome("2d", checks.get(case.index), case_folder(out, case, "2d-check"))
        r = row(sweep, value, case.scene, {"beam": beam, "2d": ref})
        r.update(elements=case.scene.beam_model.elements, level=case.scene.reference2d.level,
                 cap_s=study.timeout, max_cells=study.max_cells, case=case.index,
                 finished=time.strftime("%Y-%m-%d %H:%M:%S"),
                 measured=machine_and_date(measured_on()))
        rows.append(r)
    return rows


def main(argv: list[str] | None = None) -> int:
    """The map's command line (``python -m benchmarks.extremes --help``)."""
    ap = argparse.ArgumentParser(description="stability map of both models, from the five "
                                             "extremes studies")
    ap.add_argument("--sweeps", nargs="+", default=list(SWEEPS), choices=list(SWEEPS))
    ap.add_argument("--workers", type=int, default=2, help="local worker processes")
    ap.add_argument("--scheduler", help="a Dask scheduler address to run the cases on")
    ap.add_argument("--studies", type=Path, default=STUDY_OUT,
                    help="parent folder of the studies' own folders (resumed if there)")
    ap.add_argument("--render", action="store_true",
                    help="only redraw extremes.md/.png from extremes.csv in --out")
    ap.add_argument("--note", action="append", default=[],
                    help="a line for the map's header (e.g. the machine and its load)")
    add_out_argument(ap, OUT)
    args = ap.parse_args(argv)
    if args.render:
        rows = [_parse(r) for r in csv.DictReader((args.out / "extremes.csv").open())]
        write(rows, args.out, [*args.note, ""])
        return 0
    rows: list[dict[str, object]] = []
    for sweep in args.sweeps:
        study = load_study(STUDIES / f"extremes-{sweep}.toml")
        out = args.studies / study.name
        print(f"{sweep}: {len(study.cases)} cases, study folder {out}", flush=True)
        result = run_study(study, out, workers=args.workers, scheduler=args.scheduler)
        rows = [r for r in rows if r["sweep"] != sweep] + map_rows(sweep, study, result, out)
        rows.sort(key=lambda x: (list(SWEEPS).index(x["sweep"]), _index(x)))
        header = [f"Settings: the studies studies/shipped/extremes-*.toml (beam "
                  f"{study.cases[0].scene.beam_model.elements} graded elements, core level 1; "
                  f"2D level {study.cases[0].scene.reference2d.level} on every case; wall-time "
                  f"cap {study.timeout:g} s per case; 2D cell budget {study.max_cells}).",
                  *args.note, ""]
        write(rows, args.out, header)  # the map so far survives a crash or an interrupt
        if result.interrupted:
            return 1
    return 0 if rows else 1


def _index(r: dict[str, object]) -> int:
    """Position of a row's value in its sweep (values no longer swept go last)."""
    vals = SWEEPS.get(str(r["sweep"]), [])
    return next((i for i, v in enumerate(vals) if math.isclose(v, float(r["value"]),
                                                                abs_tol=1e-12)), len(vals))


def _parse(r: dict[str, str]) -> dict[str, object]:
    """A CSV row back into values (for --append)."""
    out: dict[str, object] = {}
    for k, v in r.items():
        if v == "":
            out[k] = None
        elif v in ("True", "False"):
            out[k] = v == "True"
        else:
            try:
                out[k] = int(v)
            except ValueError:
                try:
                    out[k] = float(v)
                except ValueError:
                    out[k] = v
    out["value"] = float(out["value"])
    return out


if __name__ == "__main__":
    raise SystemExit(main())
