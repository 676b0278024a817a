"""Scenes with known answers shared by the benchmarks and the tests (closed-form fracture cases)."""
