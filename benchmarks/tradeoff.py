"""Thin script over :mod:`benchmarks.sweeps.tradeoff` (``--help``)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout, not installed

from benchmarks.sweeps.tradeoff import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main())
