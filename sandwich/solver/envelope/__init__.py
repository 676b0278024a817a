"""Envelope (variable-band) LDLᵀ of a sparse symmetric tangent, with its inertia.

A 1D model numbered node by node (the beam) has a tangent whose non-zeros hug the diagonal:
row i couples to columns ``first[i] … i`` only, and the LDLᵀ factor of such a matrix fills in
nowhere outside that *envelope*. Factorising inside it costs about Σᵢ (i − first[i])²
operations, against n·b² for a fixed band of half-width b (the wider rows of the contact pairs
or of higher core levels do not widen the whole band), with none of a general sparse LU's
symbolic overhead. Two storages (chosen per pattern by their operation counts,
:data:`COLUMN_ADVANTAGE`): ``"columns"``, column j holding rows j … last[j] with last
non-decreasing (a band is the special case), factorised right-looking by contiguous AXPYs
(:func:`~.columns.column_ldlt`) or, longer than :data:`PANEL_MIN_WIDTH` on average, by panels
of eight columns and rank-8 updates (:func:`~.panels.panel_ldlt`); ``"envelope"``, the row
envelope exactly, factorised row by row by Crout's dot products (:func:`~.rows.row_ldlt`).

The modules:

- :mod:`.patterns`: sparsity patterns (the values' pattern, envelope rows, the storage map,
  unions of patterns);
- :mod:`.structure`: :class:`EnvelopeStructure`, the symbolic part (ordering, envelope,
  storage), and the settings :data:`COLUMN_ADVANTAGE`, :data:`PANEL_MIN_WIDTH`,
  :data:`SPARE_STORAGE` (read when a structure is built or a storage array handed out: set
  them on :mod:`sandwich.solver.envelope.structure`, not on this package);
- :mod:`.rows`, :mod:`.columns`, :mod:`.panels`: the compiled LDLᵀ kernels and solves of the
  two storages;
- :mod:`.factorization`: :func:`factorize_envelope` (load, factorise, trust the pivots or fall
  back to SuperLU) and :class:`EnvelopeFactorization`.
"""

from sandwich.solver.envelope.factorization import EnvelopeFactorization, factorize_envelope
from sandwich.solver.envelope.panels import PANEL
from sandwich.solver.envelope.structure import (
    COLUMN_ADVANTAGE,
    PANEL_MIN_WIDTH,
    SPARE_STORAGE,
    EnvelopeStructure,
)

__all__ = ["COLUMN_ADVANTAGE", "PANEL", "PANEL_MIN_WIDTH", "SPARE_STORAGE",
           "EnvelopeFactorization", "EnvelopeStructure", "factorize_envelope"]
