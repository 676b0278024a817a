"""Child process that renders one field snapshot with pyvista: ``NPZ PNG MODEL SCALE``."""

import sys
from pathlib import Path

import numpy as np

from comparisons.deformed import render_with_pyvista
from comparisons.snapshots import FieldSnapshot


def main(argv: list[str]) -> int:
    """Render the snapshot stored in ``argv[0]`` into ``argv[1]``."""
    npz, png, model, scale = argv
    with np.load(npz) as z:
        snap = FieldSnapshot(model=model, step=int(z["step"]), load_factor=float(z["load_factor"]),
                             points=z["points"], displacement=z["displacement"], cells=z["cells"],
                             von_mises=z["von_mises"],
                             region=z["region"] if "region" in z else None)
    render_with_pyvista(snap, Path(png), scale=float(scale))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
