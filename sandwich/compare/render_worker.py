"""Child process rendering one field frame with pyvista.

Arguments: ``VTU PNG MODEL STEP LOAD_FACTOR SCALE``.
"""

import sys
from pathlib import Path

from sandwich.compare.deformed import picture_from_vtu, render_with_pyvista


def main(argv: list[str]) -> int:
    """Render the frame stored in ``argv[0]`` into ``argv[1]``."""
    vtu, png, model, step, load_factor, scale = argv
    pic = picture_from_vtu(Path(vtu), model, int(step), float(load_factor))
    render_with_pyvista(pic, Path(png), scale=float(scale))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
