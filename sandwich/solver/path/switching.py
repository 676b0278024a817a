"""Going on on a finer system from a converged state: the path's refinement hook.

A caller may pass :func:`~.follower.follow_path` a ``refine(state, system)`` hook, asked at
every converged state (after its critical points are located). Where it returns a
:class:`~.records.Refinement`, the path goes on on the refinement's system: the last state is
replaced by the one re-converged there (same step number), every earlier state and the last
step are carried over by the refinement's ``transfer``, and the follower's measures (probe
vectors, reference load, inner product, return guard) are the new system's. A rewinding
refinement (a critical point was located within the last step) replaces an earlier state, and
the steps after it are taken again on the new system.

The critical points are searched segment by segment (:meth:`~.state.FollowerState.finish`): a
state re-converged on a finer system is not a step of the path, so the change of load or of the
tangent's inertia across a switch is never reported as a limit point or a bifurcation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from sandwich.solver.path.guards import ReturnGuard
from sandwich.solver.path.records import PathState, Refinement
from sandwich.solver.path.state import FollowerState
from sandwich.solver.system import Factorization, inner_product

__all__ = ["RefineHook", "SystemSwitch"]

#: ``refine(state, system)``: a finer system continued from ``state``, or None to go on as is.
RefineHook = Callable[[PathState, object], Refinement | None]


class SystemSwitch(FollowerState):
    """The switch to a finer system (:meth:`switch_system`)."""

    refine: RefineHook | None = None

    def switch_system(self, state: PathState) -> tuple[Factorization, np.ndarray] | None:
        """Ask the hook about ``state`` (the last); on a refinement, go on on its system.

        Returns the factorised tangent and the load tangent ``K⁻¹ f_ref`` at the re-converged
        state, or None where the path goes on as it is. A rewinding refinement drops the states
        after the one it replaces.
        """
        if self.refine is None:
            return None
        found = self.refine(state, self.system)
        if found is None:
            return None
        del self.states[len(self.states) - found.rewind:]
        old = self.states[-1]
        move = found.transfer
        self.system = found.system
        self.dot = inner_product(found.system)
        self.c = {n: np.asarray(found.system.probe_vector(n), dtype=float) for n in self.c}
        self.f_ref = np.asarray(found.system.f_ref, dtype=float)
        admissible = getattr(found.system, "admissible", None)
        self.admissible = admissible if callable(admissible) else None
        columns = getattr(found.system, "state_columns", None)
        self.state_columns = columns if callable(columns) else None
        self.states[:-1] = [dataclasses.replace(s, u=move(s.u)) for s in self.states[:-1]]
        if found.rewind:  # the step that ended at the state now last, carried over
            before = self.states[-2] if len(self.states) >= 2 else None
            self.prev_step = None if before is None else (
                move(old.u) - before.u, old.load_factor - before.load_factor)
        elif self.prev_step is not None:
            self.prev_step = (move(self.prev_step[0]), self.prev_step[1])
        self.bent = self.kept_half = None  # trials of the old system
        fac = found.factorization
        new = dataclasses.replace(
            old, u=np.array(found.u, dtype=float, copy=True),
            load_factor=float(found.load_factor),
            iterations=old.iterations + int(found.iterations),
            probes=self.probes(found.u), negative_pivots=fac.negative_pivots, extra={})
        self.states[-1] = new
        self.system.commit(new.u.copy(), new.load_factor)
        if self.state_columns is not None:
            new.extra.update(self.state_columns(new.u))
        self.switches.append((len(self.states) - 1, old))
        self.return_guard = ReturnGuard(self.dot, self.psi)
        t = np.asarray(fac.solve(self.f_ref), dtype=float)
        new.probe_rate = self.probe_rate(t)
        return fac, t
