"""The result contract: typed results, their writers and readers, and a result's identity.

- :mod:`sandwich.results.types`: :class:`Solution`, :class:`StepRecord`, :class:`Profile`,
  :class:`LimitPoint`, :class:`FieldFrame` (the one field type both models fill);
- :mod:`sandwich.results.writing`: ``history.csv``, ``profiles.csv``, ``summary.json`` and the
  field frames (``fields.pvd`` + VTU), written as one set;
- :mod:`sandwich.results.reading`: the inverse, :func:`load_result`;
- :mod:`sandwich.results.identity`: what produced a result folder, checked before reuse.
"""

from sandwich.results.identity import RunIdentity, scene_digest, source_digest
from sandwich.results.reading import (
    FIELDS_COLLECTION,
    RESULT_FILES,
    ResultMissing,
    load_result,
    read_field_frames,
)
from sandwich.results.types import (
    PROFILE_COLUMNS,
    FieldFrame,
    InterruptedSolve,
    LimitPoint,
    PathNote,
    Profile,
    ProgressItem,
    Solution,
    StepRecord,
)
from sandwich.results.writing import (
    OutputError,
    atomic_write_text,
    check_output_folder,
    history_csv,
    profiles_csv,
    summary_dict,
    write_solution,
)

__all__ = [
    "FIELDS_COLLECTION", "PROFILE_COLUMNS", "RESULT_FILES", "FieldFrame",
    "InterruptedSolve", "LimitPoint", "OutputError", "PathNote", "Profile", "ProgressItem",
    "ResultMissing", "RunIdentity", "Solution", "StepRecord", "atomic_write_text",
    "check_output_folder", "history_csv", "load_result", "profiles_csv",
    "read_field_frames", "scene_digest", "source_digest", "summary_dict", "write_solution"
]
