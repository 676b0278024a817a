"""Sparse assembly straight into the eliminated (free) DOFs, on a precomputed pattern.

Each local contribution (element layer or contact pair) is a dense block on a list of full DOFs.
With u_full = T u_free and T holding at most one ±1 per row (:mod:`beam_element.constraints`),
the reduced tangent Tᵀ K T is a signed scatter of the local entries. The scatter map — which CSR
slot each local entry lands in and with which sign — is computed once; assembling is then one
``np.bincount``. Node-wise numbering keeps the reduced matrix banded.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from beam_element.constraints import DofMap


@dataclass(frozen=True)
class ReducedPattern:
    """Where the entries of a list of dense local blocks go in the reduced CSR matrix."""

    block_dofs: tuple[np.ndarray, ...]  # per block family: (B, n) full DOF indices
    indices: np.ndarray
    indptr: np.ndarray
    n: int
    # per family: each local entry's CSR slot (−1 where eliminated) and sign product, (B, n, n)
    family_slots: tuple[tuple[np.ndarray, np.ndarray], ...]

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


def _signs(block_dofs: list[np.ndarray], dof_map: DofMap) -> list[np.ndarray]:
    """Per family, the sign product of each local entry (B, n, n), int8 (0 where eliminated)."""
    out = []
    for d in block_dofs:
        s = np.where(dof_map.free[d] >= 0, dof_map.sign[d], 0).astype(np.int8)
        out.append(s[:, :, None] * s[:, None, :])
    return out


def reduced_pattern(block_dofs: list[np.ndarray], dof_map: DofMap) -> ReducedPattern:
    """Precompute the scatter of local blocks (full DOF index arrays ``(B, n)``) into Tᵀ K T.

    Compiled (:func:`beam_element.kernels.block_pattern`, ``block_slots``: one pass over the
    blocks of each row) where numba is, else by sorting every local entry's key.
    """
    kernels = _pattern_kernels()
    n = dof_map.n_free
    signs = _signs(block_dofs, dof_map)
    if kernels is None:
        return _reduced_pattern_sorted(block_dofs, dof_map, signs)
    block_pattern, block_slots = kernels
    free = [np.ascontiguousarray(dof_map.free[d], dtype=np.int64) for d in block_dofs]
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
    indptr, indices = indptr.astype(np.int32), indices.astype(np.int32)
    slots = []
    for f in free:
        out = np.empty((f.shape[0], f.shape[1], f.shape[1]), dtype=np.int64)
        block_slots(f, indptr, indices, n, out)
        slots.append(out.astype(np.int32))
    return ReducedPattern(block_dofs=tuple(block_dofs), indices=indices, indptr=indptr, n=n,
                          family_slots=tuple(zip(slots, signs, strict=True)))


def _reduced_pattern_sorted(
    block_dofs: list[np.ndarray], dof_map: DofMap, signs: list[np.ndarray]
) -> ReducedPattern:
    """:func:`reduced_pattern` without numba: unique keys of every kept local entry."""
    rows = np.concatenate([np.repeat(d[:, :, None], d.shape[1], axis=2).reshape(-1)
                           for d in block_dofs])
    cols = np.concatenate([np.repeat(d[:, None, :], d.shape[1], axis=1).reshape(-1)
                           for d in block_dofs])
    r, c = dof_map.free[rows], dof_map.free[cols]
    keep = (r >= 0) & (c >= 0)
    n = dof_map.n_free
    keys = r[keep].astype(np.int64) * n + c[keep]
    unique, slot = np.unique(keys, return_inverse=True)
    row_of = unique // n
    indptr = np.searchsorted(row_of, np.arange(n + 1)).astype(np.int32)
    indices = (unique % n).astype(np.int32)
    every = np.full(keep.size, -1, dtype=np.int64)
    every[keep] = slot
    out, offset = [], 0
    for d, sg in zip(block_dofs, signs, strict=True):
        B, m = d.shape
        out.append((every[offset:offset + B * m * m].astype(np.int32).reshape(B, m, m), sg))
        offset += B * m * m
    return ReducedPattern(block_dofs=tuple(block_dofs), indices=indices, indptr=indptr, n=n,
                          family_slots=tuple(out))


_PATTERN_KERNELS: list = []


def _pattern_kernels():
    """Compiled pattern builders (:mod:`beam_element.kernels`), or None without numba."""
    if not _PATTERN_KERNELS:
        try:
            from beam_element.kernels import block_pattern, block_slots
        except ImportError:
            _PATTERN_KERNELS.append(None)
        else:
            _PATTERN_KERNELS.append((block_pattern, block_slots))
    return _PATTERN_KERNELS[0]


def scatter_vector(
    n_full: int, block_dofs: list[np.ndarray], blocks: list[np.ndarray]
) -> np.ndarray:
    """Full vector Σ of local vectors, one (B, n) array per family."""
    idx = np.concatenate([d.reshape(-1) for d in block_dofs])
    val = np.concatenate([b.reshape(-1) for b in blocks])
    return np.bincount(idx, weights=val, minlength=n_full)
