"""Thin script over :mod:`benchmarks.sweeps.tie_mismatch`: run it with ``-m``."""

from benchmarks.sweeps.tie_mismatch import main

if __name__ == "__main__":
    raise SystemExit(main())
