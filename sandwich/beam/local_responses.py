"""A beam model's local responses: each element family's and contact group's forces and blocks.

The NumPy reference path (:mod:`sandwich.beam.element`: layer states, then their tangent) and the
compiled kernels' block output, both on the full DOFs, for what needs the element blocks
themselves rather than the reduced tangent: the NumPy path's assembly, the core level
indicators (:mod:`sandwich.beam.core_levels`), the energy release rate at a debond tip
(:mod:`sandwich.beam.fracture`).
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.assembly import scatter_vector
from sandwich.beam.contact import block_rows, compact_response, penalty_response
from sandwich.beam.element import LayerState, layer_state, layer_tangent

CHUNK = 1024  # elements per vectorised block (bounds memory at large element counts)


def reference_forces(
    model: object, u_full: np.ndarray
) -> tuple[np.ndarray, list[list[LayerState]]]:
    """Internal force on the full DOFs and the layer states (per family, chunk): NumPy.

    The reference path (:mod:`sandwich.beam.element`). With the compiled kernels the model
    takes :class:`~sandwich.beam.compiled_assembly.CompiledAssembly` instead, which assembles the
    reduced tangent in the same pass.
    """
    forces, states = [], []
    lengths = model.mesh.lengths
    for op, _, els, dofs in model.element_families():
        # layer_state reads u_e[:, op.dofs]: hand it the family's DOFs in op.dofs' slots.
        u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
        u_e[:, op.dofs] = u_full[dofs]
        family = [layer_state(op, u_e[s:s + CHUNK], lengths[els[s:s + CHUNK]], model.width)
                  for s in range(0, els.size, CHUNK)]
        states.append(family)
        forces.append(np.concatenate([st.f for st in family]))
    for pairs in model.pairs:
        forces.append(penalty_response(pairs, u_full, model.penalty, model.smoothing)[0])
    return scatter_vector(u_full.size, reference_rows(model, u_full), forces), states


def reference_rows(model: object, u_full: np.ndarray) -> list[np.ndarray]:
    """Full DOFs of the NumPy path's blocks at ``u_full``: layers, then contact (located)."""
    layers = model.block_dofs[:len(model.block_dofs) - len(model.pairs)]
    return layers + [block_rows(pairs, u_full) for pairs in model.pairs]


def reference_tangent_blocks(
    model: object, u_full: np.ndarray, states: list[list[LayerState]]
) -> list[np.ndarray]:
    """Local tangent blocks (layers, then contact) at the layer states of ``u_full``: NumPy."""
    blocks = [np.concatenate([layer_tangent(op, st, products) for st in family])
              for (op, products, _, _), family in zip(model.element_families(), states,
                                                      strict=True)]
    for pairs in model.pairs:
        blocks.append(penalty_response(pairs, u_full, model.penalty, model.smoothing)[1])
    return blocks


def compiled_local_responses(
    model: object, kernels: object, u_full: np.ndarray, tangent: bool, contact_blocks: bool,
    elements: np.ndarray | None,
) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Local forces with their full DOFs, and the local blocks, by the compiled kernels.

    :meth:`BeamModel.full_response <sandwich.beam.model.BeamModel.full_response>`'s compiled
    path: the layers of ``elements`` (all if None) by the kernels' block output (the NumPy path
    for a layer they do not evaluate), every contact group. Without ``tangent`` (or without
    ``contact_blocks``) no closest-point group's (m, n, n) block is formed.
    """
    forces, blocks, rows = [], [], []
    lengths = model.mesh.lengths
    for op, products, els, dofs in model.element_families():
        if elements is not None:
            keep = np.isin(els, elements)
            if not keep.any():
                continue
            els, dofs = els[keep], dofs[keep]
        rows.append(dofs)
        if kernels.supports(op):
            f, K = kernels.layer_blocks(op, u_full[dofs], lengths[els], model.width, tangent)
        else:
            u_e = np.zeros((els.size, int(op.dofs.max()) + 1))
            u_e[:, op.dofs] = u_full[dofs]
            st = layer_state(op, u_e, lengths[els], model.width)
            f, K = st.f, (layer_tangent(op, st, products) if tangent else None)
        forces.append(f)
        blocks.append(K)
    for pairs in model.pairs:
        if pairs.search == "closest-point" and not (tangent and contact_blocks):
            f10, _, _, _, dofs10 = compact_response(pairs, u_full, model.penalty,
                                                    model.smoothing)
            forces.append(f10)
            rows.append(dofs10)
            continue
        f, K, _, _ = penalty_response(pairs, u_full, model.penalty, model.smoothing)
        forces.append(f)
        rows.append(block_rows(pairs, u_full))
        if contact_blocks:
            blocks.append(K)
    return rows, forces, blocks
