"""Time per Newton iteration of the beam model, and the full path of the fig. 5 scene.

Run: ``.venv/bin/python benchmarks/beam_speed.py [--quick]``. Writes
``benchmarks/results/beam/newton_iteration.{csv,md,png}`` and ``fig5_path.md``.

One Newton iteration = assembly of f_int and the tangent (eqs. 19, 24-25 + contact, into the
eliminated DOFs) + sparse factorisation + one solve. The state is a converged nonlinear state of
the paper's fig. 5 scene (40 mm top debond, contact active) at each element count.
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from beam_element import build_model, run  # noqa: E402
from sandwich.scene_file import load_scene  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "beam"
SCENE = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - t)
    return min(times), value


def assemble(model, u):
    model._cache = None  # time a fresh evaluation, not the cached one
    return model.tangent(u)


def newton_iteration_times(counts, repeat):
    scene = load_scene(SCENE)
    rows = []
    for n in counts:
        model = build_model(scene, elements=n)
        # a deformed state with contact: linear solution at a load giving ~5 mm at mid-span
        fac0 = model.factorize(model.tangent(np.zeros(model.size)))
        u = fac0.solve(model.f_ref)
        u *= -5.0 / (model.probe_vector("w_top_mid") @ u)
        u_full = model.expand(u)
        t_force, _ = best_of(partial(model.full_response, u_full, tangent=False), repeat)
        t_asm, K = best_of(partial(assemble, model, u), repeat)
        t_fac, fac = best_of(partial(model.factorize, K), repeat)
        r = model.internal_force(u) - model.f_ref
        t_sol, _ = best_of(partial(fac.solve, r), repeat)
        rows.append({"elements": model.mesh.n_elements, "dofs": model.size,
                     "force_s": t_force, "assembly_s": t_asm, "factorize_s": t_fac,
                     "solve_s": t_sol, "iteration_s": t_asm + t_fac + t_sol})
        print(f"{rows[-1]['elements']:5d} elements {model.size:7d} dofs: assembly {t_asm:.4f} s, "
              f"factorisation {t_fac:.4f} s, solve {t_sol:.4f} s", flush=True)
    return rows


def fig5_path(counts):
    """Full fig. 5 path at each element count (default graded mesh): one row per count."""
    scene = load_scene(SCENE)
    out = []
    for n in counts:
        t = time.perf_counter()
        r = run(scene, elements=n)
        wall = time.perf_counter() - t
        s = r.solution
        lam = s.history[-1].load_factor
        out.append((s.extra["elements"], wall, len(s.history), s.extra["total_newton_iterations"],
                    lam, s.converged, s.extra["max_penetration"]))
        print(f"fig5 {n}: {wall:.2f} s, {len(s.history)} steps, λ = {lam:.6g}", flush=True)
    return out


def richardson_limit(path_rows):
    """Mesh limit of λ(−15 mm) by Aitken's Δ² on the last three counts (each twice the last).

    Also returns the observed order p = log2 of the ratio of successive differences.
    """
    (n1, *_, l1), (n2, *_, l2), (n3, *_, l3) = [(r[0], r[4]) for r in path_rows[-3:]]
    if not (n2 == 2 * n1 and n3 == 2 * n2):
        raise ValueError("the last three element counts must double")
    d1, d2 = l1 - l2, l2 - l3
    if d1 == d2 or d1 * d2 <= 0:
        return l3, float("nan")  # not in the asymptotic range: no extrapolation
    return l3 - d2 * d2 / (d1 - d2), float(np.log2(d1 / d2))


def write(rows, path_rows):
    OUT.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    (OUT / "newton_iteration.csv").write_text(
        ",".join(keys) + "\n" + "".join(",".join(f"{r[k]:.6g}" for k in keys) + "\n" for r in rows))
    md = ["| elements | free DOFs | assembly (s) | factorisation (s) | solve (s) | iteration (s) |",
          "|---:|---:|---:|---:|---:|---:|"]
    md += [f"| {r['elements']} | {r['dofs']} | {r['assembly_s']:.4f} | {r['factorize_s']:.4f} | "
           f"{r['solve_s']:.5f} | {r['iteration_s']:.4f} |" for r in rows]
    (OUT / "newton_iteration.md").write_text("\n".join(md) + "\n")
    if path_rows:
        ref, order = richardson_limit(path_rows)
        md = ["| elements | wall (s) | steps | Newton iterations | final λ | λ vs limit | "
              "converged | max penetration (mm) |", "|---:|---:|---:|---:|---:|---:|---|---:|"]
        md += [f"| {e} | {w:.2f} | {s} | {it} | {lam:.6g} | {lam / ref - 1:+.2%} | {c} | {p:.2e} |"
               for e, w, s, it, lam, c, p in path_rows]
        within = [r for r in path_rows if abs(r[4] / ref - 1) <= 0.005 and r[5]]
        verdict = (f"Smallest count within 0.5 % of the limit: **{within[0][0]} elements, "
                   f"{within[0][1]:.1f} s** (target: under 10 s)." if within
                   else "No count within 0.5 % of the limit.")
        (OUT / "fig5_path.md").write_text(
            "Full path of paper-fig5-top-debond-40-load-top to w_top_mid = -15 mm "
            "(arc-length), the paper's element on the default graded mesh (small elements at "
            "supports, load edges, debond tips and all along the debond). The final λ is the "
            "load (N) at the target deflection; fixing the deflection and converging λ is the "
            "same statement as converging the deflection at that load. Limit: Aitken "
            f"extrapolation of the last three counts, λ∞ = {ref:.6g} N (observed order "
            f"{order:.2f}).\n\n" + "\n".join(md) + "\n\n" + verdict + "\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    n = [r["elements"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4))
    for key, label in (("assembly_s", "assembly"), ("factorize_s", "factorisation"),
                       ("solve_s", "solve"), ("iteration_s", "Newton iteration")):
        ax.loglog(n, [r[key] for r in rows], "o-", label=label)
    ax.loglog(n, [rows[0]["iteration_s"] * k / n[0] for k in n], "k:", label="linear growth")
    ax.set_xlabel("elements")
    ax.set_ylabel("time (s)")
    ax.set_title("beam model: time per Newton iteration")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "newton_iteration.png", dpi=120)


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="100..800 elements, no full path")
    args = p.parse_args()
    counts = [100, 200, 400, 800] if args.quick else [100, 200, 400, 800, 1600, 3200, 6400]
    rows = newton_iteration_times(counts, repeat=3)
    path_rows = [] if args.quick else fig5_path([120, 240, 360, 480, 960, 1920])
    write(rows, path_rows)


if __name__ == "__main__":
    main()
