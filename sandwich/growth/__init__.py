"""Debond growth: each debond with ``growth`` grown by crack-length control.

:func:`grow` runs a model's solve at successive debond lengths (:mod:`.crack_length`);
:mod:`.crossing` places the onset of growth on a path, :mod:`.envelope` reads the envelope.
"""

from sandwich.growth.crack_length import final_scene, grow, growing, tip_column
from sandwich.growth.crossing import Crossing, criterion_ratio, first_crossing
from sandwich.growth.envelope import growth_summary, onset_rows

__all__ = ["Crossing", "criterion_ratio", "final_scene", "first_crossing", "grow", "growing",
           "growth_summary", "onset_rows", "tip_column"]
