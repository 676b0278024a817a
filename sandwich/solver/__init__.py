"""Generic nonlinear solvers: Newton, load/displacement control and arc-length path following.

The solver never knows which physics it drives: it sees a :class:`DiscreteSystem`.
"""

from sandwich.solver.system import DiscreteSystem, Factorization

__all__ = ["DiscreteSystem", "Factorization"]
