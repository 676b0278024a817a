"""Generic nonlinear solvers: Newton, load/displacement control and arc-length path following.

The solver never knows which physics it drives: it sees a :class:`DiscreteSystem`.
"""

from sandwich.solver.limits import find_limit_points
from sandwich.solver.newton import NewtonResult, NewtonSettings, newton_correct, solve_equilibrium
from sandwich.solver.path import PathOptions, PathResult, PathState, follow_path, solve_linear
from sandwich.solver.sparse import (
    SingularTangentError,
    SparseFactorization,
    SparseSystemMixin,
    factorize_symmetric,
)
from sandwich.solver.system import DiscreteSystem, Factorization, OptionalHooks

__all__ = [
    "DiscreteSystem",
    "Factorization",
    "NewtonResult",
    "NewtonSettings",
    "OptionalHooks",
    "PathOptions",
    "PathResult",
    "PathState",
    "SingularTangentError",
    "SparseFactorization",
    "SparseSystemMixin",
    "factorize_symmetric",
    "find_limit_points",
    "follow_path",
    "newton_correct",
    "solve_equilibrium",
    "solve_linear",
]
