"""The knock-down study's face snaps against the clamped-strip Euler load (closed form).

Reads the study's table (``benchmarks/results/studies/fig5-knockdown/fig5-knockdown.csv`` by
default) and writes ``euler.md`` next to it: for every debond away from the load pad whose
first limit point is a load maximum, that load against the Euler load of the debonded face
as a strip clamped at both tips,

    σ_cr = π² E t² / (3 L²),    P_E = σ_cr b t d / (x / 2)

(t the face's thickness, L the debond's length, b the width, d the distance between the
faces' mid-planes; the face's membrane stress under the three-point bending moment
M = P x / 2 at the debond's centre x, from the nearer support, is M / (b t d)). The beam's
snap loads are located by walking the branch its path jumped from (docs/solver.md, "A top a
step jumps over"); the Euler load neglects the core's restraint of the tips and the moment's
variation along the debond, so it is an upper bound the snaps approach as the debond grows.

Run from the project root: ``python -m benchmarks.knockdown_euler [table.csv] [--out DIR]``
(``DIR``: the table's folder unless given; a rerun replaces ``euler.md``).
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

from benchmarks.provenance import RESULTS, ROOT, measured_on
from sandwich.scene_file import load_scene

DEFAULT = RESULTS / "studies" / "fig5-knockdown" / "fig5-knockdown.csv"
SCENE = ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"


def euler_load(scene, length: float, centre: float) -> float:
    """The clamped-strip Euler load P_E of a top-face debond of ``length`` centred at ``centre``."""
    face = scene.top
    E, t = face.material.Ex, face.thickness
    b, span = scene.width, scene.length
    d = scene.core.thickness + 0.5 * (face.thickness + scene.bottom.thickness)
    sigma = math.pi**2 * E * t**2 / (3.0 * length**2)
    arm = 0.5 * min(centre, span - centre)
    return sigma * b * t * d / arm


def main(argv: list[str] | None = None) -> int:
    """Write the table; return 0."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", nargs="?", type=Path, default=DEFAULT)
    parser.add_argument("--out", type=Path, default=None, metavar="DIR",
                        help="folder for euler.md (default: the table's)")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    pad = next(iter(scene.loads))
    rows = list(csv.DictReader(args.table.open()))
    lines = ["# Knock-down study: face snaps against the clamped-strip Euler load", "",
             f"Written by `benchmarks/knockdown_euler.py` from `{args.table.name}`; closed form "
             "in the script's docstring. Debonds that reach within 5 mm of the load pad "
             f"(x = {pad.x:g} ± {pad.width / 2:g} mm) are left out (the pad presses the face).",
             "", measured_on(verb="Computed") + " The study's run: its summary.md.",
             "", "| length (mm) | centre (mm) | first limit (beam) | Euler load | beam / Euler |",
             "|---|---|---|---|---|"]
    ratios: dict[float, list[float]] = {}
    for r in rows:
        length, centre = float(r["length"]), float(r["centre"])
        if length == 0.0 or r["first_limit_kind"] != "max" \
                or abs(centre - pad.x) < 0.5 * (length + pad.width) + 5.0:
            continue
        lam, p_e = float(r["first_limit_load"]), euler_load(scene, length, centre)
        if p_e > 2.0 * lam:  # the face does not snap first: the panel's own top
            continue
        ratios.setdefault(length, []).append(lam / p_e)
        lines.append(f"| {length:g} | {centre:g} | {lam:.1f} | {p_e:.1f} | {lam / p_e:.2f} |")
    lines += ["", "| length (mm) | beam / Euler, range |", "|---|---|"]
    lines += [f"| {k:g} | {min(v):.2f}-{max(v):.2f} |" for k, v in sorted(ratios.items())]
    out = (args.out or args.table.parent) / "euler.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    print(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
