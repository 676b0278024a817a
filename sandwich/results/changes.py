"""How much a state's answer changes between two resolutions: load, probes, G and stresses.

Both models' error estimates compare a state with the same state re-converged (beam) or
solved (2D) at another resolution through these measures, so that "1 %" means the same in
every summary.
"""

from __future__ import annotations

import numpy as np

from sandwich.results.peaks import PEAK_WINDOW, window_average
from sandwich.scene import Accuracy


def answer_change(load_factor: float, probes: dict[str, float], new_load_factor: float,
                  new_probes: dict[str, float]) -> float | None:
    """The relative change of a state's answer: the load, and every probe.

    The load relative to itself, the probes relative to the largest probe magnitude (a probe
    that barely moves is not divided by its own near-zero value); the larger of the two. None
    where nothing can be compared (no load, no probe moved).
    """
    changes = []
    if load_factor != 0.0:
        changes.append(abs(new_load_factor - load_factor) / abs(load_factor))
    scale = max((abs(v) for v in probes.values()), default=0.0)
    common = [n for n in probes if n in new_probes]
    if scale > 0.0 and common:
        changes.append(max(abs(new_probes[n] - probes[n]) for n in common) / scale)
    return max(changes) if changes else None


def release_changes(before: dict[str, float | None],
                    after: dict[str, float | None]) -> dict[str, float]:
    """The change of G at the debond tips between two states' history columns.

    ``"G"``: the largest change of a tip's total G relative to the largest G; ``"G_II/G"``: the
    largest change of a tip's mode mix (absolute), over tips carrying at least 1e-6 of the
    largest G. Empty where no tip has a G in both.
    """
    totals = [k for k in before if k.startswith("G_") and before[k] is not None
              and after.get(k) is not None]
    scale = max((abs(before[k]) for k in totals), default=0.0)
    if scale <= 0.0:
        return {}
    out = {"G": max(abs(after[k] - before[k]) for k in totals) / scale}
    mixes = []
    for k in totals:
        mode = "GII" + k[1:]
        if min(abs(before[k]), abs(after[k])) < 1e-6 * scale or before.get(mode) is None \
                or after.get(mode) is None:
            continue
        mixes.append(abs(after[mode] / after[k] - before[mode] / before[k]))
    if mixes:
        out["G_II/G"] = max(mixes)
    return out


#: The averaged stress quantities: the interface σzz at both core boundaries together (relative
#: to the larger peak), and the core shear τ at mid-core
STRESS_QUANTITIES = {"interface sigma_zz": ("sigma_zz_top", "sigma_zz_bottom"),
                     "core tau": ("tau_core",)}
#: what their estimates are held to (relative)
STRESS_TOLERANCE = 0.05


def stress_changes(before: dict[str, np.ndarray], after: dict[str, np.ndarray],
                   window: float = PEAK_WINDOW) -> dict[str, float]:
    """The change of the window-averaged stress peaks between two states' profile columns.

    Per :data:`STRESS_QUANTITIES`: the largest change of a column's averaged peak magnitude
    relative to the largest of its group (a column that barely carries stress is not divided
    by its own near-zero peak). Empty for a group with no stress, or a profile shorter than the
    window.
    """
    peaks_before, peaks_after = averaged_peaks(before, window), averaged_peaks(after, window)
    out = {}
    for name, columns in STRESS_QUANTITIES.items():
        both = [c for c in columns if c in peaks_before and c in peaks_after]
        scale = max((peaks_before[c] for c in both), default=0.0)
        if scale > 0.0:
            out[name] = max(abs(peaks_after[c] - peaks_before[c]) for c in both) / scale
    return out


def averaged_peaks(columns: dict[str, np.ndarray],
                   window: float = PEAK_WINDOW) -> dict[str, float]:
    """The window-averaged peak magnitude of each stress column (MPa).

    Every column of :data:`STRESS_QUANTITIES` that ``columns`` has and that spans the window.
    """
    out = {}
    for group in STRESS_QUANTITIES.values():
        for column in group:
            if column in columns:
                try:
                    out[column] = _averaged_peak(columns, column, window)
                except ValueError:  # the profile spans less than the window
                    continue
    return out


def _averaged_peak(columns: dict[str, np.ndarray], column: str, window: float) -> float:
    """The largest magnitude of ``column`` averaged over ``window`` mm.

    A magnitude, not a signed value: a symmetric scene carries equal and opposite shear peaks
    either side of its middle, and which of the two is larger is round-off.
    """
    _, values = window_average(np.asarray(columns["x"], dtype=float),
                               np.asarray(columns[column], dtype=float), window)
    return float(np.abs(values).max())


#: the quantities each kind of a scene's ``[accuracy]`` table names
KINDS = {"load": ("load and probes",), "G": ("G", "G_II/G"), "stresses": tuple(STRESS_QUANTITIES)}


def tolerances(accuracy: Accuracy, defaults: dict[str, float]) -> dict[str, float]:
    """What each quantity a run estimates is held to, by quantity name.

    Per kind of :data:`KINDS`: the scene's ``[accuracy]`` tolerance where given, else the
    model's ``defaults[kind]``; the kinds the scene does not want estimated are left out.
    """
    wanted = {"load": True, "G": accuracy.estimate_G, "stresses": accuracy.estimate_stresses}
    out = {}
    for kind, names in KINDS.items():
        if not wanted[kind]:
            continue
        given = getattr(accuracy, kind)
        out.update({name: float(defaults[kind] if given is None else given) for name in names})
    return out
