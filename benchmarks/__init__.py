"""Speed and accuracy benchmarks: scripts that write their tables under ``benchmarks/results/``.

Run one from the project root as a module, e.g. ``python -m benchmarks.scene_speed``; it imports
the installed ``sandwich`` package. Each benchmark keeps one current table in its folder under
``benchmarks/results/`` (a rerun replaces it, ``--out DIR`` writes elsewhere), and every table
says the machine and date it was measured on (:mod:`benchmarks.provenance`;
``SANDWICH_BENCH_MACHINE`` names the machine).
"""
