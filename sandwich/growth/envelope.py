"""What a growth envelope says: first growth load, residual strength, stability and arrest.

The envelope is the sequence of onset states of a crack-length-controlled growth run
(:mod:`sandwich.growth.crack_length`), λ_c(a_k) at the lengths a_k. Read under a load that
only rises (load control):

- the **first growth load** λ_0 = λ_c(a_0);
- growth from a_k to a_k+1 is **stable** where λ_c(a_k+1) > λ_c(a_k) (more load is needed to
  go on) and **unstable** where it falls (the debond runs on at the load reached);
- at λ_0 the debond **arrests** at the first length whose onset load exceeds λ_0, or runs
  through the whole growth range when none does;
- the **residual strength** is the largest load on the growth path: the largest onset load or
  the largest load a path passed before its onset (a load maximum of the structure itself).
  When the debond arrests within the scene's load range, the path at the arrested length goes
  on to the scene's end and the strength is at least its last load (``bounded`` is false).
"""

from __future__ import annotations

from sandwich.fracture import CRITERION
from sandwich.results import StepRecord
from sandwich.scene import Scene

METHOD = ("crack-length control: each tip advances by the debond's growth step at the load "
          "where its G (virtual crack closure) reaches G_c")


ONSET = "onset"  # history column: 1 on an onset state, 0 (or absent) on a path state


def onset_rows(rows: list[StepRecord]) -> list[StepRecord]:
    """The envelope: the rows that are onset states (``onset`` = 1, also when read back)."""
    return [r for r in rows if r.extra.get(ONSET) == 1.0]


def growth_summary(scene: Scene, rows: list[StepRecord], stages: int,
                   stopped: str) -> dict[str, object]:
    """The ``debond_growth`` entry of a growth run's ``summary.json``."""
    onsets = onset_rows(rows)
    out: dict[str, object] = {"method": METHOD, "criterion": CRITERION, "stages": stages + 1,
                              "stopped": stopped, "onsets": len(onsets)}
    tips = {}
    for i, d in enumerate(scene.debonds):
        if d.growth is None:
            continue
        last = rows[-1].extra if rows else {}
        tips[str(i)] = {"step_mm": d.growth.step, "from": [d.start, d.end],
                        "to": [float(last.get(f"tip_{i}_start", d.start)),
                               float(last.get(f"tip_{i}_end", d.end))]}
    out["debonds"] = tips
    if not onsets:
        out.update(first_growth_load=None, residual_strength=None, bounded=False,
                   arrest_at_first_growth_load=None, unstable_steps=0, stable_steps=0)
        return out
    lam0 = onsets[0].load_factor
    arrested = "no tip reaches G_c" in stopped
    strength = max(max(float(r.extra["peak_load_factor"]) for r in onsets),
                   max(r.load_factor for r in rows))
    falls = sum(b.load_factor < a.load_factor for a, b in zip(onsets, onsets[1:], strict=False))
    arrest = next((r for r in onsets[1:] if r.load_factor > lam0), None)
    if arrest is None and arrested:
        arrest = rows[-1]  # the last length: it needs more load than the scene applies
    out.update(
        first_growth_load=lam0, residual_strength=strength, bounded=not arrested,
        stable_steps=len(onsets) - 1 - falls, unstable_steps=falls,
        arrest_at_first_growth_load=None if arrest is None else {
            k: float(v) for k, v in arrest.extra.items() if k.startswith("tip_")})
    return out
