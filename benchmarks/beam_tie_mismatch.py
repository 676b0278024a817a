"""Thin script over :mod:`benchmarks.sweeps.tie_mismatch`."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout, not installed

from benchmarks.sweeps.tie_mismatch import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main())
