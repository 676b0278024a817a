"""A study's tidy table, its knock-down answer and its plots.

One row per case: its index and key, the axis values, status and reason, every number of
:mod:`sandwich.studies.study_metrics`, the knock-down ratio (the report quantity over the reference
case's), the beam's error indicator, whether and how the 2D model checked it. Written as
``<out>/<study>.csv`` (no NaN: a number that does not exist is an empty cell); plots are a
knock-down curve for one axis and a heat map for two (the 2D-checked cases marked).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

from sandwich.studies.study_file import Axis, Study, reference_case
from sandwich.studies.study_params import axis_label

METRICS = ("initial_stiffness", "first_limit_kind", "first_limit_load", "first_limit_w",
           "load_at_until", "capacity", "peak_sigma_zz", "peak_sigma_zz_5mm", "peak_tau_core",
           "peak_tau_core_5mm", "contact_length", "first_growth_load", "residual_strength",
           "converged", "steps", "stop_reason",
           "solve_seconds", "wall_seconds", "indicator")
UNITS = {"capacity": "λ", "first_limit_load": "λ", "load_at_until": "λ",
         "initial_stiffness": "N/mm", "peak_sigma_zz": "MPa", "peak_sigma_zz_5mm": "MPa",
         "peak_tau_core": "MPa", "peak_tau_core_5mm": "MPa", "contact_length": "mm",
         "first_growth_load": "λ", "residual_strength": "λ"}


def _num(v: Any) -> float | None:
    return float(v) if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(
        float(v)) else None


def rows(study: Study, records: dict[int, dict[str, Any]],
         checks: dict[int, dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """The table's rows, in case order (cases without a record are left out)."""
    checks = checks or {}
    q = study.report.quantity
    out = []
    for case in study.cases:
        rec = records.get(case.index)
        if rec is None:
            continue
        row: dict[str, Any] = {"case": case.index, "key": case.key, **case.values,
                               "status": rec.get("status", ""), "reason": " ".join(
                                   str(rec.get("reason", "")).split())}
        for m in METRICS:
            row[m] = rec.get(m)
        ref = reference_case(study, case)
        knock = None
        if ref is not None and ref.index in records:
            a, b = _num(rec.get(q)), _num(records[ref.index].get(q))
            if a is not None and b not in (None, 0.0):
                knock = a / b
        row["knockdown"] = knock
        chk = checks.get(case.index)
        row["checked_2d"] = chk is not None
        for k, v in (chk or {}).items():
            row[k] = v
        out.append(row)
    return out


def write_table(table: list[dict[str, Any]], path: Path) -> None:
    """Write ``table`` as CSV (empty cells for missing numbers; never NaN)."""
    keys = list(dict.fromkeys(k for r in table for k in r))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, keys, lineterminator="\n")
        w.writeheader()
        for r in table:
            w.writerow({k: _cell(r.get(k)) for k in keys})
    tmp.replace(path)


def _cell(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if not math.isfinite(v) else repr(v)
    return v


def crossings(study: Study, table: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Where the knock-down first falls to the report's threshold along the first axis.

    One entry per combination of the other axes' values: ``at`` the first-axis value found by
    linear interpolation between the two cases that bracket the threshold (``None`` if it never
    falls that low within the axis), ``after`` the last case above it.
    """
    thr = study.report.threshold
    if thr is None or not study.axes:
        return []
    first, others = study.axes[0], study.axes[1:]
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for r in table:
        groups.setdefault(tuple(r[a.name] for a in others), []).append(r)
    out = []
    for key, rs in groups.items():
        rs = sorted(rs, key=lambda r: first.values.index(r[first.name]))
        at, prev = None, None
        for r in rs:
            k = _num(r.get("knockdown"))
            if k is None:
                continue
            if k <= thr:
                if prev is None:
                    at = float(r[first.name])
                else:
                    x0, k0 = float(prev[first.name]), float(prev["knockdown"])
                    x1 = float(r[first.name])
                    at = x0 + (k0 - thr) / (k0 - k) * (x1 - x0) if k0 != k else x1
                break
            prev = r
        below = r if at is not None else None
        out.append({**{a.name: v for a, v in zip(others, key, strict=True)}, "at": at,
                    "after": None if prev is None else prev[first.name],
                    "value": None if below is None else _num(below.get(study.report.quantity)),
                    "kind": (below.get("first_limit_kind") or "no limit point before the "
                             "target") if below is not None else ""})
    return out


def plot(study: Study, table: list[dict[str, Any]], out: Path) -> list[Path]:
    """Write :func:`figures` into ``out`` (PNG); returns the files written."""
    import matplotlib.pyplot as plt

    written = []
    for name, fig in figures(study, table):
        path = out / name
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    return written


def figures(study: Study, table: list[dict[str, Any]]) -> list[tuple[str, Any]]:
    """The knock-down curve (one axis) or heat map (two axes), 2D-checked cases circled.

    With more than two axes the first two are mapped, one map per value of the third (at the
    other axes' first values). Returns ``(file name, matplotlib figure)`` pairs.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    q = study.report.quantity
    show = "knockdown" if study.report.reference else q
    label = (f"knock-down: {q} / {q} at {_fmt(study.report.reference)}" if show == "knockdown"
             else f"{q} ({UNITS.get(q, '')})")
    written: list[tuple[str, Any]] = []
    numeric = all(all(isinstance(v, int | float) for v in a.values) for a in study.axes[:2])
    if len(study.axes) == 1 or not numeric:
        a = study.axes[0]
        fig, ax = plt.subplots(figsize=(6, 4))
        groups: dict[tuple, list] = {}
        for r in table:
            groups.setdefault(tuple(r[b.name] for b in study.axes[1:]), []).append(r)
        two_d_drawn = False  # the 2D values' marks: one legend entry once one is drawn
        for key, rs in groups.items():
            xs = [r[a.name] for r in rs]
            ys = [_num(r.get(show)) for r in rs]
            lbl = ", ".join(f"{b.name}={v:g}" if isinstance(v, float) else f"{b.name}={v}"
                            for b, v in zip(study.axes[1:], key, strict=True)) or None
            ax.plot(xs, [np.nan if y is None else y for y in ys], "o-", ms=4, label=lbl)
            chk = [(x, y) for x, y, r in zip(xs, ys, rs, strict=True)
                   if r.get("checked_2d") and y is not None]
            if chk:
                ax.plot(*zip(*chk, strict=True), "o", ms=11, mfc="none", mec="red", mew=1.5)
            for x, y, r in zip(xs, ys, rs, strict=True):
                if not r.get("checked_2d") or y is None:
                    continue
                e = _num(r.get(f"error_{q}"))
                if e is not None:
                    ax.annotate(f"{100 * e:+.0f}%", (x, y), xytext=(0, 9),
                                textcoords="offset points", ha="center", fontsize=7,
                                color="red")
                v = _num(r.get("2d_" + q))
                ref = _ref_value(study, table, r, q) if show == "knockdown" else 1.0
                if v is not None and ref:  # the 2D knock-down needs the 2D reference too
                    ax.plot([x], [v / ref], "x", color="red", ms=8,
                            label=None if two_d_drawn else "the 2D model's value")
                    two_d_drawn = True
        if study.report.threshold is not None and show == "knockdown":
            ax.axhline(study.report.threshold, color="grey", ls="--", lw=1,
                       label=f"threshold {study.report.threshold:g}")
        ax.set_xlabel(_axis_title(a))
        ax.set_ylabel(label)
        _legend_of_checks(ax, table, q)
        if 1 < len(groups) <= 12 or ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
        ax.set_title(_wrapped(f"{study.name}: {label} over {a.name}"), fontsize=9)
        fig.tight_layout()
        return [(f"{study.name}-curve.png", fig)]
    a, b = study.axes[0], study.axes[1]
    rest = study.axes[2:]
    slices = [()] if not rest else [(v,) for v in rest[0].values]
    for sl in slices:
        rs = [r for r in table if all(r[c.name] == c.values[0] for c in rest[1:])
              and (not sl or r[rest[0].name] == sl[0])]
        X = np.sort(np.array(a.values, dtype=float))
        Y = np.sort(np.array(b.values, dtype=float))
        Z = np.full((len(Y), len(X)), np.nan)
        for r in rs:
            v = _num(r.get(show))
            if v is not None:
                Z[np.searchsorted(Y, float(r[b.name])), np.searchsorted(X, float(r[a.name]))] = v
        fig, ax = plt.subplots(figsize=(7, 4.6))
        mesh = ax.pcolormesh(_edges(X), _edges(Y), Z, shading="flat", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=label)
        if study.report.threshold is not None and show == "knockdown" and np.isfinite(Z).sum() > 3:
            try:
                cs = ax.contour(X, Y, Z, levels=[study.report.threshold], colors="white",
                                linewidths=1.5)
                ax.clabel(cs, fmt=f"{study.report.threshold:g}", fontsize=8)
            except (ValueError, TypeError):
                pass
        bad = [(r[a.name], r[b.name]) for r in rs if r.get("status") == "failed"]
        if bad:
            ax.plot(*zip(*bad, strict=True), "kx", ms=7, label="failed")
        chk = [(r[a.name], r[b.name], r) for r in rs if r.get("checked_2d")]
        for k, (x, y, r) in enumerate(chk):
            ax.plot([x], [y], "o", ms=12, mfc="none", mec="red", mew=1.5,
                    label=None if k else f"checked with the 2D model (beam − 2D error of {q})")
            e = _num(r.get(f"error_{q}"))
            if e is not None:
                ax.annotate(f"{100 * e:+.0f}%", (x, y), xytext=(0, 9), textcoords="offset points",
                            ha="center", fontsize=7, color="red")
        if X[-1] > X[0]:  # a one-value axis keeps the cell's own extent
            ax.set_xlim(X[0], X[-1])
        if Y[-1] > Y[0]:
            ax.set_ylim(Y[0], Y[-1])
        ax.set_xlabel(_axis_title(a))
        ax.set_ylabel(_axis_title(b))
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="upper right")
        where = f", {rest[0].name} = {sl[0]}" if sl else ""
        ax.set_title(_wrapped(f"{study.name}{where}: {label}"), fontsize=9)
        fig.tight_layout()
        written.append((f"{study.name}-map.png" if not sl else f"{study.name}-map-{sl[0]}.png",
                        fig))
    return written


def _ref_value(study: Study, table: list[dict[str, Any]], row: dict[str, Any],
               q: str) -> float | None:
    """The 2D value of ``q`` at the row's reference case (None if the 2D did not check it)."""
    want = {**{a.name: row[a.name] for a in study.axes}, **study.report.reference}
    for r in table:
        if all(r[k] == v or (isinstance(v, float) and isinstance(r[k], float)
                             and math.isclose(r[k], v)) for k, v in want.items()):
            return _num(r.get("2d_" + q))
    return None


def _edges(v):
    """Cell edges around sorted axis values, bounded by the first and last value.

    Inner edges halfway between values; the outer cells end at the axis's own first and last
    values (half cells), so that no cell reaches a value the axis does not span.
    """
    import numpy as np

    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    return np.concatenate([[v[0]], 0.5 * (v[1:] + v[:-1]), [v[-1]]])


def _axis_title(axis: Axis) -> str:
    return axis_label(axis.name, axis.path, axis.derived, axis.scale)


def _wrapped(title: str, width: int = 90) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(title, width))


def _legend_of_checks(ax: Any, table: list[dict[str, Any]], q: str) -> None:
    """The legend entry of the 2D-check circles, only where a case was checked."""
    if any(r.get("checked_2d") for r in table):
        ax.plot([], [], "o", ms=11, mfc="none", mec="red", mew=1.5,
                label=f"checked with the 2D model (beam − 2D error of {q})")


def _fmt(values: dict[str, Any]) -> str:
    return ", ".join(f"{k} = {v:g}" if isinstance(v, int | float) else f"{k} = {v}"
                     for k, v in values.items())


def summary(study: Study, table: list[dict[str, Any]], run_lines: list[str],
            checks: list[dict[str, Any]], plots: list[Path]) -> str:
    """The study's ``summary.md``: what ran, the threshold answer, the 2D checks."""
    q = study.report.quantity
    md = [f"# Study {study.name}", "", study.description, "",
          f"Study file: `{study.source}`; base scene: `{study.scene_path}`; model "
          f"{study.model}; {len(study.cases)} cases over "
          + " × ".join(f"{a.name} ({len(a.values)})" for a in study.axes) + ".", "",
          *run_lines, ""]
    st: dict[str, int] = {}
    for r in table:
        st[r["status"]] = st.get(r["status"], 0) + 1
    md.append("Cases: " + ", ".join(f"{v} {k}" for k, v in sorted(st.items())) + ".")
    md.append("")
    cross = crossings(study, table)
    if cross:
        thr = study.report.threshold
        md += [f"## Where {q} falls to {thr:g} × its value at {_fmt(study.report.reference)}",
               "", f"Along {study.axes[0].name} (linear interpolation between the bracketing "
               "cases):", ""]
        others = [a.name for a in study.axes[1:]]
        unit = f" ({UNITS[q]})" if q in UNITS else ""
        md.append("| " + " | ".join([*others, study.axes[0].name + " at the threshold",
                                      f"{q}{unit} of the first case below it",
                                      "its first critical point"]) + " |")
        md.append("|" + "---|" * (len(others) + 3))
        for c in cross:
            at = "not within the axis" if c["at"] is None else f"{c['at']:.3g}"
            md.append("| " + " | ".join([*(f"{c[o]:g}" if isinstance(c[o], float) else str(c[o])
                                           for o in others), at, _g(c.get("value")),
                                         c["kind"] or "—"]) + " |")
        md.append("")
    if checks:
        md += ["## 2D spot checks", "",
               "Beam against the 2D model on the same scene, (beam − 2D) / |2D|:", "",
               "| case | " + " | ".join(a.name for a in study.axes) + " | indicator | "
               f"2D status | {q} beam | {q} 2D | error {q} | error stiffness | "
               "2D core crushed at λ | 2D time (s) |",
               "|" + "---|" * (len(study.axes) + 9)]
        for c in checks:
            md.append(f"| {c['case']} | " + " | ".join(
                f"{c[a.name]:g}" if isinstance(c[a.name], float) else str(c[a.name])
                for a in study.axes) + f" | {_pct(c.get('indicator'))} | {c.get('2d_status')} | "
                f"{_g(c.get(q))} | {_g(c.get('2d_' + q))} | {_pct(c.get('error_' + q))} | "
                f"{_pct(c.get('error_initial_stiffness'))} | {_g(c.get('2d_core_crushed_load'))} | "
                f"{_g(c.get('2d_seconds'))} |")
        errs = [abs(e) for c in checks if (e := _num(c.get("error_" + q))) is not None]
        if errs:
            md += ["", f"Largest |error| of {q} over the checked cases: {100 * max(errs):.1f} %."]
        md.append("")
    for p in plots:
        md += [f"![{p.stem}]({p.name})", ""]
    return "\n".join(md)


def _pct(v: Any) -> str:
    x = _num(v)
    return "—" if x is None else f"{100 * x:+.1f} %"


def _g(v: Any) -> str:
    x = _num(v)
    return "—" if x is None else f"{x:.4g}"
