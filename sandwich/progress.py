"""A progress display for path following, driven by the solver's per-step callback."""

from __future__ import annotations

import sys
import time
from typing import Any

from sandwich.scene import Scene


class PathProgress:
    """Show how far along its ``until`` target a run is (a tqdm bar on stderr).

    The fraction is the until probe's value over its target, or λ over the target load factor.
    Use as a context manager and pass the instance as the solver's ``progress`` callback. When
    ``stream`` is not a terminal (a log file, CI), the bar becomes one line per tenth of the way
    or per ``LINE_SECONDS``, whichever comes first, instead of redrawing.
    """

    LINE_SECONDS = 30.0

    def __init__(self, scene: Scene, label: str, quiet: bool = False, stream: Any = None):
        self.scene = scene
        self.label = label
        self.quiet = quiet
        self.stream = sys.stderr if stream is None else stream
        self.bar: Any = None
        self.last_step = 0
        self.lines = not quiet and not _is_terminal(self.stream)
        self._last_line = (-1, 0.0)  # tenth shown, time

    def __enter__(self) -> PathProgress:
        if not self.quiet and not self.lines:
            from tqdm import tqdm

            self.bar = tqdm(total=1000, desc=self.label, file=self.stream, leave=True,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix}")
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.close()

    def fraction(self, load_factor: float, probes: dict[str, float]) -> float:
        """Fraction of the way to the target, clipped to [0, 1]."""
        a = self.scene.analysis
        if a.until_probe is not None and a.until_value and a.until_probe in probes:
            f = probes[a.until_probe] / a.until_value
        elif a.until_load_factor:
            f = load_factor / a.until_load_factor
        else:
            f = 0.0
        return min(max(f, 0.0), 1.0)

    def __call__(self, state: Any) -> None:
        """Per-step callback: ``state`` has ``step``, ``load_factor`` and ``probes``."""
        self.last_step = int(getattr(state, "step", self.last_step + 1))
        note = getattr(state, "message", None)  # an event that is not a step (e.g. a rerun)
        if isinstance(note, str) and note:
            if self.bar is not None:
                self.bar.write(f"{self.label}: {note}")
            elif self.lines:
                print(f"{self.label}: {note}", file=self.stream, flush=True)
                self._last_line = (-1, 0.0)  # the path restarts: so do the lines
        lam = float(getattr(state, "load_factor", 0.0))
        probes = dict(getattr(state, "probes", {}) or {})
        if self.lines:
            self._line(lam, probes)
            return
        if self.bar is None:
            return
        target = int(round(1000 * self.fraction(lam, probes)))
        self.bar.n = target
        shown = ", ".join(f"{k}={v:.4g}" for k, v in list(probes.items())[:2])
        extra = f", {shown}" if shown else ""
        self.bar.set_postfix_str(f"step {self.last_step}, λ={lam:.4g}{extra}")
        self.bar.refresh()

    def _line(self, lam: float, probes: dict[str, float]) -> None:
        """One plain line per tenth of the way, or per ``LINE_SECONDS``."""
        tenth = int(10 * self.fraction(lam, probes))
        now = time.monotonic()
        shown, at = self._last_line
        if tenth <= shown and now - at < self.LINE_SECONDS:
            return
        self._last_line = (tenth, now)
        pct = 100 * self.fraction(lam, probes) + 0.0  # no "-0%"
        print(f"{self.label}: {pct:3.0f}% step {self.last_step}, λ={lam:.4g}", file=self.stream,
              flush=True)


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False
