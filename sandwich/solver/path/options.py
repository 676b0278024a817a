"""How a path is followed and when it stops: :class:`PathOptions`."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from sandwich.scene import CONTROLS, Analysis, PathControls

__all__ = ["ANALYSIS_FIELDS", "CONTROLS", "PathOptions"]


@dataclass(frozen=True)
class PathOptions(PathControls):
    """How to follow the path and when to stop.

    The scene's :class:`~sandwich.scene.PathControls` and the solver's own settings.

    Attributes
    ----------
    control
        ``"load"``, ``"displacement"`` (of :attr:`control_probe`) or ``"arc-length"``.
    until_load_factor
        Stop when λ reaches this value (hit exactly).
    until_probe, until_value
        Stop when this probe reaches this value (hit within :attr:`target_tol`).
    max_steps
        Largest number of steps after state 0.
    initial_increment
        First increment in the units of the control; ``None``: 1/20 of the target estimated with
        the linear solution.
    min_increment, max_increment
        Bounds of the increment; ``None``: ``1e-4`` and ``10`` times the initial increment.
    tol
        Relative residual tolerance of Newton (the increment tolerance is ``√tol``).
    max_iterations
        Newton corrections allowed per step.
    desired_iterations
        Iteration count for which the increment is kept; fewer grow it, more shrink it.
    settling_allowance
        ``None`` (default): the controller weighs a step by all its corrector's iterations.
        A number k (the beam's ``[beam_model] settling_allowance``, 2 by default): until the
        path's first failed corrector and where the load curve is straight, by at most the
        iterations its increment test took to pass plus k (:mod:`.step_size`;
        docs/solver.md "Settling iterations").
    control_probe
        Probe driven under displacement control (default: :attr:`until_probe`).
    arc_load_weight
        ψ / ‖K(0)⁻¹ f_ref‖ in the arc-length norm (0: cylindrical arc).
    max_correction_ratio, max_predictor_growth
        Jump guards (:mod:`sandwich.solver.path`; :meth:`.attempts.StepAttempts.attempt`).
    min_step_cosine
        Retrace guard: a converged step whose displacement increment has a cosine below this
        with the previous step's is rejected (0: no turn by more than 90° in one step; ``-1``
        switches the guard off).
    probe_rescue
        Arc-length with an ``until_probe``: when the arc collapses at a critical point (a failed
        step cut below ``RESCUE_FRACTION`` of the largest increment accepted so far), try one
        step under control of that probe, as long as its largest change over the last
        ``RESCUE_MEMORY`` steps, towards the target (what a testing machine driving that point
        does); the message counts such steps.
    target_tol
        Relative tolerance on hitting ``until_value`` / ``until_load_factor`` by step cutting.
    target_accept
        If the crossed target cannot be hit within ``target_tol`` (corrector failures on the
        shortened steps), the closest state is still accepted as reaching the target when it
        misses by at most this (relative); the message says by how much.
    stop_at_load_reversal
        Stop (not reached) at the first converged state whose λ has the other sign than the
        state before's: the path has come back through the unloaded state. Off by default (a
        snap-through may cross λ = 0 and come back); the beam's ``auto`` core levels set it on
        its reruns, which check a pass that never crossed it (docs/solver.md).
    locate_critical_points
        Narrow a step across a bifurcation or a load extremum by equilibria solved inside it:
        shorter steps from the state before (the path's own predictor and corrector, up to
        :data:`~sandwich.solver.critical.MAX_SUBSTEPS`), aimed where the crossed eigenvalue is
        interpolated to be zero (the load curve's slope, for an extremum), until the located
        load moves by less than :data:`~sandwich.solver.critical.LOCATE_RTOL`. They are not
        path states (the path is the same with or without). Off by default: the point is then
        located within its step from the step's two states (no corrector; second order in the
        step for a bifurcation, :meth:`~.critical_points.CriticalPoints.locate_crossing`;
        fourth for an extremum, :meth:`~.critical_points.CriticalPoints.locate_extremum`).
    """

    desired_iterations: int = 5
    settling_allowance: int | None = None
    control_probe: str | None = None
    arc_load_weight: float = 1.0
    max_correction_ratio: float = 1.0
    max_predictor_growth: float = 4.0
    min_step_cosine: float = 0.0
    probe_rescue: bool = True
    target_tol: float = 1e-6
    target_accept: float = 1e-3
    stop_at_load_reversal: bool = False

    @classmethod
    def from_analysis(cls, analysis: Analysis, **overrides: object) -> PathOptions:
        """The options of a scene's ``[analysis]`` (:class:`sandwich.scene.Analysis`).

        Every field of :class:`~sandwich.scene.Analysis` that is also a path option
        (:data:`ANALYSIS_FIELDS`: all but ``kind``) is taken from ``analysis``; ``overrides``
        are a model's own settings on top (e.g. a Newton tolerance floor, an increment floor,
        ``desired_iterations``); ``None`` values among them are kept.
        """
        return cls(**{**{n: getattr(analysis, n) for n in ANALYSIS_FIELDS}, **overrides})

    def __post_init__(self) -> None:
        if self.control not in CONTROLS:
            raise ValueError(f"control must be one of {CONTROLS}, got {self.control!r}")
        if (self.until_probe is None) != (self.until_value is None):
            raise ValueError("until_probe and until_value go together")
        if self.control == "displacement" and self.driven_probe is None:
            raise ValueError("displacement control needs control_probe (or until_probe)")
        if self.until_load_factor == 0.0:
            raise ValueError("until_load_factor = 0 is the initial state")
        if self.until_value == 0.0:
            raise ValueError("until_value = 0 is the initial state")
        if self.max_steps < 1 or self.max_iterations < 1 or self.desired_iterations < 1:
            raise ValueError("max_steps, max_iterations and desired_iterations must be >= 1")
        if self.settling_allowance is not None and self.settling_allowance < 0:
            raise ValueError(f"settling_allowance must be >= 0 or None, got "
                             f"{self.settling_allowance}")
        if not -1.0 <= self.min_step_cosine < 1.0:
            raise ValueError(f"min_step_cosine must be in [-1, 1), got {self.min_step_cosine}")

    @property
    def driven_probe(self) -> str | None:
        """The probe driven under displacement control."""
        return self.control_probe or self.until_probe


#: The fields of :class:`sandwich.scene.Analysis` that :meth:`PathOptions.from_analysis` takes:
#: its :class:`~sandwich.scene.PathControls` (all but the analysis ``kind``).
ANALYSIS_FIELDS = tuple(f.name for f in dataclasses.fields(PathControls))
