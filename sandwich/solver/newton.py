"""Full Newton–Raphson corrector for R(u, λ) = f_int(u) − λ f_ref = 0 with one constraint.

Convergence (both tests, checked after every correction; at least one correction is made):

- residual: ``‖R‖ ≤ tol · max(‖λ f_ref‖, ‖f_int(u)‖, force_floor, tiny)``, where the caller's
  ``force_floor`` (the path follower passes ``‖f_ref‖ · max|λ|`` over the converged states) keeps
  the test meaningful where λ and f_int both pass through zero;
- increment: ``‖(δu, ψ δλ)‖ ≤ √tol · max(‖(Δu, ψ Δλ)‖, ‖(u, ψ λ)‖)`` for the last correction,
  with ``Δ`` the step increment from the last converged state and ψ the load-factor weight
  (displacement per unit λ). Newton converges quadratically, so a last correction of relative
  size √tol leaves an error of relative size ~tol: the two tests ask for the same accuracy.

Round-off floor: a system may provide ``residual_roundoff(u)`` (N), the level below which its
residual cannot be evaluated at ``u`` (e.g. ε ‖|K(u)| |u|‖). When the increment test passes but
the residual test does not, a residual at or below that floor is accepted ("converged to the
round-off floor"): the tolerance is fixed for the whole path while the round-off of a softening
structure grows along it (the 2D cantilevers c3/c4 stalled that way, docs/reference2d.md).
The floor is evaluated once per corrector, at the first iterate whose increment test passes,
and kept for its later iterates (they differ from it by at most √tol relative: the floor, a
level of ε, does not move at that scale), so an iteration converging linearly in the contact
law's knee does not pay a pass over K at every correction (fig. 9 d20: 369 → 55 evaluations).

Iterations after a converged increment: once the increment test passes and the residual
test does not, the rest of the corrector changes the state by less than √tol of its increment
(on the debond scenes: ≈ 1e-7 relative, the contact pairs settling in the penalty law's knee,
where each iteration moves a pair by about the law's width s and divides its force error by
≈ e; fig. 9 d20: 60 % of all iterations). A system with ``internal_force_nearby`` is asked for
the next forces through it, so it may keep the parts of its tangent that so small a step cannot
change measurably (the beam: its layers' tangent; its contact law is re-evaluated). The
residual, and so every convergence decision, is exact; only the tangent the remaining
corrections are solved with is the system's approximation, as is the converged state's if its
iterate was evaluated so (it differs from the exact one by the layers' change over the
corrections since the last full evaluation, each within √tol of the increment: its inertia
can differ from the exact one only that close to a critical point).

Line search (``backtracks`` > 0, off by default): a correction that does not lower ``‖R‖`` is
halved, up to ``backtracks`` times; if none lowers it the corrector fails there (not once ‖R‖
is within the tolerance: that correction only settles the increment test). For a start far
from equilibrium — a converged state carried into a refined model, whose full corrections
overshoot into the buckled face's other shape (fig. 5's end state: the undamped iteration's
residual grows by 1e4) — the damped iterates descend until the quadratic phase takes over with
full steps. A probe or load constraint stays satisfied to first order: each iteration's δλ is
recomputed from the current iterate.

Contact-limited corrections (``limit_corrections``, off by default; the path follower turns it
on for the rest of a path once one of its correctors has failed, :mod:`sandwich.solver.path`):
a system with ``correction_limit(u, du)`` may shorten a correction to the fraction α it returns
(at least :data:`MIN_CORRECTION_FRACTION`). Where a contact pair is open, the tangent carries no
contact stiffness for it, and a correction that closes it is blind to the penalty it meets:
fig. 7 c4 at core level 3 puts 14-59 pairs 0.1-0.2 mm deep into the core in one correction,
the residual grows by 400-1500×, the next corrections push them out and back in, and the step
is cut — down to 0.08-0.17 mm of tip deflection (docs/speed.md, "Contact-limited
corrections"). Shortened so that no open pair goes deeper than the penetration bound, the
correction leaves those pairs where the next tangent sees them. Only a corrector's first
:data:`LIMITED_CORRECTIONS` corrections are limited (the overshoot comes from the predictor);
later ones are plain Newton's, so that a pair stopped at the bound and pushed open again
cannot keep a corrector cycling. The equations and the convergence tests are unchanged (the
converged state is an equilibrium of the same R); a shortened correction never counts for the
increment test.

Divergence (reported as a failed :class:`NewtonResult`, never raised): a non-finite residual or
iterate, a singular tangent, a constraint without solution, a residual grown by more than
``divergence_factor`` over the first one, a residual that rose ``divergence_rises`` times in a
row while above the first one, or ``max_iterations`` corrections without convergence.

The rising test (off by default; the path follower turns it on for a step's attempts until
one fails by it, :mod:`sandwich.solver.path`), after the cut-back rule of commercial codes (a
residual growing in two consecutive iterations abandons the increment), stops an iteration that
has left the basin of the solution early: on fig. 5's level-3 pass two attempts wandered for 25
and 17 iterations at residuals 1e4-1e6 (the start: 2e4 and 5e3) before failing, 1.5 s of the
pass's 4.2 s. It is a heuristic, not a proof of divergence: an iteration hunting for its
contact set can rise above its first residual for several iterations and then converge (the 2D
model's first step of a cantilever with a closed debond at its root: rises at iterations 2-4,
converged at 16, at every increment), which is why a step's retry runs without it.

Contact-set settling (a system with ``contact_set()``: the active flags of its last force
evaluation, the same on every rank): a corrector that reaches ``max_iterations`` while its
contact set is still moving on is not out of iterations. It goes on while the set moved to one
it had not met before within the last :data:`SETTLED_ITERATIONS` iterations, up to
:data:`SETTLING_PER_PAIR` more per contact pair. A set that only cycles among sets met before
is chattering, not settling (fig. 9 d10's failing attempts: counting every change made its 2D
run 12.6 → 149.5 s on the same path). From the undeformed state every lip is at zero gap and
counts as shut; where most of them must open, a penalty iteration opens them about one pair
per two iterations, at any load in the linear range (the 2D model's first step of an 80-mm
debond 10 mm from a support: 43 pairs shut → 4, converged at iteration 27; docs/studies.md),
so cutting the step cannot help. A corrector whose set has settled keeps the ordinary limit.
The beam does not offer the hook (its corrector is unchanged).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from sandwich.solver.controls import Constraint, LoadConstraint
from sandwich.solver.sparse import SingularTangentError
from sandwich.solver.system import DiscreteSystem, Factorization, inner_product

__all__ = ["RISING", "NewtonResult", "NewtonSettings", "NewtonStep", "newton_correct",
           "newton_step",
           "solve_equilibrium"]

_TINY = 1e-300

#: The smallest fraction of a correction a system's ``correction_limit`` may shorten it to.
MIN_CORRECTION_FRACTION = 1e-3
#: Only a corrector's first corrections may be limited (those from the predictor, where the
#: open pairs are carried in); later ones are plain Newton's, so that a pair stopped at the
#: bound and pushed open again cannot keep the corrector cycling (fig. 6 at 40 elements, the
#: paper's core: limited on every correction, its correctors cycled with period 2-3 at the
#: face's load maximum and the path stopped there).
LIMITED_CORRECTIONS = 3

#: Contact-set settling (module docstring): more iterations per contact pair past
#: ``max_iterations`` while the set moves on to sets not met before, and the iterations after
#: its last such move that still count as settling.
SETTLING_PER_PAIR = 2
SETTLED_ITERATIONS = 3

#: How the reason of a corrector stopped by the rising test begins.
RISING = "residual rose"

#: Failures of a model evaluation that mean "this iterate is unusable", not a bug.
RECOVERABLE_ERRORS: tuple[type[BaseException], ...] = (
    SingularTangentError,
    ArithmeticError,
    np.linalg.LinAlgError,
)


@dataclass(frozen=True)
class NewtonSettings:
    """Tolerances of the corrector (see the module docstring for the tests they enter)."""

    tol: float = 1e-8
    max_iterations: int = 25
    psi: float = 1.0
    force_floor: float = 0.0
    divergence_factor: float = 1e4
    divergence_rises: int = 0  # consecutive rises above the first residual that fail (0: off)
    backtracks: int = 0  # halvings of a correction that does not lower ‖R‖ (0: plain Newton)
    limit_corrections: bool = False  # shorten corrections to the system's correction_limit


@dataclass
class NewtonResult:
    """Outcome of one corrector run.

    On success ``u``/``load_factor`` are the converged equilibrium and ``factorization`` the
    factorised tangent there (its inertia is the state's). On failure they are the start values
    and ``reason`` says why.
    """

    converged: bool
    u: np.ndarray
    load_factor: float
    iterations: int
    residual_norm: float
    reason: str
    factorization: Factorization | None = None
    rises: int = 0  # the longest run of rises above the first residual (the rising test's count)
    increment_iterations: int | None = None  # iterations until the increment test first passed


def _norm(v: np.ndarray, lam: float, psi: float, dot=None) -> float:
    vv = dot(v, v) if dot is not None else float(v @ v)
    return math.sqrt(vv + (psi * lam) ** 2)


def newton_correct(
    system: DiscreteSystem,
    u: np.ndarray,
    load_factor: float,
    constraint: Constraint,
    settings: NewtonSettings,
    u_start: np.ndarray | None = None,
    load_factor_start: float | None = None,
) -> NewtonResult:
    """Iterate from a predicted ``(u, λ)`` to an equilibrium satisfying ``constraint``.

    Parameters
    ----------
    system
        The model.
    u, load_factor
        The predictor (the start of the iterations).
    constraint
        The extra equation fixing λ (load, probe or arc-length control).
    settings
        Tolerances.
    u_start, load_factor_start
        Last converged state: the step increment ``Δ`` is counted from it (defaults: the
        predictor itself, i.e. a zero increment).

    Returns
    -------
    NewtonResult
        Converged or not; ordinary divergence is reported, not raised.
    """
    dot = inner_product(system)

    def norm(v: np.ndarray) -> float:  # nan/inf propagate; collective when dot is
        return math.sqrt(dot(v, v))

    f_ref = np.asarray(system.f_ref, dtype=float)
    u0 = np.array(u, dtype=float) if u_start is None else np.asarray(u_start, dtype=float)
    lam0 = float(load_factor) if load_factor_start is None else float(load_factor_start)
    u = np.array(u, dtype=float)
    lam = float(load_factor)
    psi = settings.psi
    tol_inc = math.sqrt(settings.tol)
    r_first = None
    last_step = None  # norm of the last correction
    r_norm = math.inf
    rises, r_last = 0, math.inf  # consecutive rises above the first residual; the last one
    most_rises = 0
    floor = None  # the system's round-off floor, at the first iterate with a converged increment

    def fail(reason: str, its: int) -> NewtonResult:
        return NewtonResult(False, u0.copy(), lam0, its, r_norm, reason)

    trial_force = None  # f_int at the iterate, when the line search has evaluated it
    # the last iterate's factorisation: let go before the next is made, so that two of them
    # (a factor each, the size of the tangent's envelope) are never held at once
    fac = None
    nearby = getattr(system, "internal_force_nearby", None)
    limit = getattr(system, "correction_limit", None) if settings.limit_corrections else None
    small_step = False  # the last correction passed the increment test
    first_small = None  # the iteration at which it first did
    contact_set = getattr(system, "contact_set", None)
    changed_at, extra = -1, 0  # the iteration of the set's last move to a new one; allowance
    seen: set[bytes] = set()  # every set this corrector met
    with np.errstate(all="ignore"):
        for it in itertools.count():
            if trial_force is None:
                try:
                    force = nearby if small_step and nearby is not None else \
                        system.internal_force
                    f_int = np.asarray(force(u), dtype=float)
                except RECOVERABLE_ERRORS as exc:
                    return fail(f"internal force failed: {exc}", it)
            else:
                f_int, trial_force = trial_force, None
            if contact_set is not None:
                now = np.asarray(contact_set(), dtype=bool)
                key = np.packbits(now).tobytes()
                if seen and key not in seen:
                    changed_at = it  # moved on to a set not met before: still settling
                seen.add(key)
                extra = SETTLING_PER_PAIR * now.size
            res = f_int - lam * f_ref
            r_norm = norm(res)
            if not math.isfinite(r_norm):
                return fail("non-finite residual", it)
            scale = max(abs(lam) * norm(f_ref), norm(f_int),
                        settings.force_floor, _TINY)
            if last_step is not None:
                inc_scale = max(_norm(u - u0, lam - lam0, psi, dot), _norm(u, lam, psi, dot))
                small_step = last_step <= tol_inc * inc_scale
                if small_step and first_small is None:
                    first_small = it
                how = ""
                if small_step and r_norm <= settings.tol * scale:
                    how = "converged"
                elif small_step:
                    if floor is None:
                        floor = _roundoff(system, u)
                    if r_norm <= floor:
                        how = "converged to the round-off floor"
                if how:
                    fac = None
                    try:
                        fac = system.factorize(system.tangent(u))
                    except RECOVERABLE_ERRORS as exc:
                        return fail(f"tangent at the converged state is singular: {exc}", it)
                    return NewtonResult(True, u, lam, it, r_norm, how, fac, most_rises,
                                        first_small)
            if r_first is None:
                r_first = max(r_norm, settings.tol * scale)
            elif r_norm > settings.divergence_factor * r_first:
                return fail(f"residual grew from {r_first:.3e} to {r_norm:.3e}", it)
            else:
                rises = rises + 1 if r_first < r_norm > r_last else 0
                most_rises = max(most_rises, rises)
                if 0 < settings.divergence_rises <= rises:
                    return fail(f"{RISING} {rises} times in a row above the first one "
                                f"({r_first:.3e} → {r_norm:.3e}): diverging", it)
            r_last = r_norm
            if it >= settings.max_iterations and not (
                    it < settings.max_iterations + extra
                    and it - changed_at <= SETTLED_ITERATIONS):
                break
            fac = None
            try:
                fac = system.factorize(system.tangent(u))
                du_r, du_f = _solve_both(fac, -res, f_ref)
            except RECOVERABLE_ERRORS as exc:
                return fail(f"singular tangent: {exc}", it)
            dlam = constraint.delta_lambda(du_r, du_f, u, lam, u - u0, lam - lam0)
            if dlam is None or not math.isfinite(dlam):
                return fail("the control equation has no solution at this iterate", it)
            du = du_r + dlam * du_f
            if not math.isfinite(dot(du, du)):
                return fail("non-finite correction", it)
            if settings.backtracks > 0 and r_norm > settings.tol * scale:
                # (at the tolerance already a correction only settles the increment test, and
                # round-off may keep it from lowering ‖R‖: taken in full)
                searched = _backtrack(system, u, lam, du, dlam, r_norm, settings.backtracks,
                                      norm, f_ref)
                if searched is None:
                    return fail(f"no decrease of the residual along the correction in "
                                f"{settings.backtracks} halvings", it)
                du, dlam, trial_force = searched
            shortened = False
            if limit is not None and trial_force is None and it < LIMITED_CORRECTIONS:
                alpha = float(limit(u, du))
                if alpha < 1.0:  # (not after a line search: its trial force is this du's)
                    alpha = max(alpha, MIN_CORRECTION_FRACTION)
                    du, dlam, shortened = alpha * du, alpha * dlam, True
            u = u + du
            lam = lam + dlam
            # a shortened correction says nothing about the remaining one: never "small"
            last_step = math.inf if shortened else _norm(du, dlam, psi, dot)
    settling = (f", {it - settings.max_iterations} more while its contact set settled"
                if it > settings.max_iterations else "")
    return fail(
        f"no convergence in {settings.max_iterations} iterations{settling} "
        f"(residual {r_norm:.3e})", it)


def _backtrack(
    system: DiscreteSystem, u: np.ndarray, lam: float, du: np.ndarray, dlam: float,
    r_norm: float, halvings: int, norm: object, f_ref: np.ndarray,
) -> tuple[np.ndarray, float, np.ndarray] | None:
    """The correction scaled by the first of 1, ½, ¼, … that lowers ‖R‖ below ``r_norm``.

    Returns the scaled correction and f_int at its iterate, or None when ``halvings`` halvings
    found no decrease (the iterate is then not a descent start: the corrector fails there
    instead of creeping on).
    """
    alpha = 1.0
    # the full step's force through internal_force: accepted, its tangent is the next one; the
    # halved trials (mostly rejected) through the force alone where the system offers it
    force = system.internal_force
    force_only = getattr(system, "internal_force_only", None) or force
    for _ in range(halvings + 1):
        try:
            f_int = np.asarray(force(u + alpha * du), dtype=float)
            force = force_only
        except RECOVERABLE_ERRORS:
            f_int = None
        if f_int is not None and norm(f_int - (lam + alpha * dlam) * f_ref) < r_norm:
            return alpha * du, alpha * dlam, f_int
        alpha *= 0.5
    return None


def _solve_both(fac: object, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """K⁻¹a and K⁻¹b.

    One call with both as columns where the factorisation takes them (``solves_columns``: one
    sweep of the factors for the two), else one call each.
    """
    if getattr(fac, "solves_columns", False):
        x = np.asarray(fac.solve(np.column_stack((a, b))), dtype=float)
        return x[:, 0], x[:, 1]
    return np.asarray(fac.solve(a), dtype=float), np.asarray(fac.solve(b), dtype=float)


def _roundoff(system: DiscreteSystem, u: np.ndarray) -> float:
    """The system's residual round-off level at ``u`` (0 if it does not say)."""
    floor = getattr(system, "residual_roundoff", None)
    if not callable(floor):
        return 0.0
    try:
        value = float(floor(u))
    except RECOVERABLE_ERRORS:
        return 0.0
    return value if math.isfinite(value) and value > 0.0 else 0.0


@dataclass(frozen=True)
class NewtonStep:
    """One full Newton correction (:func:`newton_step`): the iterate it gives and its residuals.

    ``contraction`` = ‖R‖ after / ‖R‖ before: in Newton's quadratic phase it is small, and the
    iterate's remaining distance to the equilibrium is about that fraction of the correction.
    ``factorization`` is the tangent's at the start.
    """

    u: np.ndarray
    load_factor: float
    residual_before: float
    residual_after: float
    factorization: Factorization

    @property
    def contraction(self) -> float:
        """‖R‖ after the correction over ‖R‖ before it (0 where both vanish)."""
        if self.residual_before == 0.0:
            return 0.0 if self.residual_after == 0.0 else math.inf
        return self.residual_after / self.residual_before


def newton_step(system: DiscreteSystem, u: np.ndarray, load_factor: float,
                constraint: Constraint) -> NewtonStep | None:
    """One Newton correction of R(u, λ) = f_int(u) − λ f_ref = 0 under ``constraint``.

    The linearised answer at ``(u, λ)``: δu = K⁻¹(−R) + δλ K⁻¹f_ref with δλ from the constraint
    (the step increment counted from ``(u, λ)`` itself), and the residual at the new iterate.
    None where the tangent is singular, the constraint has no solution there or a residual is not
    finite.
    """
    dot = inner_product(system)
    f_ref = np.asarray(system.f_ref, dtype=float)
    u = np.asarray(u, dtype=float)
    lam = float(load_factor)
    with np.errstate(all="ignore"):
        try:
            res = np.asarray(system.internal_force(u), dtype=float) - lam * f_ref
            fac = system.factorize(system.tangent(u))
            du_r, du_f = _solve_both(fac, -res, f_ref)
        except RECOVERABLE_ERRORS:
            return None
        dlam = constraint.delta_lambda(du_r, du_f, u, lam, np.zeros_like(u), 0.0)
        if dlam is None or not math.isfinite(dlam):
            return None
        u1 = u + du_r + dlam * du_f
        lam1 = lam + dlam
        try:
            res1 = np.asarray(system.internal_force(u1), dtype=float) - lam1 * f_ref
        except RECOVERABLE_ERRORS:
            return None
        before, after = math.sqrt(dot(res, res)), math.sqrt(dot(res1, res1))
    if not (math.isfinite(before) and math.isfinite(after)):
        return None
    return NewtonStep(u1, lam1, before, after, fac)


def solve_equilibrium(
    system: DiscreteSystem,
    load_factor: float,
    u0: np.ndarray | None = None,
    settings: NewtonSettings | None = None,
) -> NewtonResult:
    """Newton–Raphson at fixed λ from ``u0`` (default zero), with no path following."""
    u = np.zeros(system.size) if u0 is None else np.asarray(u0, dtype=float)
    return newton_correct(system, u, load_factor, LoadConstraint(float(load_factor)),
                          settings or NewtonSettings())
