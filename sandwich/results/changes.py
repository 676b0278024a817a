"""How much a state's answer changes between two resolutions: the load, probes and G.

Both models' error estimates compare a state with the same state re-converged (beam) or
solved (2D) at another resolution through these measures, so that "1 %" means the same in
every summary.
"""

from __future__ import annotations


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
