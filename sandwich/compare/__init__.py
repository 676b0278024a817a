"""Comparison harness: the beam model against the 2D reference on any scene.

Layer order: scene → model → solver → results → models registry/runner → **comparisons**. This
package reads results (in memory or from result folders, through :mod:`sandwich.models` and
:mod:`sandwich.results`), computes errors and draws; it never computes mechanics and never
reaches into a model's internals.
"""

from sandwich.compare.claims import ClaimResult, Verdict, check_claims
from sandwich.compare.compare import Comparison, compare, model_folder
from sandwich.compare.gallery import Gallery, gallery, shipped_scenes
from sandwich.compare.metrics import Metrics

__all__ = ["ClaimResult", "Comparison", "Gallery", "Metrics", "Verdict", "check_claims",
           "compare", "gallery", "model_folder", "shipped_scenes"]
