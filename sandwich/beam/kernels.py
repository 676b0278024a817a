"""The compiled layer kernels and the sparse assembly's kernels, as the model calls them.

A layer's internal force (eq. 19) and consistent tangent (eqs. 24-25) are evaluated in one pass
by one of three numba kernels, chosen here per layer:

- the packed kernel (:mod:`sandwich.beam.packed_kernel`), for any layer;
- the averaged kernel (:mod:`sandwich.beam.averaged_kernel`: same arrays, ε_x averaged along η)
  for layers with the ``membrane_average`` option (the faces' default), or the NumPy path where
  its assumptions fail (:func:`supports`);
- the sum-factorised kernel (:mod:`sandwich.beam.sum_factor`: same integrand, same points, ξ
  summed first) for layers whose rows factor into x- and z-functions at a tensor rule, where
  that saves enough flops (:func:`uses_sum_factorisation`): the cores, the paper's one
  included. The faces keep the packed kernel.

The tangent is either written as blocks ``(E, n, n)`` (:func:`layer_response`, the
:mod:`sandwich.beam.element` interface) or scattered straight into the values of the reduced CSR
matrix through a precomputed slot map (:func:`layer_assemble`, used by the model), which skips
the blocks and their concatenation. The sparse assembly's kernels
(:mod:`sandwich.beam.csr_kernels`) and the packed kernel's operators are exported from here
too: this module is the compiled path's one entry.
"""

from __future__ import annotations

import numpy as np

from sandwich.beam.averaged_kernel import averaged_kernel, averaging_weights
from sandwich.beam.csr_kernels import (
    abs_matvec,
    add_reduced,
    block_pattern,
    block_slots,
    embed_pattern,
    scatter_blocks,
    scatter_compact,
    scatter_compact_known,
)
from sandwich.beam.layer_operators import LayerOperators
from sandwich.beam.packed_kernel import (
    KernelOperators,
    kernel_operators,
    packed_kernel,
    point_flops,
)
from sandwich.beam.sum_factor import factored_flops, factored_kernel, factored_operators

__all__ = ["KernelOperators", "abs_matvec", "add_reduced", "block_pattern", "block_slots",
           "embed_pattern", "kernel_operators", "layer_assemble", "layer_blocks", "layer_flops",
           "layer_response", "point_flops", "scatter_blocks", "scatter_compact",
           "scatter_compact_known", "supports", "uses_sum_factorisation"]


def supports(op: LayerOperators) -> bool:
    """Whether a kernel evaluates ``op``.

    Every layer without the ``membrane_average`` option; with it, where
    :func:`~sandwich.beam.averaged_kernel.averaging_weights` accepts the rule and stiffness
    (tensor rule with η slowest, separable weights, symmetric C: every layer the model builds).
    """
    return not op.membrane_average or averaging_weights(op) is not None



_NO_BLOCKS = np.empty((0, 0, 0))
_NO_SLOTS = np.empty((0, 0, 0), dtype=np.int32)
_NO_SIGNS = np.empty((0, 0, 0), dtype=np.int8)
_NO_DATA = np.empty(0)


SUM_FACTORISATION = "auto"  # "auto" (by flops, below), "always" (where the rows factor), "never"
# auto: factored when its flops × this < the packed kernel's. Measured (docs/speed.md,
# machine B, 2026-12-05): the paper's core (2.2× fewer flops) force + tangent 0.79-0.85 against
# 1.0 ms at 240 elements, fig. 5's path 6-10 % faster; the paper's faces (1.4×) slower factored
# (0.19 against 0.145 ms); from level 2 on (3.7× and more) factored is far faster. (3.0 until
# then, from a measurement under load in which the paper's core tied.)
FACTORED_OVERHEAD = 2.0


def uses_sum_factorisation(op: LayerOperators) -> bool:
    """Whether ``op`` is evaluated by the sum-factorised kernel (:mod:`sandwich.beam.sum_factor`).

    Only where the rows factor (tensor rule, every column an x-function times a z-function,
    checked); then by :data:`SUM_FACTORISATION`: ``"auto"`` takes it when its flops
    (:func:`~sandwich.beam.sum_factor.factored_flops`) times :data:`FACTORED_OVERHEAD` are fewer
    than the packed kernel's (:func:`point_flops` × G), i.e. the cores (the paper's one
    included), not the faces. Decided on the tangent's flops, for force-only calls too: a
    force is the same with or without its tangent, bit for bit. Kept on ``op`` for the
    setting it was made under (the flop counts cost ≈ 0.15 ms, and the kernels ask on every
    call); a changed setting is obeyed at once.
    """
    key = (SUM_FACTORISATION, FACTORED_OVERHEAD)  # the decision, kept on ``op`` per setting
    known = op.__dict__.get("_uses_sum_factorisation")
    if known is not None and known[0] == key:
        return known[1]
    if SUM_FACTORISATION == "never":
        use = False
    else:
        fo = factored_operators(op)
        use = fo is not None and (
            SUM_FACTORISATION == "always"
            or FACTORED_OVERHEAD * factored_flops(fo) < op.eta.size * point_flops(op))
    object.__setattr__(op, "_uses_sum_factorisation", (key, use))
    return use


def layer_flops(op: LayerOperators, tangent: bool = True) -> int:
    """Flops per element of whichever kernel evaluates ``op`` (as executed)."""
    if uses_sum_factorisation(op):
        return factored_flops(factored_operators(op), tangent)
    return op.eta.size * point_flops(op, tangent)


def _run(op, u_l, lengths, width, want_k, K_out, slots, signs, data):
    k = kernel_operators(op)
    u_l = np.ascontiguousarray(u_l, dtype=float)
    if u_l.ndim != 2 or u_l.shape[1] != k.dofs.size:
        raise ValueError(f"expected values of the layer's {k.dofs.size} DOFs, got {u_l.shape}")
    lengths = np.ascontiguousarray(lengths, dtype=float)
    if lengths.shape != (u_l.shape[0],):
        raise ValueError(f"expected {u_l.shape[0]} element lengths, got {lengths.shape}")
    f = np.empty((u_l.shape[0], k.dofs.size))
    if op.membrane_average:
        wbar = averaging_weights(op)
        if wbar is None:
            raise ValueError(f"{op.name}: membrane_average needs a tensor rule and symmetric C")
        q = k.packed
        averaged_kernel(u_l, lengths, float(width), k.NuT, k.MwT, k.Nu, k.Mw, q.Quu, q.Qww,
                        q.Quw, q.pu, q.pw, k.ucols, k.wcols, k.x_slope, k.weight, wbar,
                        k.stiffness, k.thickness, f, want_k, K_out, slots, signs, data)
        return f
    if uses_sum_factorisation(op):
        fo = factored_operators(op)
        factored_kernel(u_l, lengths, float(width), fo.Xu, fo.Xdu, fo.ZuT, fo.ZduT, fo.iu,
                        fo.ju, fo.Xw, fo.Xdw, fo.ZwT, fo.ZdwT, fo.iw, fo.jw, fo.Quu, fo.Puu,
                        fo.Qww, fo.Pww, fo.Quw, fo.Puw, fo.entries, k.ucols, k.wcols,
                        k.x_slope, k.weight, k.stiffness, k.thickness, f, want_k, K_out, slots,
                        signs, data)
        return f
    q = k.packed
    packed_kernel(u_l, lengths, float(width), k.NuT, k.MwT, k.Nu, k.Mw, q.Quu, q.Qww, q.Quw,
                  q.pu, q.pw, k.ucols, k.wcols, k.x_slope, k.weight, k.stiffness, k.thickness, f,
                  want_k, K_out, slots, signs, data)
    return f


def layer_response(
    op: LayerOperators, u_e: np.ndarray, lengths: np.ndarray, width: float,
    tangent: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Force ``(E, n)`` and tangent blocks ``(E, n, n)`` (or None).

    The compiled twin of :func:`sandwich.beam.element.layer_response`.

    Parameters
    ----------
    op
        The layer (one the kernels evaluate, see :func:`supports`).
    u_e
        Element DOF vectors ``(E, n_element)`` (physical slopes), indexed by ``op.dofs``.
    lengths
        Element lengths (mm), ``(E,)``.
    width
        Beam width (mm).
    tangent
        Whether to compute the tangent.
    """
    if not supports(op):
        raise ValueError(f"{op.name}: not evaluated by the kernels, use sandwich.beam.element")
    E, n = u_e.shape[0], op.dofs.size
    K = np.empty((E, n, n)) if tangent else _NO_BLOCKS
    f = _run(op, np.asarray(u_e)[:, op.dofs], lengths, width, tangent, K, _NO_SLOTS, _NO_SIGNS,
             _NO_DATA)
    return f, (K if tangent else None)


def layer_blocks(
    op: LayerOperators, u_l: np.ndarray, lengths: np.ndarray, width: float,
    tangent: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Force ``(E, n)`` and tangent blocks ``(E, n, n)`` from the layer's DOF values ``u_l``.

    As :func:`layer_response`, with ``u_l = u_e[:, op.dofs]`` already gathered.
    """
    E, n = np.shape(u_l)[0], op.dofs.size
    K = np.empty((E, n, n)) if tangent else _NO_BLOCKS
    f = _run(op, u_l, lengths, width, tangent, K, _NO_SLOTS, _NO_SIGNS, _NO_DATA)
    return f, (K if tangent else None)


def layer_assemble(
    op: LayerOperators, u_l: np.ndarray, lengths: np.ndarray, width: float,
    slots: np.ndarray | None, signs: np.ndarray | None, data: np.ndarray,
) -> np.ndarray:
    """Force ``(E, n)``; with ``slots`` the tangent is added into ``data`` (CSR values) in place.

    ``u_l`` ``(E, n)`` holds the values of the layer's DOFs ``op.dofs`` of each element (physical
    slopes), e.g. ``u_full[family DOFs]``.

    ``slots[e, a, b]`` is the CSR slot of the layer's entry (a, b) of element e in the reduced
    matrix (−1 if it is eliminated) and ``signs`` its sign product
    (:meth:`sandwich.beam.assembly.ReducedPattern.family_slots`).
    """
    if slots is None:
        return _run(op, u_l, lengths, width, False, _NO_BLOCKS, _NO_SLOTS, _NO_SIGNS, _NO_DATA)
    return _run(op, u_l, lengths, width, True, _NO_BLOCKS, slots, signs, data)
