"""G along the path at every debond tip, beam vs 2D, on fig5 and the c2/c3 cantilevers.

For each scene both models follow the scene's own path; each converged step's history holds
``G_<debond>_<tip>``, ``GI_…``, ``GII_…`` (N/mm). The table compares them at common values of the
scene's until-probe (interpolation of √G in each model's path, within the range both reached);
the plot overlays G, G_I and G_II against that probe. The 2D model also reports the domain
J-integral (``sandwich.plane2d.jintegral``, disc of 4 face thicknesses) as a cross-check of its G.

Run from the project root: ``python -m benchmarks.fracture_paths [--level medium] [--scenes fig5
c2 c3] [--reuse-2d] [--core 1] [--out DIR]``. Writes
``benchmarks/results/fracture/<scene>_<level>[_core<k>].md``, ``.csv`` and ``.png`` (or into
``DIR``; a rerun replaces them). ``--reuse-2d`` reads the 2D rows (G, split, J per converged
step) from the stored ``benchmarks/results/fracture/<scene>_<level>.csv`` instead of solving
the 2D model again (hours on this machine at medium); ``--core`` sets the beam's
``[beam_model] core`` (default: the scene's).
"""

from __future__ import annotations

import argparse
import csv
import os
import time
from pathlib import Path

import numpy as np

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.scene_file import load_scene

OUT = RESULTS / "fracture"
SCENES = {"fig5": "paper-fig5-top-debond-40-load-top", "c2": "paper-fig7-cantilever-c2",
          "c3": "paper-fig7-cantilever-c3"}
SAMPLES = 8  # probe values compared in the table
J_RADIUS_FACES = 4.0  # 2D J-integral disc radius / face thickness


def _solve(scene, model: str, level: str):
    if model == "beam":
        from sandwich.beam.solve import solve
        return solve(scene)
    from sandwich.plane2d.fracture import VcctEvaluator
    from sandwich.plane2d.jintegral import JIntegral
    from sandwich.plane2d.model import interface_z
    from sandwich.plane2d.solve import solve

    sol = solve(scene, level=level, keep_states=True, estimate=False)
    model, states = sol.reference2d_states
    radius = J_RADIUS_FACES * min(scene.top.thickness, scene.bottom.thickness)
    for t in VcctEvaluator(model).tips:
        j = JIntegral(model, t.x_tip, interface_z(scene, t.interface),
                      1.0 if t.tip == "end" else -1.0, radius)
        for r, (_, _, u) in zip(sol.history, states, strict=True):
            r.extra[f"J_{t.debond}_{t.tip}"] = j.evaluate(u)
    sol.extra["j_radius"] = radius
    return sol


def _stored_2d(stem: Path, probe: str):
    """The 2D rows of a stored table as a Solution (history: probe, λ, G/GI/GII/J per tip)."""
    from sandwich.results import Solution, StepRecord

    by_step: dict[int, StepRecord] = {}
    with open(f"{stem}.csv", newline="") as fh:
        for row in csv.DictReader(fh):
            if row["model"] != "2d":
                continue
            k = int(row["step"])
            rec = by_step.setdefault(k, StepRecord(k, float(row["load_factor"]),
                                                   {probe: float(row[probe])}, 0, {}))
            for p in ("G", "GI", "GII", "J"):
                if row[p] != "":
                    rec.extra[f"{p}_{row['tip']}"] = float(row[p])
    return Solution("2d", stem.name, [by_step[k] for k in sorted(by_step)], [], True,
                    f"rows reused from {stem.name}.csv (not solved again)", [], 0.0, 0,
                    {"cells": "stored", "vcct_closure_length": "stored", "j_radius": "stored"})


def _tips(sol) -> list[str]:
    return sorted({k[2:] for r in sol.history for k in r.extra if k.startswith("G_")})


def _path(sol, probe: str, tip: str) -> tuple[np.ndarray, ...]:
    w = np.array([r.probes[probe] for r in sol.history])
    cols = [np.array([r.extra.get(f"{p}_{tip}", 0.0) for r in sol.history])
            for p in ("G", "GI", "GII", "J")]
    return (w, np.array([r.load_factor for r in sol.history]), *cols)


def _interp_energy(x: float, xs: np.ndarray, g: np.ndarray) -> float:
    """Interpolate an energy release rate in √|G| (exact where G ∝ w², the linear regime)."""
    r = np.interp(x, xs, np.sign(g) * np.sqrt(np.abs(g)))
    return float(np.sign(r) * r * r)


def _monotone(path: tuple[np.ndarray, ...], sign: float) -> tuple[np.ndarray, ...]:
    """The path up to where the probe first stops moving towards the target (a turn-back)."""
    w = sign * path[0]
    back = np.flatnonzero(np.diff(w) <= 0)
    end = int(back[0]) + 1 if len(back) else len(w)
    return tuple(c[:end] for c in path)


def main() -> None:
    """Solve, tabulate and plot."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", default="medium")
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--reuse-2d", action="store_true")
    ap.add_argument("--core", default=None, help="beam core level (1…6 or auto)")
    add_out_argument(ap, OUT)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    load = os.getloadavg()[0]
    for key in args.scenes:
        scene = load_scene(ROOT / "scenes" / f"{SCENES[key]}.toml")
        if args.core is not None:
            import dataclasses

            core = args.core if args.core == "auto" else int(args.core)
            scene = dataclasses.replace(scene, beam_model=dataclasses.replace(
                scene.beam_model, core=core))
        probe = scene.analysis.until_probe
        stamp = measured_on() + (" The 2D rows are reused from the stored "
                                 f"{key}_{args.level}.csv, not solved in this run."
                                 if args.reuse_2d else "")
        sols, walls = {}, {}
        for model in ("beam", "2d"):
            t0 = time.perf_counter()
            sols[model] = (_stored_2d(OUT / f"{key}_{args.level}", probe)
                           if model == "2d" and args.reuse_2d else _solve(scene, model, args.level))
            walls[model] = time.perf_counter() - t0
        stem = args.out / (f"{key}_{args.level}" + (f"_core{args.core}" if args.core else ""))
        with open(f"{stem}.csv", "w", newline="") as fh:
            wr = csv.writer(fh)
            wr.writerow(["model", "tip", "step", "load_factor", probe, "G", "GI", "GII", "J"])
            for model, sol in sols.items():
                for tip in _tips(sol):
                    w, lam, g, gi, gii, j = _path(sol, probe, tip)
                    for k in range(len(w)):
                        wr.writerow([model, tip, k, lam[k], w[k], g[k], gi[k], gii[k],
                                     j[k] if model == "2d" else ""])
        lines = [f"# G along the path: {scene.name}", "",
                 f"Beam: {sols['beam'].extra.get('elements')} elements, core "
                 f"{scene.beam_model.core}, closure over Δ ≈ the thinner face "
                 f"thickness (sandwich.beam.fracture.closure_elements). 2D: level {args.level}, "
                 f"{sols['2d'].extra.get('cells')} cells, VCCT closure length "
                 f"{sols['2d'].extra.get('vcct_closure_length')} mm, J-integral disc radius "
                 f"{sols['2d'].extra.get('j_radius')} mm. "
                 f"Wall time beam {walls['beam']:.1f} s, 2D {walls['2d']:.1f} s "
                 f"(load average {load:.2f} at the start).", "", stamp, "",
                 f"Beam: {sols['beam'].message}", "", f"2D: {sols['2d'].message}", ""]
        tips = sorted(set(_tips(sols["beam"])) & set(_tips(sols["2d"])))
        sign = np.sign(scene.analysis.until_value)
        for tip in tips:
            pb = _monotone(_path(sols["beam"], probe, tip), sign)
            p2 = _monotone(_path(sols["2d"], probe, tip), sign)
            reach = min(sign * pb[0][-1], sign * p2[0][-1])
            lines += [f"## tip {tip}", "", f"Compared up to {probe} = {sign * reach:.4g} mm "
                      "(the shorter of the two paths before any turn-back of the probe).", "",
                      f"| {probe} (mm) | λ beam | λ 2D | G beam | G 2D | beam/2D | "
                      "GII/G beam | GII/G 2D | J 2D / G 2D |", "|" + "---|" * 9]
            for w in sign * np.linspace(reach / SAMPLES, reach, SAMPLES):
                row = []
                for p in (pb, p2):
                    row.append([np.interp(sign * w, sign * p[0], p[1]),
                                *(_interp_energy(sign * w, sign * p[0], c) for c in p[2:])])
                (lb, gb, _, giib, _), (l2, g2, _, gii2, j2) = row
                ratio = f"{gb / g2:.3f}" if g2 > 0 else "-"
                jr = f"{j2 / g2:.3f}" if g2 > 0 else "-"
                lines.append(f"| {w:.3g} | {lb:.4g} | {l2:.4g} | {gb:.4g} | {g2:.4g} | "
                             f"{ratio} | {giib / gb if gb > 0 else 0:.2f} | "
                             f"{gii2 / g2 if g2 > 0 else 0:.2f} | {jr} |")
            lines.append("")
        Path(f"{stem}.md").write_text("\n".join(lines) + "\n")
        _plot(scene, sols, probe, tips, f"{stem}.png")
        print(f"{key}: wrote {stem}.md/.csv/.png")


def _plot(scene, sols, probe, tips, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, max(1, len(tips)), figsize=(6 * max(1, len(tips)), 4.2),
                             squeeze=False)
    for ax, tip in zip(axes[0], tips, strict=False):
        for model, style in (("beam", "-"), ("2d", "--")):
            w, _, g, gi, gii, j = _path(sols[model], probe, tip)
            if model == "2d":
                ax.plot(w, j, "C2:", label="J 2d")
            ax.plot(w, g, "k" + style, label=f"G {model}")
            ax.plot(w, gi, "C0" + style, label=f"G_I {model}")
            ax.plot(w, gii, "C3" + style, label=f"G_II {model}")
        ax.set_xlabel(f"{probe} (mm)")
        ax.set_ylabel("G (N/mm)")
        ax.set_title(f"{scene.name}: tip {tip}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
