"""Speed and accuracy benchmarks: scripts that write their tables under ``benchmarks/results/``.

Run one from the project root as a module, e.g. ``.venv/bin/python -m benchmarks.scene_speed``.
"""
