"""States carried onto another beam model and re-converged there: the checks' common step.

:class:`Reconverging` is what :class:`~sandwich.beam.one_pass.OnePass` does with a state of its
path on a model at other core levels or on another mesh: Newton from the carried-over state to the
equilibrium at the same value of the until probe (else the same load), with a backtracking line
search (:meth:`Reconverging.lift`, :meth:`Reconverging.reconverge`), or one Newton correction
only, the linearised response (:meth:`Reconverging.linearised`).
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.build import build_model, scene_gauss_orders
from sandwich.beam.core_levels import transfer
from sandwich.beam.model import BeamModel
from sandwich.beam.path_pass import max_penetration
from sandwich.solver import PathState
from sandwich.solver.controls import LoadConstraint, ProbeConstraint
from sandwich.solver.newton import NewtonResult, NewtonSettings, newton_correct, newton_step
from sandwich.solver.system import inner_product

#: Newton's iterations and backtracking halvings of a state re-converged at other levels: a
#: state carried over converged in 2-10 on fig. 5, fig. 6 and the demo scene, 15 once on c1;
#: one that takes more has left the levels' equilibrium, and failing early keeps that cheap.
LIFT_ITERATIONS = 20
LIFT_BACKTRACKS = 8
#: A one-correction check (:meth:`Reconverging.linearised`) is accepted where the correction left
#: at most this fraction of the residual it started from. The
#: residual after it says little of the load (contact pairs in the penalty law's knee: left
#: 1.5-90 × with the load within 5 % on d20), but a large one is what a state with no equilibrium
#: near it one level higher shows too (c1 past its load maximum: 50 ×, with a change of +0.11 %
#: where the re-converged state does not exist), so those are re-converged.
ONE_STEP_CONTRACTION = 0.75


class Reconverging:
    """Carrying states between models of one scene.

    The class using it sets ``scene``, ``elements``, ``options`` (the build options) and
    ``model`` (the model the states are of).
    """

    scene: object
    elements: int | None
    options: dict
    model: BeamModel

    def lift(self, model: BeamModel, u: np.ndarray, lam: float, probes: dict[str, float],
             levels: np.ndarray, up: BeamModel | None = None,
             tol: float | None = None) -> tuple[BeamModel, object] | None:
        """The state ``(u, λ)`` of ``model`` re-converged on the model at ``levels``, or None.

        Newton with a backtracking line search from the carried-over state (new enrichment
        amplitudes zero): :meth:`reconverge`. ``up``: the model at ``levels`` if built already;
        ``tol``: Newton's (default the scene's).
        """
        if up is None:
            up = build_model(self.scene, elements=self.elements,
                             gauss=scene_gauss_orders(self.scene),
                             **{**self.options, "core_level": levels})
        return self.reconverge(up, transfer(u, model, up), lam, probes, tol, LIFT_BACKTRACKS)

    def reconverge(self, up: BeamModel, start: np.ndarray, lam: float, probes: dict[str, float],
                   tol: float | None, backtracks: int,
                   iterations: int = 0) -> tuple[BeamModel, object] | None:
        """Newton on ``up`` from ``start`` to the state at the same until probe (else load).

        At the same value of the until probe where the scene has one, else at the same load;
        ``backtracks`` halvings of a correction that does not lower the residual, at most
        ``iterations`` (default ``LIFT_ITERATIONS``). None where Newton fails or the state
        penetrates deeper than the model's bound.
        """
        constraint = self._constraint(up, lam, probes)
        settings = NewtonSettings(
            tol=float(self.scene.analysis.tol) if tol is None else tol,
            max_iterations=iterations or LIFT_ITERATIONS,
            force_floor=float(np.linalg.norm(up.f_ref)) * abs(lam), backtracks=backtracks)
        res = newton_correct(up, start, lam, constraint, settings)
        if not res.converged or res.load_factor == 0.0 or res.factorization is None:
            return None
        if max_penetration(up, [res.u]) > up.penetration_bound():
            return None
        return up, res

    def linearised(self, up: BeamModel, state: PathState) -> tuple[BeamModel, object] | None:
        """``state`` carried onto ``up`` and corrected once by Newton: the linearised response.

        One correction at the same until probe, else load (:func:`newton_step`); None where it
        leaves more than ``ONE_STEP_CONTRACTION`` of the carried-over state's residual or a
        pair penetrates deeper than the model's bound. Its factorisation is the tangent's at
        the carried-over state.
        """
        probes = dict(state.probes)
        step = newton_step(up, transfer(state.u, self.model, up), state.load_factor,
                           self._constraint(up, state.load_factor, probes))
        if step is None or step.contraction > ONE_STEP_CONTRACTION or step.load_factor == 0.0:
            return None
        if max_penetration(up, [step.u]) > up.penetration_bound():
            return None
        return up, NewtonResult(True, step.u, step.load_factor, 1, step.residual_after,
                                "one correction", step.factorization)

    def _constraint(self, up: BeamModel, lam: float,
                    probes: dict[str, float]) -> LoadConstraint | ProbeConstraint:
        """What a state re-converged on ``up`` holds: the until probe's value, else the load."""
        name = self._held_probe(probes)
        if name is None:
            return LoadConstraint(lam)
        return ProbeConstraint(np.asarray(up.probe_vector(name), dtype=float),
                               float(probes[name]), inner_product(up))

    def _held_probe(self, probes: dict[str, float]) -> str | None:
        """The probe a lift holds: the until probe (None without one, or at 0: the load)."""
        name = self.scene.analysis.until_probe
        return name if name and probes.get(name, 0.0) != 0.0 else None


def probes_of(model: BeamModel, u: np.ndarray) -> dict[str, float]:
    """Every probe of ``model`` at the state ``u``."""
    return {n: float(np.asarray(model.probe_vector(n)) @ u) for n in model.probe_rows}
