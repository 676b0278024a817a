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
    slot: np.ndarray  # CSR slot of each kept local entry
    keep: np.ndarray  # bool over all local entries (families concatenated, row-major)
    weight: np.ndarray  # sign product of each kept entry
    indices: np.ndarray
    indptr: np.ndarray
    n: int

    def assemble(self, blocks: list[np.ndarray]) -> sp.csr_matrix:
        """Reduced matrix Tᵀ K T from local blocks, one array (B, n, n) per family."""
        values = np.concatenate([b.reshape(-1) for b in blocks])[self.keep]
        data = np.bincount(self.slot, weights=self.weight * values, minlength=self.indices.size)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))

    @cached_property
    def family_slots(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per block family, ``(slots, signs)`` of shape ``(B, n, n)``, for in-place assembly.

        Each local entry's CSR slot (−1 where it is eliminated) and sign product
        (:func:`beam_element.kernels.layer_assemble`). Computed on first use, then kept.
        """
        pos = np.cumsum(self.keep) - 1  # index into slot/weight of each kept entry
        out, offset = [], 0
        for d in self.block_dofs:
            B, n = d.shape
            k = self.keep[offset:offset + B * n * n]
            idx = pos[offset:offset + B * n * n]
            slots = np.where(k, self.slot[idx], -1).astype(np.int32).reshape(B, n, n)
            signs = np.where(k, self.weight[idx], 0).astype(np.int8).reshape(B, n, n)
            out.append((slots, signs))
            offset += B * n * n
        return tuple(out)


def reduced_pattern(block_dofs: list[np.ndarray], dof_map: DofMap) -> ReducedPattern:
    """Precompute the scatter of local blocks (full DOF index arrays ``(B, n)``) into Tᵀ K T."""
    rows = np.concatenate([np.repeat(d[:, :, None], d.shape[1], axis=2).reshape(-1)
                           for d in block_dofs])
    cols = np.concatenate([np.repeat(d[:, None, :], d.shape[1], axis=1).reshape(-1)
                           for d in block_dofs])
    r, c = dof_map.free[rows], dof_map.free[cols]
    keep = (r >= 0) & (c >= 0)
    n = dof_map.n_free
    r, c = r[keep], c[keep]
    locate = _slot_search()
    if locate is None:  # no numba: sort the keys
        keys = r.astype(np.int64) * n + c
        unique, slot = np.unique(keys, return_inverse=True)
        row_of = unique // n
        indptr = np.searchsorted(row_of, np.arange(n + 1)).astype(np.int32)
        indices = (unique % n).astype(np.int32)
    else:  # the same canonical CSR pattern from scipy's COO -> CSR, then one search per entry
        P = sp.csr_matrix((np.ones(r.size), (r, c)), shape=(n, n))
        P.sum_duplicates()
        indptr, indices = P.indptr.astype(np.int32), P.indices.astype(np.int32)
        slot = locate(indptr, indices, r.astype(np.int64), c.astype(np.int64))
    return ReducedPattern(
        block_dofs=tuple(block_dofs), slot=slot, keep=keep,
        weight=dof_map.sign[rows[keep]] * dof_map.sign[cols[keep]],
        indices=indices, indptr=indptr, n=n,
    )


_SLOT_SEARCH: list = []


def _slot_search():
    """Compiled slot search (:func:`beam_element.kernels.csr_slots`), or None without numba."""
    if not _SLOT_SEARCH:
        try:
            from beam_element.kernels import csr_slots
        except ImportError:
            csr_slots = None
        _SLOT_SEARCH.append(csr_slots)
    return _SLOT_SEARCH[0]


def scatter_vector(
    n_full: int, block_dofs: list[np.ndarray], blocks: list[np.ndarray]
) -> np.ndarray:
    """Full vector Σ of local vectors, one (B, n) array per family."""
    idx = np.concatenate([d.reshape(-1) for d in block_dofs])
    val = np.concatenate([b.reshape(-1) for b in blocks])
    return np.bincount(idx, weights=val, minlength=n_full)
