"""The follower's state, shared by all its parts: the system, the options, the path so far.

:class:`FollowerState` is the base of every part of :class:`~.follower.PathFollower`: it holds
what they all read (and the arc's sign, the previous step, the flags they set), records and
commits converged states (:meth:`~FollowerState.accept`), and measures states and steps
(probes, the arc's norm, the step in the control's units, the targets a step crossed).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from sandwich.solver.limits import find_limit_points
from sandwich.solver.path.options import PathOptions
from sandwich.solver.path.records import PathResult, PathState, Trial
from sandwich.solver.system import DiscreteSystem, inner_product

__all__ = ["FollowerState"]


class FollowerState:
    """The state of one :func:`~.follower.follow_path` call.

    Attributes
    ----------
    system, opt, progress
        The model, the options and the caller's per-state callback.
    dot
        The system's inner product (global over MPI ranks if it provides one).
    c, f_ref
        The probe vectors by name (the until and driven probes included) and the reference load.
    states
        The converged states so far (state 0 first).
    switches
        Where the path went on on a finer system (:mod:`.switching`): the index of the state
        re-converged there and that state as it was before.
    admissible, state_columns
        The system's optional hooks (:class:`~sandwich.solver.system.OptionalHooks`), None
        where it lacks them.
    rescues
        The steps taken by the probe rescue (:mod:`.rescue`).
    psi, lam_est, curve_probe, rate_probe
        Set once the linear solution is known (:meth:`~.follower.PathFollower.converged_states`):
        ψ of the arc's norm ‖(Δu, ψΔλ)‖, the target's load estimated from the linear solution,
        the load curve's probe with its linear value at that load (:mod:`.step_size`), the probe
        whose dw/dλ the states record.
    sigma, prev_step
        The arc's sign (forward along the path) and the last accepted step ``(Δu, Δλ)``.
    recent, peak
        The probe rescue's memory: (increment, until-probe change) of the last accepted steps,
        the largest accepted increment.
    divergence_rises
        The corrector's rising test for a step's first attempts (0: off for the rest of the path).
    failed_once
        A corrector of this path has failed (contact-limited corrections from then on).
    bent, kept_half
        A step cut as bent: (start step, converged state); that state while it is the step
        being accepted (:mod:`.step_size`).
    """

    failed_once = False  # a corrector of this path has failed
    curve_probe: tuple[str | None, float] = (None, 0.0)  # set once the linear solution is known
    rate_probe: str | None = None  # set once the linear solution is known
    bent: tuple[int, Trial] | None = None  # (start step, converged state) of a step cut as BENT
    kept_half: Trial | None = None  # that state, while it is the step being accepted

    def __init__(
        self,
        system: DiscreteSystem,
        options: PathOptions,
        probe_names: Sequence[str],
        progress: Callable[[PathState], None] | None,
    ) -> None:
        self.system = system
        self.dot = inner_product(system)  # global over MPI ranks if the system provides it
        self.opt = options
        self.progress = progress
        names = list(dict.fromkeys([*probe_names, *(n for n in (options.until_probe,
                                                                 options.driven_probe) if n)]))
        self.c = {n: np.asarray(system.probe_vector(n), dtype=float) for n in names}
        self.f_ref = np.asarray(system.f_ref, dtype=float)
        self.states: list[PathState] = []
        self.rescues: list[int] = []
        admissible = getattr(system, "admissible", None)
        self.admissible = admissible if callable(admissible) else None
        columns = getattr(system, "state_columns", None)
        self.state_columns = columns if callable(columns) else None
        # (index of a state re-converged on a finer system, that state as it was before)
        self.switches: list[tuple[int, PathState]] = []

    # -- measures --------------------------------------------------------------------------------
    def probes(self, u: np.ndarray) -> dict[str, float]:
        """Every probe's value ``c · u``."""
        return {n: self.dot(c, u) for n, c in self.c.items()}

    def value(self, name: str, u: np.ndarray, lam: float) -> float:
        """The value of a target's quantity: λ for ``"λ"``, else the probe ``name``."""
        return lam if name == "λ" else self.dot(self.c[name], u)

    def wnorm(self, du: np.ndarray, dlam: float) -> float:
        """The arc's norm ‖(Δu, ψΔλ)‖."""
        return math.sqrt(self.dot(du, du) + (self.psi * dlam) ** 2)

    def increment(self, last: PathState, trial: Trial | PathState) -> float:
        """The step from ``last`` to ``trial`` in the units of the control (h's)."""
        dl = trial.load_factor - last.load_factor
        if self.opt.control == "load":
            return abs(dl)
        if self.opt.control == "displacement":
            name = self.opt.driven_probe
            return abs(self.value(name, trial.u, 0.0) - last.probes[name])
        return self.wnorm(trial.u - last.u, dl)

    def probe_rate(self, t: np.ndarray) -> float | None:
        """dw/dλ = c·t of the load curve's probe w (:attr:`rate_probe`) for the load tangent t."""
        if self.rate_probe is None:
            return None
        rate = self.dot(self.c[self.rate_probe], t)
        return float(rate) if math.isfinite(rate) else None

    def crossings(self, last: PathState, trial: Trial) -> list[tuple[float, str, float]]:
        """Targets crossed between ``last`` and ``trial``: (linear fraction, name, target)."""
        out = []
        pairs = []
        if self.opt.until_load_factor is not None:
            pairs.append(("λ", self.opt.until_load_factor, last.load_factor, trial.load_factor))
        if self.opt.until_probe is not None:
            c = self.c[self.opt.until_probe]
            pairs.append((self.opt.until_probe, self.opt.until_value,
                          last.probes[self.opt.until_probe], self.dot(c, trial.u)))
        for name, target, a, b in pairs:
            if (a - target) * (b - target) <= 0.0 and a != b:
                out.append(((target - a) / (b - a), name, target))
        return sorted(out)

    # -- the record ------------------------------------------------------------------------------
    def accept(self, u: np.ndarray, lam: float, its: int, neg: int | None,
               cuts: int) -> PathState:
        """Record and commit a converged state; return it (the caller yields it)."""
        state = PathState(len(self.states), u.copy(), float(lam), its, self.probes(u), neg, cuts)
        self.states.append(state)
        self.system.commit(state.u.copy(), state.load_factor)
        if self.state_columns is not None:
            state.extra.update(self.state_columns(state.u))
        return state

    def finish(self, reached: bool, message: str) -> PathResult:
        """The :class:`~.records.PathResult` of the states so far, with ``message`` completed."""
        opt = self.opt
        warnings = []
        if (opt.until_probe is not None and opt.until_load_factor is None and self.states
                and self.states[-1].load_factor < 0
                and not any(s.load_factor > 0 for s in self.states)):
            # The probe's target lies the other way from where the loads push it: the follower
            # heads for it with λ < 0, which a user rarely means (a sign slip in until or force).
            # (Not said of a path that came back through zero load: no sign slip sends it there.)
            warnings.append(f"{opt.until_probe} heads for {opt.until_value:g} only with λ < 0: "
                            "every load's force is reversed (check the sign of "
                            "analysis.until's value and of the loads' force)")
        if self.rescues:
            message += (f" ({len(self.rescues)} step(s) taken under control of "
                        f"{self.opt.until_probe} where the arc collapsed at a critical point: "
                        f"step(s) {', '.join(map(str, self.rescues))})")
        return PathResult(self.states, reached, message, self._limit_points(), warnings)

    def _limit_points(self) -> list:
        """The critical points of each stretch of the path on one system (:mod:`.switching`)."""
        found, start = [], 0
        for index, old in self.switches:
            found += find_limit_points([*self.states[start:index], old])
            start = index
        return found + find_limit_points(self.states[start:])
