"""Overlay plots of both models (matplotlib PNG), each with the CSV of exactly what it draws.

Functions here only draw the curves they are given: every number comes from the caller.
The reference (2D) is drawn solid, the beam model dashed.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from sandwich.compare.paths import Curve  # noqa: E402

STYLE = {"2d": {"linestyle": "-", "color": "C0"}, "beam": {"linestyle": "--", "color": "C3"}}
EXTRA_COLORS = ("C2", "C1", "C4", "C5", "C6")
MARKERS = {"2d": "o", "beam": "s"}  # critical points and limit loads, by model


@dataclass(frozen=True)
class Panel:
    """One axes of a figure: its curves, y label, markers (label, x, y) and shaded x spans.

    A marker's label starts with its model's name (its colour and symbol) and is shown in the
    legend.
    """

    ylabel: str
    curves: Sequence[Curve]
    title: str = ""
    markers: Sequence[tuple[str, float, float]] = ()
    spans: Sequence[tuple[float, float]] = ()


def write_curves_csv(path: Path, panels: Sequence[Panel], xname: str) -> Path:
    """Write the curves of ``panels`` in long form: ``panel, series, <xname>, value``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["panel", "series", xname, "value"])
        for panel in panels:
            for c in panel.curves:
                for x, y in zip(c.x, c.y, strict=True):
                    if np.isfinite(x) and np.isfinite(y):  # never write NaN
                        w.writerow([panel.ylabel, c.label, repr(float(x)), repr(float(y))])
    return path


def _style(label: str, k: int) -> dict[str, object]:
    model = label.split()[0]
    if model in STYLE:
        style = dict(STYLE[model])
        if k:  # a second quantity of the same model in the same axes
            style["color"] = EXTRA_COLORS[k % len(EXTRA_COLORS)]
        return style
    return {"linestyle": "-", "color": EXTRA_COLORS[k % len(EXTRA_COLORS)]}


def overlay(path: Path, panels: Sequence[Panel], xlabel: str, title: str) -> tuple[Path, Path]:
    """Draw ``panels`` stacked vertically into ``path`` (PNG) and their data into ``.csv``.

    Returns
    -------
    (Path, Path)
        The PNG and the CSV written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(len(panels), 1, figsize=(7.0, 3.2 * len(panels)), squeeze=False,
                             sharex=True)
    for ax, panel in zip(axes[:, 0], panels, strict=True):
        seen: dict[str, int] = {}
        for c in panel.curves:
            model = c.label.split()[0]
            k = seen.get(model, 0)
            seen[model] = k + 1
            ax.plot(c.x, c.y, label=c.label, linewidth=1.4, **_style(c.label, k))
        for a, b in panel.spans:
            ax.axvspan(a, b, color="0.85", zorder=0)
        for label, x, y in panel.markers:  # in the legend, not as text that may collide
            model = label.split()[0]
            ax.plot([x], [y], linestyle="none", marker=MARKERS.get(model, "D"), markersize=7,
                    fillstyle="none", markeredgewidth=1.4,
                    color=STYLE.get(model, {}).get("color", "k"), label=label)
        ax.set_ylabel(panel.ylabel)
        if panel.title:
            ax.set_title(panel.title, fontsize=9)
        ax.grid(True, linewidth=0.3)
        if panel.curves or panel.markers:
            ax.legend(fontsize=7)
    axes[-1, 0].set_xlabel(xlabel)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    table = write_curves_csv(path.with_suffix(".csv"), panels, xlabel)
    return path, table
