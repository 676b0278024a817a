"""Thin script over :mod:`benchmarks.sweeps.tradeoff`: ``python -m benchmarks.tradeoff --help``."""

from benchmarks.sweeps.tradeoff import main

if __name__ == "__main__":
    raise SystemExit(main())
