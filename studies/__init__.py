"""Studies over many cases: the code behind the benchmark tables, importable by tests.

- :mod:`studies.extremes`: stability of both models at the extremes of the parameter space;
- :mod:`studies.tradeoff`: speed against accuracy over resolutions of both models;
- :mod:`studies.tie_mismatch`: the beam element's interface-tie mismatch (its order, soft cores).

The scripts in ``benchmarks/`` only call their ``main``; tables go to ``benchmarks/results/``.
Models are reached through the registry (:mod:`models`).
"""
