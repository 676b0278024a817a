"""Energy release rate at a debond tip: the result both models give, and its history columns."""

from __future__ import annotations

import re
from dataclasses import dataclass

COLUMN = re.compile(r"GI{0,2}_\d+_(start|end)")  # G_0_end, GI_0_end, GII_0_end


@dataclass(frozen=True)
class TipRelease:
    """G and its split at one tip for one state (N/mm), with the closure length used (mm)."""

    debond: int
    tip: str
    G: float
    GI: float
    GII: float
    closure_length: float


def column_names(debond: int, tip: str) -> tuple[str, str, str]:
    """History columns of one tip: ``G_<debond>_<tip>``, ``GI_…``, ``GII_…`` (N/mm)."""
    return (f"G_{debond}_{tip}", f"GI_{debond}_{tip}", f"GII_{debond}_{tip}")


def is_release_column(name: str) -> bool:
    """Whether ``name`` is a G column (an empty cell there means "not evaluated")."""
    return COLUMN.fullmatch(name) is not None


def history_columns(releases: list[TipRelease]) -> dict[str, float]:
    """The history.csv columns of a list of tip results."""
    cols: dict[str, float] = {}
    for r in releases:
        g, gi, gii = column_names(r.debond, r.tip)
        cols.update({g: float(r.G), gi: float(r.GI), gii: float(r.GII)})
    return cols
