"""Comparison harness: the beam model against the 2D reference on any scene.

Layer order: scene → model → solver → results → models registry/runner → **comparisons**. This
package reads results (in memory or from result folders, through :mod:`models` and
:mod:`sandwich.results`), computes errors and draws; it never computes mechanics and never
reaches into a model's internals.
"""

from comparisons.claims import ClaimResult, Verdict, check_claims
from comparisons.compare import Comparison, compare, model_folder
from comparisons.gallery import Gallery, gallery, shipped_scenes
from comparisons.metrics import Metrics

__all__ = ["ClaimResult", "Comparison", "Gallery", "Metrics", "Verdict", "check_claims",
           "compare", "gallery", "model_folder", "shipped_scenes"]
