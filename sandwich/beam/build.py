"""Build the beam model of a scene: :func:`build_model` and the options a scene sets.

:func:`build_model` turns a scene into nodes (:mod:`~sandwich.beam.mesh`), layer rules
(:mod:`~sandwich.beam.layer_operators`), the core's level groups
(:mod:`~sandwich.beam.core_groups`), the elimination of ties and supports
(:mod:`~sandwich.beam.constraints`), loads and probes (:mod:`~sandwich.beam.loads`) and contact
pairs on debonded stretches (:mod:`~sandwich.beam.contact_search`), and hands them to
:class:`~sandwich.beam.model.BeamModel`. :func:`scene_model_options` and
:func:`scene_gauss_orders` read the element choices of a scene's ``[beam_model]``.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.cohesive import cohesive_groups
from sandwich.beam.constitutive import core_stiffness, face_stiffness
from sandwich.beam.constraints import DofMap, NodeSupport, build_dof_map
from sandwich.beam.contact_search import DEFAULT_REACH, contact_pair_groups
from sandwich.beam.core_basis import CoreBasis
from sandwich.beam.core_groups import CoreGroup, core_groups, node_levels
from sandwich.beam.dofs import ELEMENT_DOFS, NODE_DOFS
from sandwich.beam.element import geometric_products
from sandwich.beam.fracture import beam_tips
from sandwich.beam.layer_operators import (
    LayerOperators,
    build_core_operators,
    build_face_operators,
    build_layer_operators,
)
from sandwich.beam.loads import (
    patch_load,
    point_load,
    probe_row,
    stretch_patch_load,
    stretch_point_load,
    stretch_row,
)
from sandwich.beam.mesh import DEFAULT_GROWTH, DEFAULT_SIZE_RATIO, BeamMesh, build_mesh
from sandwich.beam.model import PENETRATION_BOUND, BeamModel
from sandwich.beam.quadrature import EXACT_ORDER
from sandwich.scene import FACE_MEMBRANES, GRADINGS, BeamModelOptions

PENALTY_FACTOR = 1e4  # default contact penalty ε = PENALTY_FACTOR · Q_z / h_c  (N/mm³)
SMOOTHING_FRACTION = 0.002  # default contact regularisation width s = SMOOTHING_FRACTION × bound
FACES = ("top", "bottom")


def mesh_stations(scene: object) -> list[float]:
    """X positions that must be nodes: debond ends, supports, loads (patch edges).

    Probes are not: each is read where it falls by the element's interpolation
    (:func:`~sandwich.beam.loads.probe_row`), so any number of them leaves the mesh as it is.
    """
    pts: list[float] = []
    for d in scene.debonds:
        if d.end > d.start:  # a zero-length debond unties no node: not a station
            pts += [d.start, d.end]
    pts += [s.x for s in scene.supports]
    for load in scene.loads:
        pts += [load.x] if load.width == 0 else [*load.span, load.x]
    return pts


def refinement_centres(scene: object) -> list[float]:
    """Where the graded mesh puts its smallest elements: supports, debond tips, load edges."""
    pts: list[float] = [s.x for s in scene.supports]
    for d in scene.debonds:
        if d.end > d.start:
            pts += [d.start, d.end]
    for load in scene.loads:
        pts += [load.x] if load.width == 0 else list(load.span)
    return pts


def refinement_zones(scene: object) -> list[tuple[float, float]]:
    """Intervals the graded mesh fills with its smallest elements: the debonded stretches.

    A debonded face is free to buckle or wrinkle over its whole length; with the paper's face
    interpolation (u linear, w cubic) the buckled face locks in membrane unless its elements are
    short all along the debond, not only at the tips (measured on fig. 5: docs/beam_element.md,
    speed). The stretches a cohesive tip may open too: its process zone runs along them.
    """
    return ([(d.start, d.end) for d in scene.debonds if d.end > d.start]
            + [tuple(sorted((s.origin, s.far))) for s in scene.cohesive_spans()])


def default_contact_smoothing(scene: object) -> float:
    """The contact law's default regularisation width s (mm).

    ``SMOOTHING_FRACTION`` × the allowed penetration (``PENETRATION_BOUND`` × the thinner face).
    """
    return SMOOTHING_FRACTION * PENETRATION_BOUND * min(float(scene.top.thickness),
                                                        float(scene.bottom.thickness))

def build_model(
    scene: object,
    *,
    elements: int | None = None,
    gauss: dict[str, tuple[int, int]] | None = None,
    contact_penalty: float | None = None,
    contact_smoothing: float | None = None,
    grading: str = "graded",
    growth: float = DEFAULT_GROWTH,
    size_ratio: float = DEFAULT_SIZE_RATIO,
    face_membrane: str | None = None,
    contact_search: str | None = None,
    contact_reach: float = DEFAULT_REACH,
    core_level: int | np.ndarray | None = None,
    core_basis: str = "sublayers",
    face_stretch: bool | None = None,
    mesh: BeamMesh | None = None,
) -> BeamModel:
    """Discretise ``scene`` (a :class:`sandwich.scene.Scene`) with the beam element.

    Parameters
    ----------
    scene
        The problem.
    elements
        Element count over the length (default ``scene.beam_model.elements``); kept exactly.
    gauss
        Gauss orders (n_η, n_ξ) per layer name; default
        :data:`~sandwich.beam.quadrature.EXACT_ORDER`
        (exact for the polynomial strain energy).
    contact_penalty
        Contact penalty ε (N/mm³); default ``scene.beam_model.contact_penalty`` or
        ``PENALTY_FACTOR · Q_z / h_c``.
    contact_smoothing
        Width s (mm) over which the penalty pressure is regularised
        (:func:`~sandwich.beam.contact_law.pressure_law`); default ``SMOOTHING_FRACTION`` × the
        penetration bound. 0 gives the plain (kinked) penalty.
    grading, growth, size_ratio
        Mesh along x (:func:`~sandwich.beam.mesh.build_mesh`): ``"graded"`` (default) puts the
        smallest elements at :func:`refinement_centres` and all along :func:`refinement_zones`
        and grows them by ``growth`` per element up to ``size_ratio`` × the smallest;
        ``"tips"`` grades towards the centres only; ``"uniform"`` keeps one size.
    face_membrane
        ``"paper"``: the faces' ε_x of eq. (15) at every Gauss point. ``"averaged"`` (departs
        from the paper): the faces' ε_x is its element mean along x (assumed membrane strain;
        removes membrane locking, see docs/comparisons.md). Default: the scene's
        ``[beam_model] face_membrane`` (``"averaged"``).
    contact_search
        Pairing on debonded stretches (:func:`~sandwich.beam.contact_search.contact_pairs`):
        ``"same-x"`` (the paper's closest-node rule under small sliding): each untied face
        node against the core point of the same x; ``"closest-point"``: the node projected on
        the deformed core boundary curve (node-to-segment, consistent linearisation, continuous
        beyond the search reach, docs/contact.md). Default: the scene's
        ``[beam_model] contact_search`` (``"closest-point"``: with the faces' stretch and core
        levels ≥ 3 the same-x pairing stalls on fig. 5, docs/comparisons.md).
    contact_reach
        Closest-point search: the segments within this distance (mm) on each side of a node, at
        least one per side, are searched (default ``DEFAULT_REACH``).
    core_level
        Level of the core hierarchy (:mod:`sandwich.beam.core_basis`): one integer for every
        element, or one per element of the mesh :func:`beam_mesh` gives (see
        :mod:`sandwich.beam.core_levels`); default 1, the paper's core.
    core_basis
        Enrichment family of levels > 1: ``"sublayers"`` (default) or ``"polynomial"``.
    face_stretch
        ``False`` (the paper's faces): a face's w is constant through its thickness.
        ``True``: each face gets a stretch DOF per node
        (:func:`~sandwich.beam.layer_operators.build_face_operators`), so that a rotated face
        bends as stiffly as an unrotated one; stored first in each node's extra block.
        Default: the scene's ``[beam_model] faces`` (``"stretch"`` unless it says ``"paper"``).
    mesh
        The nodes along x, in place of the ones ``elements`` and ``grading`` give (every
        station must be a node: :func:`sandwich.beam.bisection.bisected_mesh` of a built
        model's mesh keeps them).
    """
    options = getattr(scene, "beam_model", None)
    if face_membrane is None:
        face_membrane = getattr(options, "face_membrane", BeamModelOptions.face_membrane)
    if contact_search is None:
        contact_search = getattr(options, "contact_search", BeamModelOptions.contact_search)
    if face_membrane not in FACE_MEMBRANES:
        raise ValueError(f"face_membrane must be one of {FACE_MEMBRANES}, got {face_membrane!r}")
    if face_stretch is None:
        face_stretch = getattr(options, "faces", BeamModelOptions.faces) == "stretch"
    if elements is None:
        elements = getattr(options, "elements", BeamModelOptions.elements)
    if mesh is None:
        mesh = beam_mesh(scene, elements, grading=grading, growth=growth, size_ratio=size_ratio)
    if not (np.isfinite(scene.width) and scene.width > 0):
        raise ValueError(f"beam width must be positive, got {scene.width!r}")
    orders = dict(EXACT_ORDER)
    orders.update(gauss or {})
    layers, stiffness, z_bottom = _layers(scene, orders, face_membrane, face_stretch)
    levels = np.broadcast_to(np.asarray(1 if core_level is None else core_level, dtype=int),
                             (mesh.n_elements,)).copy()
    if np.any(levels < 1):
        raise ValueError(f"core levels must be >= 1, got {levels.min()}")
    basis = CoreBasis(core_basis, int(levels.max()))
    groups, mode_active, face_dofs = _core_layout(
        scene, mesh, levels, basis, layers,
        lambda level: build_core_operators(scene.core.thickness, z_bottom["core"],
                                           stiffness["core"], basis, level,
                                           gauss=orders["core"]),
        face_stretch)
    cohesive = cohesive_groups(scene, mesh.x, stiffness["core"][1, 1])
    dof_map, bonded = _dof_map(scene, mesh, mode_active, face_stretch, cohesive)
    pairs = [group for i in FACES if np.any(~bonded[i])
             for group in contact_pair_groups(i, np.flatnonzero(~bonded[i]), mesh.x, scene.width,
                                              search=contact_search, reach=contact_reach)]
    pairs += cohesive
    if contact_penalty is None:
        contact_penalty = getattr(options, "contact_penalty", None)
    if contact_penalty is None:
        contact_penalty = PENALTY_FACTOR * stiffness["core"][1, 1] / scene.core.thickness
    if contact_smoothing is None:
        contact_smoothing = default_contact_smoothing(scene)
    model = BeamModel(
        name=scene.name, mesh=mesh, width=float(scene.width), layers=layers,
        products={n: geometric_products(op) for n, op in layers.items()},
        dof_map=dof_map, pairs=pairs, penalty=float(contact_penalty),
        f_ref_full=_reference_load(scene, mesh, mode_active.shape, face_stretch),
        probe_rows=_probe_rows(scene, mesh, mode_active.shape, face_stretch),
        face_thickness={"top": scene.top.thickness, "bottom": scene.bottom.thickness},
        smoothing=float(contact_smoothing), core=groups, element_levels=levels,
        face_dofs=face_dofs,
    )
    model.fracture_tips = beam_tips(scene, model)
    return model


def _layers(
    scene: object, orders: dict[str, tuple[int, int]], face_membrane: str, face_stretch: bool
) -> tuple[dict[str, LayerOperators], dict[str, np.ndarray], dict[str, float]]:
    """The layers' rows (the paper's core), their stiffness matrices and bottom heights z (mm)."""
    hc, ht, hb = scene.core.thickness, scene.top.thickness, scene.bottom.thickness
    z_bottom = {"top": hc / 2, "core": -hc / 2, "bottom": -hc / 2 - hb}
    stiffness = {"top": face_stiffness(scene.top.material),
                 "core": core_stiffness(scene.core.material),
                 "bottom": face_stiffness(scene.bottom.material)}
    thickness = {"top": ht, "core": hc, "bottom": hb}
    if face_stretch:  # the face's through-thickness modulus, uncoupled (σ_z = E ε_z)
        for n in FACES:
            stiffness[n] = stiffness[n].copy()
            stiffness[n][1, 1] = stiffness[n][0, 0]
    layers = {"core": build_layer_operators("core", hc, z_bottom["core"], stiffness["core"],
                                            gauss=orders["core"])}
    for n in FACES:
        layers[n] = build_face_operators(n, thickness[n], z_bottom[n], stiffness[n],
                                         gauss=orders[n],
                                         membrane_average=face_membrane == "averaged",
                                         stretch=face_stretch)
    return layers, stiffness, z_bottom


def _core_layout(
    scene: object, mesh: BeamMesh, levels: np.ndarray, basis: CoreBasis,
    layers: dict[str, LayerOperators], core_operators: object, face_stretch: bool,
) -> tuple[list[CoreGroup], np.ndarray, dict[str, np.ndarray] | None]:
    """The core's level groups, each node's active extra DOFs and the faces' DOF families.

    A node's extra block holds the faces' stretch DOFs (top, bottom; with ``face_stretch``),
    then the core enrichment of the highest level; ``mode_active`` (n_nodes, block) says which
    of them the node carries. ``core_operators(level)`` gives a level's core rows.
    """
    groups: list[CoreGroup] = []
    m = 4 * basis.count(basis.max_level)
    fs = 2 if face_stretch else 0  # face stretch DOFs per node (top, bottom), first in the block
    e = np.arange(mesh.n_elements)[:, None]
    if basis.max_level > 1:
        groups = core_groups(basis, levels, NODE_DOFS * e + np.arange(ELEMENT_DOFS)[None, :],
                             mesh.n_nodes, core_operators, stride=m + fs, offset=fs)
    mode_active = (np.arange(m)[None, :]
                   < 4 * np.array([basis.count(int(k)) for k in node_levels(levels)])[:, None])
    face_dofs = None
    if face_stretch:
        mode_active = np.concatenate([np.ones((mesh.n_nodes, 2), dtype=bool), mode_active], 1)
        paper = NODE_DOFS * e + np.arange(ELEMENT_DOFS)[None, :]
        face_dofs = {}
        for j, n in enumerate(FACES):
            ext = NODE_DOFS * mesh.n_nodes + (m + fs) * (e + np.arange(2)[None, :]) + j
            face_dofs[n] = np.concatenate([paper, ext], axis=1)[:, layers[n].dofs]
    return groups, mode_active, face_dofs


def _dof_map(
    scene: object, mesh: BeamMesh, mode_active: np.ndarray, face_stretch: bool,
    cohesive: list,
) -> tuple[DofMap, dict[str, np.ndarray]]:
    """The elimination of ties and supports, and each face's bonded nodes (contact elsewhere).

    With ``face_stretch`` a clamp also holds the face's stretch (``mode_active`` is changed in
    place): it holds the face's whole end section, so no thickness change there. The nodes of
    ``cohesive`` groups are untied (the law holds them), not bonded and not contact nodes.
    """
    tol = 1e-9 * scene.length
    bonded = {i: np.array([scene.is_bonded(i, float(x), tol) for x in mesh.x]) for i in FACES}
    for group in cohesive:
        bonded[group.interface][group.nodes] = True  # no contact pair of its own
    ties = {i: b.copy() for i, b in bonded.items()}
    for group in cohesive:
        ties[group.interface][group.nodes] = False
    supports = [NodeSupport(mesh.node_at(s.x, 1e-6 * scene.length), face, s.type)
                for s in scene.supports for face in s.faces]
    if face_stretch:
        for s in supports:
            if s.type == "clamp":
                mode_active[s.node, FACES.index(s.face)] = False
    return build_dof_map(mesh.n_nodes, ties, supports, mode_active), bonded


def _reference_load(
    scene: object, mesh: BeamMesh, extra_shape: tuple[int, int], face_stretch: bool
) -> np.ndarray:
    """f_ref on the full DOFs: the scene's loads at unit load factor (none on the enrichment).

    With ``face_stretch`` the loads act on the faces' outer surfaces: they work on the faces'
    stretch DOFs too.
    """
    f_ref = np.zeros(NODE_DOFS * mesh.n_nodes)
    for load in scene.loads:
        if load.width == 0:
            f_ref += point_load(mesh, load.on, load.x, load.force)
        else:
            f_ref += patch_load(mesh, load.on, *load.span, load.force)
    extra = np.zeros(extra_shape)
    if face_stretch:
        for load in scene.loads:
            j = FACES.index(load.on)
            extra[:, j] += (stretch_point_load(mesh, load.x, load.force) if load.width == 0
                            else stretch_patch_load(mesh, *load.span, load.force))
    return np.concatenate([f_ref, extra.ravel()])


def _probe_rows(
    scene: object, mesh: BeamMesh, extra_shape: tuple[int, int], face_stretch: bool
) -> dict[str, np.ndarray]:
    """Each probe's row c on the full DOFs: w of the face's mid-surface, where 2D reads it."""
    probes = {}
    for p in scene.probes:
        extra = np.zeros(extra_shape)
        if face_stretch:
            nodes, weights = stretch_row(mesh, p.x)
            extra[nodes, FACES.index(p.on)] = 0.5 * weights
        probes[p.name] = np.concatenate([probe_row(mesh, p.on, p.x), extra.ravel()])
    return probes


def beam_mesh(
    scene: object,
    elements: int,
    *,
    grading: str = "graded",
    growth: float = DEFAULT_GROWTH,
    size_ratio: float = DEFAULT_SIZE_RATIO,
) -> BeamMesh:
    """The nodes :func:`build_model` puts on ``scene`` for ``elements`` elements."""
    if grading not in GRADINGS:
        raise ValueError(f"grading must be one of {GRADINGS}, got {grading!r}")
    return build_mesh(scene.length, elements, mesh_stations(scene),
                      centres=refinement_centres(scene),
                      zones=refinement_zones(scene) if grading == "graded" else (),
                      grading="uniform" if grading == "uniform" else "graded", growth=growth,
                      size_ratio=size_ratio)


def scene_model_options(scene: object) -> dict[str, object]:
    """The :func:`build_model` options a scene's ``[beam_model]`` sets.

    Grading, face membrane, contact search, core basis and faces (the element choices; the
    core levels are chosen by :func:`sandwich.beam.core_choice.choose_core_levels`).
    """
    bm = scene.beam_model
    return {"grading": getattr(bm, "grading", "graded"),
            "face_membrane": getattr(bm, "face_membrane", "averaged"),
            "contact_search": getattr(bm, "contact_search", "closest-point"),
            "core_basis": getattr(bm, "core_basis", "sublayers"),
            "face_stretch": getattr(bm, "faces", "stretch") == "stretch"}


def scene_gauss_orders(scene: object) -> dict[str, tuple[int, int]]:
    """Per-layer Gauss orders: the exact rule, raised (never lowered) by the scene's options."""
    opts = getattr(scene, "beam_model", None)
    gx, gz = getattr(opts, "gauss_x", None), getattr(opts, "gauss_z", None)
    orders = {}
    for layer, (nx, nz) in EXACT_ORDER.items():
        orders[layer] = (max(nx, gx or 0), max(nz, gz or 0))
    return orders
