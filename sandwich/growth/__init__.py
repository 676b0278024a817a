"""Debond growth: by crack-length control (any model) or read from a cohesive law's path.

:func:`grow` runs a model's solve at successive debond lengths (:mod:`.crack_length`);
:mod:`.crossing` places the onset of growth on a path, :mod:`.envelope` reads the envelope.
A debond grown by a cohesive law grows along one path of either model; :mod:`.cohesive` reads
its tips from that path.
"""

from sandwich.growth.cohesive import cohesive_growing, cohesive_summary
from sandwich.growth.crack_length import final_scene, grow, growing, tip_column
from sandwich.growth.crossing import Crossing, criterion_ratio, first_crossing
from sandwich.growth.envelope import growth_summary, onset_rows

__all__ = ["Crossing", "cohesive_growing", "cohesive_summary",
           "criterion_ratio", "final_scene", "first_crossing", "grow", "growing",
           "growth_summary", "onset_rows", "tip_column"]
