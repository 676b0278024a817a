"""How much memory a solve or a mesh will need, estimated from the scene before any work.

The command line compares these estimates with the memory the system has available
(``MemAvailable`` of ``/proc/meminfo``, :func:`available_bytes`) and refuses a run that cannot fit
before anything is meshed, solved or written (``sandwich.cli.memory_guard``).

Each estimate is a model of the peak resident set size of the command's process, fitted to peak
RSS measured by ``benchmarks/memory_guard.py`` on ``scenes/default.toml``
(``benchmarks/results/memory/memory_guard.md``: the rows, the fit and its error):

- **beam**: ``BEAM_BASE + BEAM_PER_WORK · elements · z · d`` where, at the core level ℓ the
  solve may build (:func:`beam_level`), ``z`` is the number of Gauss points through the core and
  ``d`` the DOFs of an element (both from :mod:`sandwich.beam.core_basis`): the element arrays the
  vectorised assembly holds at once scale with their product (measured: 0.93–1.13 of the peak at
  levels 1, 3, 4 and 5). Plus every converged state the path keeps (``8 · DOFs`` bytes each,
  ``analysis.max_steps`` of them at most; twice for ``"auto"``, which keeps the pass it checks).
- **2D solve**: ``TWO_D_BASE + TWO_D_PER_DOF · n · log2(n)`` for ``n`` DOFs (the MUMPS LDLᵀ factor
  of a 2D mesh under nested dissection grows as n log n), plus the kept states as above. ``n`` is
  twice the nodes of the 9-node quadrilateral mesh, whose cell count is computed exactly from the
  mesh layout (:func:`mesh_size`, no gmsh).
- **2D mesh** (``sandwich mesh``): ``MESH_BASE + MESH_PER_CELL · cells``.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

from sandwich.scene import Scene

GB = 1e9
STATE_BYTES_PER_DOF = 8.0  # a kept converged state: its float64 displacement vector

# Fitted by benchmarks/memory_guard.py (benchmarks/results/memory/memory_guard.md)
BEAM_BASE = 204.6e6  # bytes
BEAM_PER_WORK = 194.0  # bytes per element, core Gauss point and element DOF
TWO_D_BASE = 169.0e6  # bytes
TWO_D_PER_DOF = 189.5  # bytes per DOF and log2(DOFs)
MESH_BASE = 92.61e6  # bytes
MESH_PER_CELL = 1736.0  # bytes per cell


@dataclass(frozen=True)
class MemoryEstimate:
    """The estimated peak memory of one run, and what sets it.

    Attributes
    ----------
    what
        ``"beam solve"``, ``"2D solve"`` or ``"2D mesh"``.
    peak_bytes
        Estimated peak resident memory of the process (bytes).
    dofs
        Unknowns of the discretisation (cells for a mesh).
    detail
        The resolution in words (``"8000 elements at core level 3 (288036 DOFs)"``).
    keys
        The scene keys that set the size, the one to lower first.
    """

    what: str
    peak_bytes: float
    dofs: int
    detail: str
    keys: tuple[str, ...]


def beam_level(scene: Scene) -> tuple[int, str]:
    """The highest core level a beam solve of ``scene`` may build over every element, and why.

    A fixed ``core`` (raised by ``core_zones``) is that level. ``"auto"`` follows its path up to
    ``max_core_level``, but its error indicator builds the model with every element
    :data:`~sandwich.beam.core_levels.LOOKAHEAD` levels higher (up to the top level): at worst,
    with every element at the cap, that is the model it holds.
    """
    from sandwich.beam.core_basis import MAX_LEVEL
    from sandwich.beam.core_levels import LOOKAHEAD

    bm = scene.beam_model
    zones = max((z.level for z in bm.core_zones), default=1)
    if bm.core == "auto":
        cap = max(int(bm.max_core_level), zones)
        level = min(cap + LOOKAHEAD, MAX_LEVEL)
        return level, (f"core level {level} (\"auto\" up to beam_model.max_core_level = "
                       f"{cap}, its error check {level - cap} above)")
    level = max(int(bm.core), zones)
    return level, f"core level {level}"


def _beam_sizes(scene: Scene) -> tuple[int, int, int, str]:
    """Elements, DOFs, the work feature (elements × core Gauss points × element DOFs), words."""
    from sandwich.beam.core_basis import CoreBasis
    from sandwich.beam.dofs import NODE_DOFS, NODES_PER_ELEMENT

    bm = scene.beam_model
    level, why = beam_level(scene)
    basis = CoreBasis(bm.core_basis, level)
    node_dofs = NODE_DOFS + 4 * basis.count(level)
    n = int(bm.elements)
    work = n * len(basis.rule(level)[0]) * NODES_PER_ELEMENT * node_dofs
    dofs = (n + 1) * node_dofs
    return n, dofs, work, f"{n} elements at {why}, {dofs} DOFs"


def beam_work(scene: Scene) -> int:
    """Elements × core Gauss points × element DOFs at the level of :func:`beam_level`."""
    return _beam_sizes(scene)[2]


def states_bytes(scene: Scene, model: str, states: int | None = None) -> float:
    """Memory of the converged states a solve keeps (``states``, default the step budget)."""
    if states is None:
        states = _kept_states(scene)
        if model == "beam" and scene.beam_model.core == "auto":
            states *= 2  # auto keeps the pass it checks while it reruns the path
    dofs = _beam_sizes(scene)[1] if model == "beam" else 2 * mesh_size(scene)[1]
    return states * STATE_BYTES_PER_DOF * dofs


def beam_estimate(scene: Scene, states: int | None = None) -> MemoryEstimate:
    """Peak memory of a beam solve of ``scene`` (elements and core level of ``[beam_model]``).

    ``states``: converged states kept (default: every step of ``analysis.max_steps``).
    """
    bm = scene.beam_model
    n, dofs, work, detail = _beam_sizes(scene)
    peak = BEAM_BASE + BEAM_PER_WORK * work + states_bytes(scene, "beam", states)
    keys = ("beam_model.elements", "beam_model.max_core_level" if bm.core == "auto"
            else "beam_model.core", "analysis.max_steps")
    return MemoryEstimate("beam solve", peak, dofs, detail, keys)


def _kept_states(scene: Scene) -> int:
    """Converged states a path keeps at most (one for a linear analysis)."""
    a = scene.analysis
    return int(a.max_steps) + 1 if a.kind == "nonlinear" else 1


def n_log_n(n: int) -> float:
    """N log2 n: how the sparse LDLᵀ factor of a 2D mesh with n DOFs grows."""
    return n * math.log2(max(n, 2))


def mesh_size(scene: Scene) -> tuple[int, int]:
    """Cells and (approximate) nodes of the 2D mesh of ``scene``, without meshing it.

    The cells are exact: the segment layout along x (:func:`sandwich.meshes.build.segments_for`)
    times
    the element rows through the thickness. Nodes: those of a structured 9-node grid (the crack
    lips add a few). ``ValueError`` if the layout refuses the geometry.
    """
    from sandwich.meshes.build import segments_for
    from sandwich.meshes.layout import make_layout
    from sandwich.meshes.levels import sizing_for

    sizing = sizing_for(scene)
    with warnings.catch_warnings():  # merged stations are reported by the mesher itself
        warnings.simplefilter("ignore")
        layout = make_layout(scene, sizing.snap_tolerance, half=scene.reference2d.half_model)
    nx = sum(s.n for s in segments_for(layout, sizing))
    rows = 2 * sizing.face_rows + 2 * sizing.core_rows_half
    return nx * rows, (2 * nx + 1) * (2 * rows + 1)


def _resolution_2d(scene: Scene) -> str:
    opts = scene.reference2d
    return f"level {opts.level}" + (f" + refine {opts.refine}" if opts.refine else "")


def _keys_2d(scene: Scene) -> tuple[str, ...]:
    opts = scene.reference2d
    first = "reference2d.refine" if opts.refine else "reference2d.level"
    return (first, "reference2d.level" if opts.refine else "reference2d.refine")


def mesh_estimate(scene: Scene, states: int | None = None) -> MemoryEstimate:
    """Peak memory of ``sandwich mesh`` on ``scene`` (gmsh, the arrays, the files).

    ``states`` is ignored (a mesh solves nothing); it keeps the estimates' signature one.
    """
    cells, _ = mesh_size(scene)
    return MemoryEstimate("2D mesh", MESH_BASE + MESH_PER_CELL * cells, cells,
                          f"{_resolution_2d(scene)}: {cells} cells", _keys_2d(scene))


def reference2d_estimate(scene: Scene, states: int | None = None) -> MemoryEstimate:
    """Peak memory of a 2D solve of ``scene`` at its ``[reference2d]`` level and refinement.

    ``states``: converged states kept (default: every step of ``analysis.max_steps``).
    """
    cells, nodes = mesh_size(scene)
    dofs = 2 * nodes
    peak = TWO_D_BASE + TWO_D_PER_DOF * n_log_n(dofs) + states_bytes(scene, "2d", states)
    return MemoryEstimate("2D solve", peak, dofs,
                          f"{_resolution_2d(scene)}: {cells} cells, about {dofs} DOFs",
                          (*_keys_2d(scene), "analysis.max_steps"))


ESTIMATES = {"beam": beam_estimate, "2d": reference2d_estimate, "mesh": mesh_estimate}


def estimate(scene: Scene, what: str, states: int | None = None) -> MemoryEstimate:
    """The estimate of ``what``: ``"beam"``, ``"2d"`` (a solve) or ``"mesh"``."""
    return ESTIMATES[what](scene, states)


def available_bytes(meminfo: Path = Path("/proc/meminfo")) -> float | None:
    """Memory available to a new process now, bytes; None if it cannot be read.

    ``MemAvailable`` of ``/proc/meminfo`` (Linux ≥ 3.14); on older kernels ``MemFree + Buffers +
    Cached``, the same idea computed by hand; None elsewhere (no check is made then).
    """
    try:
        text = meminfo.read_text()
    except OSError:
        return None
    fields = {m.group(1): float(m.group(2)) * 1024.0
              for m in re.finditer(r"^(\w+):\s+(\d+)\s*kB", text, re.MULTILINE)}
    if "MemAvailable" in fields:
        return fields["MemAvailable"]
    parts = [fields.get(k) for k in ("MemFree", "Buffers", "Cached")]
    return sum(parts) if all(p is not None for p in parts) else None
