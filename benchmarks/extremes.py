"""Thin script: ``python benchmarks/extremes.py --help``; the code is :mod:`studies.extremes`."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout, not installed

from studies.extremes import main  # noqa: E402

if __name__ == "__main__":
    raise SystemExit(main())
