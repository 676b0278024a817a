"""How much memory a solve or a mesh will need, estimated from the scene before any work.

The command line compares these estimates with the memory the system has available
(``MemAvailable`` of ``/proc/meminfo``, :func:`available_bytes`) and refuses a run that cannot fit
before anything is meshed, solved or written (``sandwich.cli.memory_guard``).

Each estimate is a model of the peak resident set size of the command's process, fitted to peak
RSS measured by ``benchmarks/memory_guard.py`` on ``scenes/default.toml``
(``benchmarks/results/memory/memory_guard.md``: the rows, the fit and its error):

- **beam**: ``BEAM_BASE + BEAM_PER_ELEMENT · elements + BEAM_PER_DOF · DOFs + contact +
  states``, summed over the models the solve holds at once (:func:`held_levels`: one at the
  fixed level; for ``"auto"`` the path's at ``max_core_level`` and its check's
  :data:`~sandwich.beam.core_levels.LOOKAHEAD` levels above), each with every node at its
  level. Per element what does not grow with the core level (the faces' arrays and slot maps,
  the mesh, the fields); per DOF the tangent's values and their spares and the envelope factors
  held at once (the path's last state's and the corrector's).
- **contact term** (closest-point contact on a debond, nonlinear analysis:
  :func:`closest_point_growth`): ``CONTACT_PER_ENTRY · E`` per model held, E the entries of its
  tangent's sparsity pattern (:func:`pattern_entries`). A closest-point pair's pattern holds the
  core segments next to its node; as the faces slide past them it grows by the segments met,
  and the envelope LDLᵀ's symbolic structure (:class:`~sandwich.solver.envelope.EnvelopeStructure`,
  whose maps are the size of the pattern, not of the factor) is built again on the grown
  pattern and widened as pairs close. While a widened structure is built, the one it replaces
  is still held: per entry of the pattern, the new structure's slot map (8 bytes: two int64 per
  entry of the stored triangle, half the entries), its runs (12 bytes: three int64 per run, runs
  of about one entry in the reverse Cuthill-McKee order a widening takes) and its values'
  pattern (8 bytes), the full-length slot map its construction holds before cutting it to the
  triangle (16 bytes) and the next factor's storage (≈ 5 bytes): 49 bytes, derived, not fitted
  (measured at core level 1, 8000 and 16000 elements: 63 and 56 bytes per entry above the
  same-x run, whose pattern never grows). On the scene's own path the faces slide past a
  segment at any useful resolution (the default scene at core level 1: from 2000 elements on by
  w_top_mid = −2 mm), so the term is always counted.
- **states**: every converged state the path keeps (``8 · DOFs`` bytes each at the highest
  level, ``analysis.max_steps`` of them at most; twice for ``"auto"``, which keeps the pass it
  checks).
- Not covered: where a tangent's pivot-free LDLᵀ is refused (a tiny pivot), the beam
  factorises it with SuperLU's pivoting LU (:class:`~sandwich.solver.sparse.SparseFactorization`),
  whose factors are several times the envelope's; such runs peak well above the estimate (the
  table's last section).
- **2D solve**: ``TWO_D_BASE + TWO_D_PER_DOF · n · log2(n)`` for ``n`` DOFs (the MUMPS LDLᵀ factor
  of a 2D mesh under nested dissection grows as n log n), plus the kept states as above. ``n`` is
  twice the nodes of the 9-node quadrilateral mesh, whose cell count is computed exactly from the
  mesh layout (:func:`mesh_size`, no gmsh). Where the mesh estimate's coarser path runs in a
  process beside the solve (:func:`beside_estimate`), that process's estimate is added (derived:
  a 2D solve at the coarser level; not fitted).
- **2D mesh** (``sandwich mesh``): ``MESH_BASE + MESH_PER_CELL · cells``.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

from sandwich.scene import Scene

GB = 1e9
STATE_BYTES_PER_DOF = 8.0  # a kept converged state: its float64 displacement vector

# Fitted by benchmarks/memory_guard.py (benchmarks/results/memory/memory_guard.md)
BEAM_BASE = 38.39e6  # bytes
BEAM_PER_ELEMENT = 22496.0  # bytes per element of the models held
BEAM_PER_DOF = 1444.5  # bytes per DOF of the models held
# Derived (module docstring): a widened envelope structure and its construction, per entry of
# the tangent's pattern, while the structure it replaces is still held
CONTACT_PER_ENTRY = 8.0 + 12.0 + 8.0 + 16.0 + 5.0  # bytes
ENTRY_SAMPLE = (60, 120)  # elements of the two small models the entries are counted on
TWO_D_BASE = 179.9e6  # bytes
TWO_D_PER_DOF = 192.0  # bytes per DOF and log2(DOFs)
MESH_BASE = 92.49e6  # bytes
MESH_PER_CELL = 1797.2  # bytes per cell


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
    with every element at the cap, that is the largest model it holds (with the path's own,
    :func:`held_levels`).
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


def held_levels(scene: Scene) -> tuple[int, ...]:
    """Core levels of the beam models a solve of ``scene`` holds at once, every element at each.

    A fixed ``core``: one model, :func:`beam_level`'s. ``"auto"``: the path's model (at most
    ``max_core_level``) and its check's (:func:`beam_level`), which re-converges the path's
    states while the path's model is kept.
    """
    level = beam_level(scene)[0]
    bm = scene.beam_model
    if bm.core != "auto":
        return (level,)
    zones = max((z.level for z in bm.core_zones), default=1)
    return (max(int(bm.max_core_level), zones), level)


def _dofs_at(scene: Scene, level: int) -> int:
    """DOFs of the beam model of ``scene`` with every node at core ``level``."""
    from sandwich.beam.core_basis import CoreBasis
    from sandwich.beam.dofs import NODE_DOFS

    basis = CoreBasis(scene.beam_model.core_basis, level)
    return (int(scene.beam_model.elements) + 1) * (NODE_DOFS + 4 * basis.count(level))


def _beam_sizes(scene: Scene) -> tuple[int, int, str]:
    """Elements, DOFs at the level of :func:`beam_level`, words."""
    level, why = beam_level(scene)
    n = int(scene.beam_model.elements)
    dofs = _dofs_at(scene, level)
    return n, dofs, f"{n} elements at {why}, {dofs} DOFs"


def beam_dofs(scene: Scene) -> int:
    """DOFs of the beam models a solve holds at once (:func:`held_levels`), summed."""
    return sum(_dofs_at(scene, level) for level in held_levels(scene))


def beam_elements(scene: Scene) -> int:
    """Elements of the beam models a solve holds at once (:func:`held_levels`), summed."""
    return len(held_levels(scene)) * int(scene.beam_model.elements)


def closest_point_growth(scene: Scene) -> bool:
    """Whether the contact term applies: closest-point pairs on a debond, a nonlinear path."""
    return (bool(scene.debonds) and scene.analysis.kind == "nonlinear"
            and scene.beam_model.contact_search == "closest-point")


def pattern_entries(scene: Scene, level: int) -> int:
    """Entries of the beam tangent's sparsity pattern with every element at core ``level``.

    Counted on the scene's own model at :data:`ENTRY_SAMPLE` elements (built in milliseconds,
    nothing solved): the entries per element between the two (the layers' blocks and the
    debonds' contact pairs; the fixed part of the supports and ends cancels) times
    ``beam_model.elements``. Within 0.3 % of the pattern of the full model on the default scene
    at 2000 elements (level 1, 3, 5).
    """
    from sandwich.beam.build import build_model, scene_model_options

    small, large = ENTRY_SAMPLE
    count = [build_model(scene, elements=m, core_level=level,
                         **scene_model_options(scene)).pattern.indices.size
             for m in ENTRY_SAMPLE]
    per_element = (count[1] - count[0]) / (large - small)
    return int(round(count[0] + per_element * (int(scene.beam_model.elements) - small)))


def contact_bytes(scene: Scene) -> float:
    """The contact term: ``CONTACT_PER_ENTRY`` × :func:`pattern_entries` where it applies.

    Of every model held at once (:func:`held_levels`): each grows its own pattern.
    """
    if not closest_point_growth(scene):
        return 0.0
    return CONTACT_PER_ENTRY * sum(pattern_entries(scene, level)
                                   for level in held_levels(scene))


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
    n, dofs, detail = _beam_sizes(scene)
    peak = (BEAM_BASE + BEAM_PER_ELEMENT * beam_elements(scene) + BEAM_PER_DOF * beam_dofs(scene)
            + contact_bytes(scene) + states_bytes(scene, "beam", states))
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

    ``states``: converged states kept (default: every step of ``analysis.max_steps``). Where
    the mesh estimate's coarser path runs in a process beside the solve
    (:func:`beside_estimate`), that process's peak is added: both are held at once.
    """
    cells, nodes = mesh_size(scene)
    dofs = 2 * nodes
    peak = TWO_D_BASE + TWO_D_PER_DOF * n_log_n(dofs) + states_bytes(scene, "2d", states)
    beside = beside_estimate(scene)
    detail = f"{_resolution_2d(scene)}: {cells} cells, about {dofs} DOFs"
    if beside is not None:
        peak += beside.peak_bytes
        detail += f", and the mesh estimate's {beside.detail} beside it"
    return MemoryEstimate("2D solve", peak, dofs, detail,
                          (*_keys_2d(scene), "analysis.max_steps"))


def beside_estimate(scene: Scene) -> MemoryEstimate | None:
    """The process beside a 2D solve of ``scene``: its mesh estimate's coarser path, or None.

    That path runs in a second process (:mod:`sandwich.plane2d.beside`) where the estimate is on,
    the level has a coarser one and the machine more than one core (and
    ``SANDWICH_ESTIMATE_BESIDE`` is not ``0``); its peak is a 2D solve's at the coarser level.
    """
    from sandwich.meshes.levels import coarser_level

    opts = scene.reference2d
    against = coarser_level(opts.level, opts.refine)
    if (not opts.error_estimate or against is None or (os.cpu_count() or 1) < 2
            or os.environ.get("SANDWICH_ESTIMATE_BESIDE", "1") == "0"):
        return None
    coarser = dataclasses.replace(scene, reference2d=dataclasses.replace(
        opts, level=against.level, refine=against.refine, error_estimate=False))
    return reference2d_estimate(coarser)


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
