"""The contract between a discretised model and the path-following solver.

A model exposes its equilibrium equations on the *free* unknowns ``u`` (supports and exact ties
already eliminated) as

    R(u, λ) = f_int(u) − λ f_ref = 0,

with ``f_ref`` the reference (dead) load of the scene and λ the load factor.

Beyond :class:`DiscreteSystem`, a model may provide any of the methods of
:class:`OptionalHooks` (each looked up by name where it is used, ``getattr(system, name, None)``;
a model without one gets the plain behaviour it documents): a global inner product over MPI
ranks, a test of admissible states, history columns of its own, cheaper force evaluations
within a converged increment, a bound on Newton corrections, its contact set and its residual's
round-off floor.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np


class Factorization(Protocol):
    """A factorised tangent: solves with it, and its inertia if the backend knows it.

    A factorisation whose ``solve`` also takes an (n, m) array of right-hand sides may say so
    with a true ``solves_columns`` attribute: the corrector then asks for its two solves in
    one call (:mod:`sandwich.solver.newton`).
    """

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Return ``K⁻¹ b``."""
        ...

    @property
    def negative_pivots(self) -> int | None:
        """Number of negative eigenvalues of ``K`` (Sylvester), or ``None`` if unknown."""
        ...


class DiscreteSystem(Protocol):
    """Equilibrium equations of a model, as the solver sees them."""

    @property
    def size(self) -> int:
        """Number of free unknowns."""
        ...

    @property
    def f_ref(self) -> np.ndarray:
        """Reference external load on the free unknowns (multiplied by λ)."""
        ...

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """Return f_int(u) (including contact forces), shape ``(size,)``."""
        ...

    def tangent(self, u: np.ndarray) -> object:
        """Return ∂f_int/∂u at ``u`` in whatever form :meth:`factorize` accepts."""
        ...

    def factorize(self, K: object) -> Factorization:
        """Factorise a tangent returned by :meth:`tangent`."""
        ...

    def probe_vector(self, name: str) -> np.ndarray:
        """Return ``c`` with probe value ``c · u`` (probes are linear in ``u``)."""
        ...

    def commit(self, u: np.ndarray, load_factor: float) -> None:
        """Accept a converged state (update history variables such as contact status)."""
        ...


class OptionalHooks(Protocol):
    """The optional methods a :class:`DiscreteSystem` may add; the solver works without any.

    Each is looked up on the system by name where it is used (``getattr(system, name, None)``,
    :func:`inner_product`, :mod:`sandwich.solver.newton`,
    :class:`~sandwich.solver.path.state.FollowerState`); a system that lacks it gets the
    behaviour described under its "Without it".
    """

    def dot(self, a: np.ndarray, b: np.ndarray) -> float:
        """The global inner product of a system distributed over MPI ranks.

        Each rank holds its owned entries of every vector; the solver then uses this for every
        inner product and norm (:func:`inner_product`). Without it: ``float(a @ b)``.
        """
        ...

    def admissible(self, u: np.ndarray) -> str:
        """``""`` if ``u`` is a physically meaningful state of the model, else the reason.

        E.g. an element turned inside out (det F ≤ 0). The path follower rejects a converged
        step whose state is inadmissible (the step is cut), so it never follows the model's
        equations into a region where they have no physical meaning (the St. Venant–Kirchhoff
        law, for one, has equilibrium states with inverted elements). Without it: every state
        is admissible.
        """
        ...

    def state_columns(self, u: np.ndarray) -> dict[str, float | None]:
        """History columns the model adds to an accepted state ``{name: value or None}``.

        Called after :meth:`DiscreteSystem.commit` and kept in
        :attr:`sandwich.solver.path.PathState.extra`, so that a caller that streams the states
        (an interrupted run) has them without the model's post-processing. Without it: none.
        """
        ...

    def internal_force_nearby(self, u: np.ndarray) -> np.ndarray:
        """f_int(u), exactly as ``internal_force(u)``, for an iterate near the last one.

        Asked for an iterate within a converged increment of the last one evaluated (the
        corrector's increment test passed); the tangent that ``tangent(u)`` then returns may
        keep the parts the system knows such a step cannot change measurably and re-evaluate
        only the rest (the beam keeps its layers' tangent and re-evaluates the contact law,
        whose knee is what such iterations still resolve: :mod:`sandwich.solver.newton`).
        Without it: ``internal_force(u)``.
        """
        ...

    def internal_force_only(self, u: np.ndarray) -> np.ndarray:
        """f_int(u), exactly as ``internal_force(u)`` (bit for bit), without a tangent's work.

        Without the work a following ``tangent(u)`` could reuse (the beam assembles its tangent
        in the same pass as the force). The line search asks for its halved trials through it:
        most of them are rejected, and the one accepted is evaluated again, in full, when its
        tangent is asked for. Without it: ``internal_force(u)``.
        """
        ...

    def correction_limit(self, u: np.ndarray, du: np.ndarray) -> float:
        """The largest fraction α ∈ (0, 1] of a Newton correction ``du`` from ``u`` to trust.

        The model's linearisation can be trusted that far (the beam: no contact pair that is
        open at ``u``, where its tangent has no contact stiffness, may be carried deeper into
        the core than the penetration bound along its linearised gap). The corrector shortens
        a correction to that fraction where the path follower asks it to
        (``NewtonSettings.limit_corrections``, :mod:`sandwich.solver.newton`). Without it:
        corrections are never shortened.
        """
        ...

    def contact_set(self) -> np.ndarray:
        """The active flags of the last force evaluation's contact pairs (the same on every rank).

        A corrector that reaches ``max_iterations`` while this set still moves on to sets it
        had not met is given more iterations (contact-set settling,
        :mod:`sandwich.solver.newton`). Without it: the iteration limit is fixed.
        """
        ...

    def residual_roundoff(self, u: np.ndarray) -> float:
        """The level (force units) below which the residual cannot be evaluated at ``u``.

        E.g. ε ‖|K(u)| |u|‖. When the increment test passes but the residual test does not, a
        residual at or below it is accepted ("converged to the round-off floor",
        :mod:`sandwich.solver.newton`). Without it (or where it fails, or is not finite and
        positive): no floor.
        """
        ...


def _local_dot(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.asarray(a) @ np.asarray(b))


def inner_product(system: object) -> Callable[[np.ndarray, np.ndarray], float]:
    """The system's optional ``dot(a, b)`` (global over MPI ranks), else ``float(a @ b)``."""
    dot = getattr(system, "dot", None)
    return dot if callable(dot) else _local_dot
