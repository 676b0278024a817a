"""The memory guard of the command line: refuse a run that cannot fit, before any work.

The estimate of a run's peak memory (:mod:`sandwich.models.memory`, calibrated by
``benchmarks/memory_guard.py``) is compared with the memory available now
(:func:`sandwich.models.memory.available_bytes`). Above it the run is refused (exit code 2) with
the file,
the key that sets the size (or the command-line option that overrode it), both numbers and what
to lower; above :data:`WARN_FRACTION` of it a warning is printed before the run. When the
available memory cannot be read (no ``/proc/meminfo``), nothing is checked.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from sandwich.models import memory
from sandwich.scene import Problem, Scene

WARN_FRACTION = 0.5  # warn when a run is estimated to need more than this share of what is free


@dataclass(frozen=True)
class MemoryVerdict:
    """What the guard says of one run: a refusal, a warning, or neither."""

    refusal: Problem | None = None
    warning: str | None = None


def _gb(n: float) -> str:
    return f"{n / memory.GB:.2f} GB" if n < 10 * memory.GB else f"{n / memory.GB:.0f} GB"


def check_memory(scene: Scene, what: str, options: Mapping[str, str] | None = None, *,
                 copies: int = 1, where: str | None = None, label: str = "") -> MemoryVerdict:
    """Judge the run ``what`` (``"beam"``, ``"2d"`` or ``"mesh"``) of ``scene``.

    Parameters
    ----------
    scene
        The scene as it will be run (command-line overrides applied).
    what
        The model solved, or ``"mesh"``.
    options
        Scene keys overridden on the command line, and the option that did it
        (``{"beam_model.elements": "--elements"}``): the refusal names the option.
    copies
        Runs at once (a study's workers): the estimate is multiplied by it.
    where
        File named in the refusal (default: the scene's file).
    label
        Words put before the reason (a study's case).
    """
    available = memory.available_bytes()
    if available is None or what not in memory.ESTIMATES:
        return MemoryVerdict()
    try:
        est = memory.estimate(scene, what)
    except (ValueError, ArithmeticError):  # a layout the mesher refuses: it says why itself
        return MemoryVerdict()
    options = options or {}
    need = est.peak_bytes * copies
    key = options.get(est.keys[0], est.keys[0])
    others = [options.get(k, k) for k in est.keys[1:]]
    runs = f" ({copies} at once)" if copies > 1 else ""
    said = ((f"{label}: " if label else "") + f"the {est.what}{runs} needs about "
            f"{_gb(need)}, {{}} the {_gb(available)} of memory available now: {est.detail}")
    if need > available:
        reason = (said.format("more than") + f"; lower {key} (or {', '.join(others)})"
                  + (" or the workers" if copies > 1 else ""))
        return MemoryVerdict(refusal=Problem(where or str(scene.source), key, reason))
    if need > WARN_FRACTION * available:
        return MemoryVerdict(warning=f"{key}: " + said.format(
            f"{100 * need / available:.0f} % of"))
    return MemoryVerdict()
