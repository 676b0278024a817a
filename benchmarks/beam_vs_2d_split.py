"""Beam vs 2D reference: split the deflection into global bending and local indentation.

Run: ``XDG_CACHE_HOME=.cache .venv/bin/python benchmarks/beam_vs_2d_split.py SCENE UNTIL
[beam elements] [2D level] [load=patch|uniform] [kind=nonlinear|linear]``. Prints, at common
load levels, w_top_mid, w_bottom_mid and their difference (indentation of the top face into the
core) for both models. ``load=uniform`` replaces the patch by the same force spread over the whole
top face (no local indentation) to isolate global behaviour. Throwaway experiment for
docs/beam_vs_2d.md.
"""

import dataclasses
import sys
import time

import numpy as np

import sandwich.beam
import sandwich.plane2d
from sandwich.scene_file import load_scene

path, until = sys.argv[1], float(sys.argv[2])
n = int(sys.argv[3]) if len(sys.argv) > 3 else 240
level = sys.argv[4] if len(sys.argv) > 4 else "coarse"
load = sys.argv[5] if len(sys.argv) > 5 else "patch"
kind = sys.argv[6] if len(sys.argv) > 6 else "nonlinear"
s = load_scene(path)
an = dataclasses.replace(s.analysis, until_value=until, kind=kind)
s = dataclasses.replace(s, analysis=an)
if load == "uniform":
    s = dataclasses.replace(s, loads=tuple(dataclasses.replace(ld, x=s.length / 2, width=s.length)
                                           for ld in s.loads))
out = {}
for name, fn in (("beam", lambda: sandwich.beam.run(
        s, elements=n, model_options={"face_membrane": "averaged"}).solution),
                 ("2d", lambda: sandwich.plane2d.solve(s, level=level))):
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
        a, b = np.interp(lam, L, wt), np.interp(lam, L, wb)
        row.append((a, b, a - b))
    r = [row[0][i] / row[1][i] for i in range(3)]
    print(f"{lam:8.2f} | {row[0][0]:8.4f} {row[0][1]:8.4f} {row[0][2]:8.4f} | "
          f"{row[1][0]:8.4f} {row[1][1]:8.4f} {row[1][2]:8.4f} | {r[0]:.4f} {r[1]:.4f} {r[2]:.4f}")
