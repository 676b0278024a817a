"""Sparse assembly straight into the eliminated (free) DOFs, on a precomputed pattern.

Each local contribution (element layer or contact pair) is a dense block on a list of full DOFs.
With u_full = T u_free and T holding at most one ±1 per row (:mod:`sandwich.beam.constraints`),
the reduced tangent Tᵀ K T is a signed scatter of the local entries. The scatter map — which CSR
slot each local entry lands in and with which sign — is computed once; assembling is then one
``np.bincount``. Node-wise numbering keeps the reduced matrix banded.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from functools import cached_property
from types import ModuleType

import numpy as np
import scipy.sparse as sp

from sandwich.beam.constraints import DofMap


@dataclass(frozen=True)
class ReducedPattern:
    """Where the entries of a list of dense local blocks go in the reduced CSR matrix.

    The slot map of a family (each local entry's CSR slot and sign) is built when first asked
    for (:meth:`slots_of`): a family assembled another way (closest-point contact, on each
    pair's chosen segment: :func:`sandwich.beam.kernels.scatter_compact`) never builds its
    (B, n, n) map, which on fine meshes is the largest array of the model.
    """

    block_dofs: tuple[np.ndarray, ...]  # per block family: (B, n) full DOF indices
    indices: np.ndarray
    indptr: np.ndarray
    n: int
    free: tuple[np.ndarray, ...]  # per family: (B, n) reduced DOF (−1: eliminated), int64
    sign: tuple[np.ndarray, ...]  # per family: (B, n) sign of the reduced DOF (0: eliminated)
    compiled: bool = True  # slot maps by the compiled kernels where numba is (else NumPy)
    _slots: dict = field(default_factory=dict, repr=False, compare=False)

    def slots_of(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Family ``i``'s ``(slots, signs)`` of shape ``(B, n, n)`` (−1 / 0 where eliminated).

        For in-place assembly (:func:`sandwich.beam.kernels.layer_assemble`); computed on first
        use, then kept.
        """
        if i not in self._slots:
            f = self.free[i]
            B, m = f.shape
            kernels = compiled_kernels() if self.compiled else None
            if kernels is None:
                slots = _slots_sorted(f, self.indptr, self.indices).astype(np.int32)
            else:  # written as int32 straight from the int32 pattern: no copies
                slots = np.empty((B, m, m), dtype=np.int32)
                kernels.block_slots(f, self.indptr, self.indices, self.n, slots)
            sg = self.sign[i]
            self._slots[i] = (slots, sg[:, :, None] * sg[:, None, :])
        return self._slots[i]

    @property
    def family_slots(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Every family's :meth:`slots_of`."""
        return tuple(self.slots_of(i) for i in range(len(self.block_dofs)))

    @cached_property
    def keep(self) -> np.ndarray:
        """Bool over all local entries (families concatenated, row-major): not eliminated."""
        return np.concatenate([s.reshape(-1) >= 0 for s, _ in self.family_slots])

    @cached_property
    def slot(self) -> np.ndarray:
        """CSR slot of each kept local entry."""
        return np.concatenate([s.reshape(-1) for s, _ in self.family_slots])[self.keep].astype(
            np.int64)

    @cached_property
    def weight(self) -> np.ndarray:
        """Sign product of each kept local entry."""
        return np.concatenate([w.reshape(-1) for _, w in self.family_slots])[self.keep].astype(
            float)

    def assemble(self, blocks: list[np.ndarray]) -> sp.csr_matrix:
        """Reduced matrix Tᵀ K T from local blocks, one array (B, n, n) per family."""
        values = np.concatenate([b.reshape(-1) for b in blocks])[self.keep]
        data = np.bincount(self.slot, weights=self.weight * values, minlength=self.indices.size)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))


def _slots_sorted(free: np.ndarray, indptr: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """:meth:`ReducedPattern.slots_of` without numba: one sorted search per kept entry."""
    B, m = free.shape
    n = indptr.size - 1
    r = np.repeat(free[:, :, None], m, axis=2).reshape(-1)
    c = np.repeat(free[:, None, :], m, axis=1).reshape(-1)
    ok = (r >= 0) & (c >= 0)
    out = np.full(r.size, -1, dtype=np.int64)
    # the pattern's keys row * (n + 1) + column are sorted (rows in order, columns sorted)
    row_key = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr)) * (n + 1) + indices
    out[ok] = np.searchsorted(row_key, r[ok] * (n + 1) + c[ok])
    return out.reshape(B, m, m)


def reduced_pattern(
    block_dofs: list[np.ndarray], dof_map: DofMap, compiled: bool = True
) -> ReducedPattern:
    """Precompute the scatter of local blocks (full DOF index arrays ``(B, n)``) into Tᵀ K T.

    Compiled (:func:`sandwich.beam.kernels.block_pattern`: one pass over the blocks of each
    row) where numba is and ``compiled``, else by sorting every local entry's key; the slot maps
    per family on demand (:meth:`ReducedPattern.slots_of`), by the same rule.
    """
    kernels = compiled_kernels() if compiled else None
    n = dof_map.n_free
    free = [np.ascontiguousarray(dof_map.free[d], dtype=np.int64) for d in block_dofs]
    sign = [np.where(f >= 0, dof_map.sign[d], 0).astype(np.int8)
            for f, d in zip(free, block_dofs, strict=True)]
    if kernels is None:
        indptr, indices = _pattern_sorted(free, n)
    else:
        indptr, indices = _pattern_compiled(free, n, kernels.block_pattern)
    return ReducedPattern(block_dofs=tuple(block_dofs), indices=indices, indptr=indptr, n=n,
                          free=tuple(free), sign=tuple(sign), compiled=compiled)


def _pattern_compiled(free: list[np.ndarray], n: int, block_pattern) -> tuple:
    widths = np.concatenate([np.full(f.shape[0], f.shape[1], dtype=np.int64) for f in free])
    bptr = np.concatenate([[0], np.cumsum(widths)]).astype(np.int64)
    bdofs = np.concatenate([f.reshape(-1) for f in free])
    block_of = np.repeat(np.arange(widths.size), widths)
    ok = bdofs >= 0
    rows, blocks = bdofs[ok], block_of[ok]
    order = np.lexsort((blocks, rows))  # by row; a block listed once per row it holds
    rows, blocks = rows[order], blocks[order]
    first = np.ones(rows.size, dtype=bool)
    first[1:] = (rows[1:] != rows[:-1]) | (blocks[1:] != blocks[:-1])
    rows, blocks = rows[first], blocks[first]
    inc_ptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    indptr, indices = block_pattern(bptr, bdofs, inc_ptr, blocks.astype(np.int64), n)
    return indptr.astype(np.int32), indices.astype(np.int32)


def _pattern_sorted(free: list[np.ndarray], n: int) -> tuple:
    """The canonical CSR pattern of the blocks' entries by sorting their keys (no numba)."""
    keys = []
    for f in free:
        m = f.shape[1]
        r = np.repeat(f[:, :, None], m, axis=2).reshape(-1)
        c = np.repeat(f[:, None, :], m, axis=1).reshape(-1)
        ok = (r >= 0) & (c >= 0)
        keys.append(np.unique(r[ok] * n + c[ok]))
    unique = np.unique(np.concatenate(keys))
    indptr = np.searchsorted(unique // n, np.arange(n + 1)).astype(np.int32)
    return indptr, (unique % n).astype(np.int32)


@functools.cache
def compiled_kernels() -> ModuleType | None:
    """:mod:`sandwich.beam.kernels` (imported on first use), or None without numba."""
    try:
        from sandwich.beam import kernels
    except ImportError:
        return None
    return kernels


def scatter_vector(
    n_full: int, block_dofs: list[np.ndarray], blocks: list[np.ndarray]
) -> np.ndarray:
    """Full vector Σ of local vectors, one (B, n) array per family."""
    idx = np.concatenate([d.reshape(-1) for d in block_dofs])
    val = np.concatenate([b.reshape(-1) for b in blocks])
    return np.bincount(idx, weights=val, minlength=n_full)
