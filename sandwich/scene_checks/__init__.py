"""Turn parsed TOML into a :class:`~sandwich.scene.Scene`, collecting every problem on the way.

Each check names the key in dotted form (``debonds[2].end``) and says why it is refused, so that a
bad scene is answered with one line per problem before any model does any work.

The modules: :mod:`.reader` (the :class:`Reader` every check reads through), :mod:`.geometry`
(beam, materials, layers), :mod:`.stations` (debonds, supports, loads, probes, and whether the
supports hold the beam), :mod:`.options` (analysis, ``[beam_model]``, ``[reference2d]``) and
:mod:`.build` (:func:`build_scene`, which runs them all).
"""

from sandwich.scene_checks.build import TOP_KEYS, build_scene
from sandwich.scene_checks.geometry import MIN_SIZE, MIN_STIFFNESS_DET
from sandwich.scene_checks.options import MIN_TOL
from sandwich.scene_checks.reader import MAX_MAGNITUDE, Reader
from sandwich.scene_checks.stations import GEOMETRY_TOL

__all__ = ["GEOMETRY_TOL", "MAX_MAGNITUDE", "MIN_SIZE", "MIN_STIFFNESS_DET", "MIN_TOL",
           "TOP_KEYS", "Reader", "build_scene"]
