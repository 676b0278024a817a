"""Beam vs 2D reference: split the deflection into global bending and local indentation.

Run from the project root: ``python -m benchmarks.beam_vs_2d_split SCENE UNTIL [beam elements]
[2D level] [load=patch|uniform] [kind=nonlinear|linear]``. Prints, at common load levels,
w_top_mid, w_bottom_mid and their difference (indentation of the top face into the core) for
both models. ``load=uniform`` replaces the patch by the same force spread over the whole top face
(no local indentation) to isolate global behaviour. Throwaway experiment for docs/comparisons.md;
it writes no table.
"""

import argparse
import dataclasses
import time

import numpy as np

from sandwich.scene_file import load_scene


def main(argv: list[str] | None = None) -> int:
    """Solve both models on the scene and print the split at nine common load levels."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="scene file")
    ap.add_argument("until", type=float, help="target of the scene's until probe (mm)")
    ap.add_argument("elements", type=int, nargs="?", default=240, help="beam elements")
    ap.add_argument("level", nargs="?", default="coarse", help="2D mesh level")
    ap.add_argument("load", nargs="?", default="patch", choices=("patch", "uniform"))
    ap.add_argument("kind", nargs="?", default="nonlinear", choices=("nonlinear", "linear"))
    a = ap.parse_args(argv)
    import sandwich.beam
    import sandwich.plane2d

    s = load_scene(a.scene)
    an = dataclasses.replace(s.analysis, until_value=a.until, kind=a.kind)
    s = dataclasses.replace(s, analysis=an)
    if a.load == "uniform":
        s = dataclasses.replace(s, loads=tuple(
            dataclasses.replace(ld, x=s.length / 2, width=s.length) for ld in s.loads))
    out = {}
    for name, fn in (("beam", lambda: sandwich.beam.run(
            s, elements=a.elements, model_options={"face_membrane": "averaged"}).solution),
                     ("2d", lambda: sandwich.plane2d.solve(s, level=a.level, estimate=False))):
        t = time.perf_counter()
        sol = fn()
        h = sol.history
        lam = np.array([r.load_factor for r in h])
        wt = np.array([r.probes["w_top_mid"] for r in h])
        wb = np.array([r.probes["w_bottom_mid"] for r in h])
        out[name] = (lam, wt, wb)
        print(name, sol.dofs, f"{time.perf_counter() - t:.1f}s", flush=True)
    lmax = min(out["beam"][0].max(), out["2d"][0].max())
    print("lambda | beam w_top w_bot indent | 2d w_top w_bot indent | ratios top bot indent")
    for lam in np.linspace(0, lmax, 9)[1:]:
        row = []
        for m in ("beam", "2d"):
            L, wt, wb = out[m]
            top, bottom = np.interp(lam, L, wt), np.interp(lam, L, wb)
            row.append((top, bottom, top - bottom))
        r = [row[0][i] / row[1][i] for i in range(3)]
        print(f"{lam:8.2f} | {row[0][0]:8.4f} {row[0][1]:8.4f} {row[0][2]:8.4f} | "
              f"{row[1][0]:8.4f} {row[1][1]:8.4f} {row[1][2]:8.4f} | "
              f"{r[0]:.4f} {r[1]:.4f} {r[2]:.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
