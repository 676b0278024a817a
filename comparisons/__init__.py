"""Comparison harness: the beam model against the 2D reference on any scene.

Layer order: scene → model → solver → results → **comparisons**. This package reads results
(in memory or from result folders), computes errors and draws; it never computes mechanics.
"""

from comparisons.claims import ClaimResult, Verdict, check_claims
from comparisons.compare import Comparison, compare
from comparisons.gallery import Gallery, gallery, shipped_scenes
from comparisons.metrics import Metrics
from comparisons.reading import ResultMissing, load_result
from comparisons.runs import ModelRun, ProgressEvent, text_progress
from comparisons.snapshots import FieldSnapshot, save_snapshot

__all__ = ["ClaimResult", "Comparison", "Gallery", "Verdict", "check_claims", "gallery",
           "shipped_scenes", "FieldSnapshot", "Metrics", "ModelRun", "ProgressEvent",
           "ResultMissing", "compare", "load_result", "save_snapshot", "text_progress"]
