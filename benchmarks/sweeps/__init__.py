"""Research sweeps behind some benchmark tables (extremes, speed against accuracy, tie mismatch).

Each writes under ``benchmarks/results/``; the thin scripts in ``benchmarks/`` call their ``main``.
"""
