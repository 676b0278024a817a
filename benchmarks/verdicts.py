"""The test the estimate tables apply: does an estimate cover its true error?

Issue 47's rule: where the true error exceeds a tenth of its tolerance, the estimate must lie
between 1 and 5 times it.
"""

from __future__ import annotations

BELOW = "true error below a tenth of the tolerance"


def verdict(true: float, estimated: float | None, tolerance: float) -> tuple[float | None, str]:
    """``(estimated / true, verdict)``; the ratio None where there is no estimate or no error."""
    ratio = None if estimated is None or true <= 0.0 else estimated / true
    if true <= 0.1 * tolerance:
        return ratio, BELOW
    if estimated is None:
        return ratio, "not estimated"
    if 1.0 <= ratio <= 5.0:
        return ratio, "covered (1-5×)"
    return ratio, "low (< 1×)" if ratio < 1.0 else "high (> 5×)"
