"""Thin script over :mod:`benchmarks.sweeps.extremes`: ``python -m benchmarks.extremes --help``."""

from benchmarks.sweeps.extremes import main

if __name__ == "__main__":
    raise SystemExit(main())
