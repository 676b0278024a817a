"""Beam vs 2D, linear, fig. 4/5 scene with extra probes: where does the compliance differ?

Run from the project root: ``python -m benchmarks.beam_vs_2d_support SCENE [elements] [level]``.
Linear analyses at λ = 100 N (load control); prints w of both faces at the support (x = 0; the
top face over the support shows how much the core is squeezed there), at x = 75 and at mid-span,
for both models. Throwaway experiment for docs/comparisons.md; it writes no table.
"""

import argparse
import dataclasses

from sandwich.scene import Probe
from sandwich.scene_file import load_scene


def main(argv: list[str] | None = None) -> int:
    """Solve both models linearly on the scene and print the faces' w at the probes."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="scene file")
    ap.add_argument("elements", type=int, nargs="?", default=240, help="beam elements")
    ap.add_argument("level", nargs="?", default="coarse", help="2D mesh level")
    a = ap.parse_args(argv)
    import sandwich.beam
    import sandwich.plane2d

    s = load_scene(a.scene)
    probes = tuple(Probe(f"w_{f}_{x:g}", f, x) for x in (0.0, 75.0, 150.0)
                   for f in ("top", "bottom"))
    an = dataclasses.replace(s.analysis, kind="linear", control="load", until_load_factor=100.0,
                             until_probe=None, until_value=None)
    s = dataclasses.replace(s, probes=probes, analysis=an)
    b = sandwich.beam.run(s, elements=a.elements).solution.history[-1].probes
    r = sandwich.plane2d.solve(s, level=a.level, estimate=False).history[-1].probes
    print(f"{'probe':14s} {'beam':>10s} {'2d':>10s} {'beam/2d':>8s}")
    for p in probes:
        print(f"{p.name:14s} {b[p.name]:10.5f} {r[p.name]:10.5f} {b[p.name] / r[p.name]:8.4f}")
    for x in ("0", "75", "150"):
        db, dr = b[f"w_top_{x}"] - b[f"w_bottom_{x}"], r[f"w_top_{x}"] - r[f"w_bottom_{x}"]
        print(f"squeeze x={x:4s} {db:10.5f} {dr:10.5f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
