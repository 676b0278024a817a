"""Debond growth by crack-length control: the load at which each debond length starts to grow.

For a debond of a given length the structure is elastic (frictionless contact, no damage), so
its equilibrium at a load does not depend on how it got there. Growth under the
Benzeggagh–Kenane criterion with the model's own G (virtual crack closure) is then traced as a
sequence of lengths instead of in time (the crack-length control of fracture mechanics):

1. solve the scene's path at the current debond lengths with the model;
2. find, for every growing tip, the first state where G reaches G_c
   (:func:`~sandwich.growth.crossing.first_crossing`); the tip that gets there first along the
   path advances by the debond's ``growth.step`` and that critical state is kept;
3. repeat until no tip reaches G_c before the path's end (the debond arrests within the scene's
   load range), a tip comes within a step of a beam end or another debond, or the debond is
   ``max_length`` long.

The kept states are the growth envelope: load factor and probes at the onset of growth at each
length. A falling load from one length to the next is unstable growth (under load control the
debond runs on to the next length that needs more load); the largest load on the envelope
(or on a path before its crossing, where the structure passes a load maximum first) is the
residual strength (:mod:`sandwich.growth.envelope`). Each path is the model's ordinary solve
(its own resolution and accuracy controls), so both models grow the same debonds from the same
scene.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable

from sandwich.growth.crossing import Crossing, criterion_ratio, first_crossing
from sandwich.growth.envelope import ONSET, growth_summary
from sandwich.growth.locate import (
    ONSET_RTOL,
    located,
    needs_solving,
    predicted_target,
    target_quantity,
    with_target,
)
from sandwich.results import PathNote, ProgressItem, Solution, StepRecord
from sandwich.results.fracture import column_names
from sandwich.scene import Debond, Scene

Solve = Callable[..., Solution]
TIPS = ("start", "end")
GEOMETRY_MARGIN = 1e-9  # mm: a tip closer than this to a beam end is an open mouth


def growing(scene: Scene) -> bool:
    """Whether any debond of ``scene`` asks to be grown by crack-length control."""
    return any(d.growth is not None and not d.growth.cohesive for d in scene.debonds)


def tip_column(debond: int, tip: str) -> str:
    """History column of a tip's position (mm) in a growth run."""
    return f"tip_{debond}_{tip}"


def open_tips(scene: Scene, i: int) -> tuple[str, ...]:
    """The tips of debond ``i`` that may grow: not at a beam end (an open mouth has no G)."""
    d = scene.debonds[i]
    return tuple(t for t, x in zip(TIPS, (d.start, d.end), strict=True)
                 if GEOMETRY_MARGIN < x < scene.length - GEOMETRY_MARGIN)


def room(scene: Scene, i: int, tip: str) -> float:
    """How far tip ``tip`` of debond ``i`` may still advance (mm).

    Up to one growth step short of a beam end or of the next debond on the same interface, and
    within the debond's ``max_length`` (this tip alone).
    """
    d = scene.debonds[i]
    step = d.growth.step
    others = [o for j, o in enumerate(scene.debonds) if j != i and o.interface == d.interface]
    if tip == "end":
        bound = min([scene.length] + [o.start for o in others if o.start > d.end])
        free = bound - step - d.end
    else:
        bound = max([0.0] + [o.end for o in others if o.end < d.start])
        free = d.start - (bound + step)
    if d.growth.max_length is not None:
        free = min(free, d.growth.max_length - d.length)
    return free


def advanced(scene: Scene, i: int, tip: str, by: float) -> Scene:
    """``scene`` with tip ``tip`` of debond ``i`` moved ``by`` mm outwards."""
    d = scene.debonds[i]
    moved: Debond = (dataclasses.replace(d, end=d.end + by) if tip == "end"
                     else dataclasses.replace(d, start=d.start - by))
    debonds = tuple(moved if j == i else o for j, o in enumerate(scene.debonds))
    return dataclasses.replace(scene, debonds=debonds)


def tip_positions(scene: Scene) -> dict[str, float]:
    """The growth history's tip columns: every tip of every growing debond (mm)."""
    out = {}
    for i, d in enumerate(scene.debonds):
        if d.growth is not None:
            out[tip_column(i, "start")] = d.start
            out[tip_column(i, "end")] = d.end
    return out


def grow(scene: Scene, solve: Solve, progress: Callable[[ProgressItem], None] | None = None
         ) -> Solution:
    """Grow every debond with ``growth`` by crack-length control; the envelope as a Solution.

    ``solve(scene, progress=None)`` is one model's solve. The history holds the first path up
    to the onset of growth, then one state per length: the load, probes and G where that length
    starts to grow, with the tip positions (``tip_<debond>_<tip>``, mm) and the stage; the path
    at the last length follows when the debond arrests. Profiles and fields are those of the
    last path, at its last state before growth (or at its end where it arrests).
    """
    say = progress or (lambda item: None)
    t0 = time.perf_counter()
    rows: list[StepRecord] = []
    # each stage's path ends at the scene's target, not at its onset: a 2D mesh estimate there
    # would measure the wrong state, at the cost of another path per stage
    stage, current = 0, dataclasses.replace(
        scene, reference2d=dataclasses.replace(scene.reference2d, error_estimate=False))
    last_solution: Solution | None = None
    last_cut: int | None = None
    stopped = ""
    failed: str | None = None
    warnings: list[str] = []
    onsets: list[float] = []  # the until quantity at each onset (where the next is looked for)
    limit = sum(math.ceil(max(room(scene, i, t), 0.0) / scene.debonds[i].growth.step) + 1
                for i, d in enumerate(scene.debonds) if d.growth is not None
                for t in open_tips(scene, i))
    while True:
        say(PathNote(f"growth stage {stage}: " + _lengths(current), restart=False))
        inner = None  # a stage's own path states are not the growth run's: not streamed
        try:
            solution, first = _stage(current, solve, predicted_target(current, onsets))
        except KeyboardInterrupt:
            raise KeyboardInterrupt("interrupted during a growth stage") from None
        except Exception as exc:  # a failing path ends the growth; the kept stages stay
            failed = f"{type(exc).__name__}: {exc}"
            stopped = f"the path at stage {stage} ({_lengths(current)}) failed: {failed}"
            break
        there = None
        if first is not None and needs_solving(current, first, solution.history):
            first, there = located(current, solve, first, solution.history, inner)
            if there is None:
                warnings.append(f"stage {stage}: the onset is interpolated across a step from "
                                f"λ {first.bracket[0]:.6g} to {first.bracket[1]:.6g} (a path "
                                "stopped on it did not converge)")
            else:
                solution = there
        last_solution = solution
        if first is None and not _carries_g(current, solution.history):
            failed = solution.extra.get("G_warning") or "no G at the growing tips"
            stopped = (f"the path at stage {stage} ({_lengths(current)}) gives no G at the "
                       f"growing tips, so their growth cannot be judged: {failed}")
            break
        if first is None:
            end = solution.history[-1].load_factor if solution.history else 0.0
            why = "reached its end" if solution.converged else f"stopped ({solution.message})"
            stopped = (f"no tip reaches G_c at stage {stage} ({_lengths(current)}): the path "
                       f"{why} at λ {end:.6g} first")
            rows.extend(_tail(solution.history, rows, current))
            last_cut = None
            break
        if stage == 0:
            rows.extend(_record(r, current, stage) for r in solution.history[: first.index + 1])
        tips = _together(current, first, solution.history, there is not None)
        onsets.append(target_quantity(current)(solution.history[-1]) if there is not None
                      else first.probes.get(current.analysis.until_probe, first.load_factor)
                      if current.analysis.until_probe is not None else first.load_factor)
        rows.append(_crossing_row(first, tips, solution.history, current, stage, rows,
                                 there is not None))
        say(rows[-1])
        last_cut = first.index + 1 if there is not None else first.index
        ahead = current
        for i, t in tips:
            ahead = advanced(ahead, i, t, current.debonds[i].growth.step)
        why = _no_room(current, ahead, tips)
        if why or stage + 1 >= limit:
            stopped = f"{why or 'the stage limit'}, at stage {stage} ({_lengths(current)})"
            break
        current = ahead
        stage += 1
    base = last_solution
    profiles, fields = _last_frames(base, last_cut, rows)
    # the paths' limit points are numbered along their own paths, not the envelope's: the
    # summary's debond_growth holds the peak loads instead
    out = Solution(
        base.model if base else "?", scene.name, rows, profiles, failed is None,
        f"growth by crack-length control: {stopped}", [], time.perf_counter() - t0,
        base.dofs if base else 0, fields=fields,
        warnings=(list(base.warnings) if base else []) + warnings)
    if base is not None:  # what the last path says of itself (the beam's core levels, …)
        out.extra.update({k: v for k, v in base.extra.items() if k != "debond_growth"})
    out.extra["debond_growth"] = growth_summary(scene, rows, stage, stopped)
    return out


def final_scene(scene: Scene, solution: Solution) -> Scene:
    """``scene`` with its growing debonds at the lengths of the growth run's last state."""
    if not solution.history:
        return scene
    last = solution.history[-1].extra
    debonds = []
    for i, d in enumerate(scene.debonds):
        if d.growth is not None and tip_column(i, "start") in last:
            d = dataclasses.replace(d, start=float(last[tip_column(i, "start")]),
                                    end=float(last[tip_column(i, "end")]))
        debonds.append(d)
    return dataclasses.replace(scene, debonds=tuple(debonds))


def _carries_g(scene: Scene, history: list[StepRecord]) -> bool:
    """Whether some state of ``history`` has G at a growing tip of ``scene``."""
    names = [column_names(i, t)[0] for i, d in enumerate(scene.debonds) if d.growth is not None
             for t in open_tips(scene, i)]
    return any(r.extra.get(n) is not None for r in history for n in names)


def _stage(scene: Scene, solve: Solve, target: float | None
           ) -> tuple[Solution, Crossing | None]:
    """One length's path and its first crossing: up to ``target`` first, then to the end.

    ``target`` (the ``until`` quantity, :func:`~sandwich.growth.locate.predicted_target`)
    shortens the path where the onset is expected; where no tip reaches G_c by then, the path
    is solved to the scene's own target.
    """
    if target is not None:
        solution = solve(with_target(scene, target))
        first = _first(scene, solution.history)
        if first is not None:
            return solution, first
    solution = solve(scene)
    return solution, _first(scene, solution.history)


def _first(scene: Scene, history: list[StepRecord]) -> Crossing | None:
    """The crossing that comes first along the path among every growing tip's."""
    found = [c for i, d in enumerate(scene.debonds) if d.growth is not None
             for t in open_tips(scene, i)
             if (c := first_crossing(d.toughness, history, i, t)) is not None]
    return min(found, key=lambda c: c.position) if found else None


def _no_room(scene: Scene, ahead: Scene, tips: list[tuple[int, str]]) -> str:
    """Why ``ahead`` (``scene`` with ``tips`` advanced) cannot be; ``""`` if it can.

    A tip may come no closer than one step to a beam end or to another debond on its
    interface, and a debond may be no longer than its ``max_length``.
    """
    for i, t in tips:
        d, new = scene.debonds[i], ahead.debonds[i]
        most = d.growth.max_length
        if most is not None and new.length > most + GEOMETRY_MARGIN:
            return (f"debond {i} is {d.length:g} mm long: another step would pass its "
                    f"max_length {most:g}")
        if room(scene, i, t) - d.growth.step < -GEOMETRY_MARGIN and (
                most is None or d.length + d.growth.step <= most + GEOMETRY_MARGIN):
            return (f"debond {i} cannot grow its {t} tip by another step of {d.growth.step:g} "
                    "mm (it would come within a step of a beam end or another debond)")
    return ""


def _together(scene: Scene, first: Crossing, history: list[StepRecord],
              at_end: bool) -> list[tuple[int, str]]:
    """The tips that reach G_c at the onset ``first`` (it and any other there within tolerance).

    ``at_end``: the onset is the last state of ``history`` (solved for); otherwise interpolated.
    """
    out = [(first.debond, first.tip)]
    for i, d in enumerate(scene.debonds):
        if d.growth is None:
            continue
        for t in open_tips(scene, i):
            if (i, t) == out[0]:
                continue
            if at_end:
                r = criterion_ratio(d.toughness, history[-1], i, t)
                if r is not None and r >= 1.0 - ONSET_RTOL:
                    out.append((i, t))
            else:
                c = first_crossing(d.toughness, history, i, t)
                if (c is not None and c.index == first.index and abs(c.load_factor
                        - first.load_factor) <= ONSET_RTOL * abs(first.load_factor)):
                    out.append((i, t))
    return out


def _record(r: StepRecord, scene: Scene, stage: int) -> StepRecord:
    """A path state in the growth history: renumbered later, with tip positions and stage."""
    return StepRecord(r.step, r.load_factor, dict(r.probes), r.iterations,
                      {**r.extra, **tip_positions(scene), "stage": float(stage)})


def _crossing_row(c: Crossing, tips: list[tuple[int, str]], history: list[StepRecord],
                  scene: Scene, stage: int, rows: list[StepRecord], at_end: bool) -> StepRecord:
    """The onset state of a stage, numbered after the rows kept so far.

    ``at_end``: solved for, the last state of ``history`` (all its columns); otherwise
    interpolated (the probes and the G of the tip that reached G_c first).
    """
    extra = dict(history[-1].extra) if at_end else {}
    for i, t in tips:  # interpolated: each onset tip's own crossing in the same step
        own = c if (i, t) == (c.debond, c.tip) or at_end else first_crossing(
            scene.debonds[i].toughness, history, i, t)
        if not at_end or own is c:
            extra.update(zip(column_names(i, t), (own.G, own.GI, own.GII), strict=True))
    extra |= {**tip_positions(scene), "stage": float(stage),
             ONSET: 1.0, "Gc": c.Gc, "peak_load_factor": c.peak_load,
             "onset_bracket": c.bracket[1] - c.bracket[0]}
    step = rows[-1].step + 1 if rows else 0
    return StepRecord(step, c.load_factor, dict(c.probes), history[c.index].iterations, extra)


def _tail(history: list[StepRecord], rows: list[StepRecord], scene: Scene) -> list[StepRecord]:
    """The path at the arrested length beyond the last kept load, numbered after the rows."""
    if not rows:
        return [_record(r, scene, 0) for r in history]
    start = next((j for j, r in enumerate(history) if r.load_factor > rows[-1].load_factor),
                 len(history))
    stage = int(rows[-1].extra.get("stage", 0)) + 1
    return [dataclasses.replace(_record(r, scene, stage), step=rows[-1].step + 1 + k)
            for k, r in enumerate(history[start:])]


def _last_frames(solution: Solution | None, cut: int | None, rows: list[StepRecord]):
    """Profiles and fields of the last path at its onset (or its end), renumbered to the last row.

    ``cut`` is the index of the onset state in the path (where it was solved for) or of the
    state before it (interpolated); each kind of frame is taken at the latest step up to it that
    has one (a model may write profiles only at some steps).
    """
    if solution is None or not rows or not solution.history:
        return [], []
    limit = solution.history[-1 if cut is None else cut].step

    def latest(frames):
        steps = [f.step for f in frames if f.step <= limit]
        return ([dataclasses.replace(f, step=rows[-1].step) for f in frames
                 if f.step == max(steps)] if steps else [])

    return latest(solution.profiles), latest(solution.fields)


def _lengths(scene: Scene) -> str:
    """The growing debonds' stretches, for messages."""
    return ", ".join(f"debond {i} [{d.start:g}, {d.end:g}]"
                     for i, d in enumerate(scene.debonds) if d.growth is not None)
