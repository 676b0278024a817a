"""The nodal degrees of freedom of the sandwich beam element, as data (eq. 8).

One table lists the 20 nodal DOFs in the paper's order. Each row says which layer the DOF
belongs to, which displacement it interpolates (``u`` axial, ``w`` transverse) and which
one-dimensional shape functions multiply it along x and through the layer thickness
(eqs. 11-13). Every index used anywhere in :mod:`sandwich.beam` is derived from this table.

Shape-function kinds (reference element, see :mod:`sandwich.beam.shape_functions`):

- along x: ``"L"`` linear Lagrange (face u), ``"H"`` Hermite value, ``"Hbar"`` Hermite slope;
- through the thickness: ``"L_t"``/``"L_b"`` linear Lagrange to the layer's top/bottom surface
  (face u), ``"1"`` constant (face w), ``"H_t"``/``"H_b"`` Hermite value and
  ``"Hbar_t"``/``"Hbar_b"`` Hermite slope at the core's top/bottom boundary.
"""

from __future__ import annotations

from dataclasses import dataclass

LAYERS = ("top", "core", "bottom")


@dataclass(frozen=True)
class NodalDof:
    """One row of the DOF table: name, layer, field and its shape-function kinds."""

    name: str
    layer: str  # "top" | "core" | "bottom"
    field: str  # "u" | "w"
    x_kind: str  # "L" | "H" | "Hbar"
    z_kind: str  # "L_t" | "L_b" | "1" | "H_t" | "H_b" | "Hbar_t" | "Hbar_b"


# eq. (8): the nodal displacement vector u(i), in the paper's order.
DOF_TABLE: tuple[NodalDof, ...] = (
    NodalDof("u_tt", "top", "u", "L", "L_t"),
    NodalDof("u_tb", "top", "u", "L", "L_b"),
    NodalDof("w_t", "top", "w", "H", "1"),
    NodalDof("w_t,x", "top", "w", "Hbar", "1"),
    NodalDof("u_ct", "core", "u", "H", "H_t"),
    NodalDof("u_ct,x", "core", "u", "Hbar", "H_t"),
    NodalDof("u_ct,z", "core", "u", "H", "Hbar_t"),
    NodalDof("u_cb", "core", "u", "H", "H_b"),
    NodalDof("u_cb,x", "core", "u", "Hbar", "H_b"),
    NodalDof("u_cb,z", "core", "u", "H", "Hbar_b"),
    NodalDof("w_ct", "core", "w", "H", "H_t"),
    NodalDof("w_ct,x", "core", "w", "Hbar", "H_t"),
    NodalDof("w_ct,z", "core", "w", "H", "Hbar_t"),
    NodalDof("w_cb", "core", "w", "H", "H_b"),
    NodalDof("w_cb,x", "core", "w", "Hbar", "H_b"),
    NodalDof("w_cb,z", "core", "w", "H", "Hbar_b"),
    NodalDof("u_bt", "bottom", "u", "L", "L_t"),
    NodalDof("u_bb", "bottom", "u", "L", "L_b"),
    NodalDof("w_b", "bottom", "w", "H", "1"),
    NodalDof("w_b,x", "bottom", "w", "Hbar", "1"),
)

DOF_NAMES: tuple[str, ...] = tuple(d.name for d in DOF_TABLE)
NODE_DOFS = len(DOF_TABLE)  # 20
NODES_PER_ELEMENT = 2
ELEMENT_DOFS = NODES_PER_ELEMENT * NODE_DOFS  # 40, eq. (9)

_INDEX = {name: i for i, name in enumerate(DOF_NAMES)}


def dof(name: str) -> int:
    """Position of the nodal DOF ``name`` in the nodal vector of eq. (8).

    Raises
    ------
    ValueError
        If ``name`` is not one of :data:`DOF_NAMES`.
    """
    try:
        return _INDEX[name]
    except KeyError:
        raise ValueError(f"unknown nodal DOF {name!r}; expected one of {DOF_NAMES}") from None


def global_dof(node: int | object, name: str) -> object:
    """Global index of DOF ``name`` at ``node`` (node-wise numbering; arrays broadcast)."""
    return NODE_DOFS * node + dof(name)


def layer_element_dofs(layer: str) -> tuple[int, ...]:
    """Element-local indices (0..39) of the DOFs a layer's displacement depends on (eq. 13)."""
    if layer not in LAYERS:
        raise ValueError(f"unknown layer {layer!r}; expected one of {LAYERS}")
    return tuple(
        n * NODE_DOFS + i
        for n in range(NODES_PER_ELEMENT)
        for i, d in enumerate(DOF_TABLE)
        if d.layer == layer
    )


# The interface ties of a bonded node (section 2.3): core boundary DOF = face surface DOF.
TIES: dict[str, tuple[tuple[str, str], ...]] = {
    "top": (("u_ct", "u_tb"), ("w_ct", "w_t"), ("w_ct,x", "w_t,x")),
    "bottom": (("u_cb", "u_bt"), ("w_cb", "w_b"), ("w_cb,x", "w_b,x")),
}

# Names of each face's DOFs, by role, for supports, loads and probes.
FACE_DOFS: dict[str, dict[str, str]] = {
    "top": {"u_top": "u_tt", "u_bottom": "u_tb", "w": "w_t", "w,x": "w_t,x"},
    "bottom": {"u_top": "u_bt", "u_bottom": "u_bb", "w": "w_b", "w,x": "w_b,x"},
}

# Contact pairs of a debonded interface: the face's inner surface (master) against the core
# boundary (slave), eqs. (41-42).
CONTACT_DOFS: dict[str, dict[str, str]] = {
    "top": {"u_face": "u_tb", "w_face": "w_t", "u_core": "u_ct", "w_core": "w_ct",
            "u_core,x": "u_ct,x", "w_core,x": "w_ct,x"},
    "bottom": {"u_face": "u_bt", "w_face": "w_b", "u_core": "u_cb", "w_core": "w_cb",
               "u_core,x": "u_cb,x", "w_core,x": "w_cb,x"},
}
