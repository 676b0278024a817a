"""Spare arrays reused while nothing else holds them (no page faults on large arrays).

A freshly allocated large array (above glibc's mmap threshold) is new pages: one page fault per
4 KiB on first read and another on first write — at 960 elements, core level 3, 22 000 faults
(≈ 30 ms) for a tangent's 46 MB of CSR values. The beam model's value arrays and the envelope
factorisation's storage therefore come from a short list of spares (:func:`free_array`); a spare
is handed out again only when its reference count says that nothing outside the list holds it —
no matrix, no view (a view holds its base), no live factorisation — so no array in use is ever
overwritten.
"""

from __future__ import annotations

import sys

import numpy as np

__all__ = ["free_array"]


def free_array(spares: list[np.ndarray], size: int, keep: int) -> np.ndarray:
    """A float array of ``size`` from ``spares`` that nothing else holds, else a new one.

    The content is arbitrary (the caller fills it). A new array is put first in ``spares``,
    which keeps at most ``keep``.
    """
    for i in range(len(spares)):  # by index: an iterator would hold a reference
        array = spares[i]
        # referenced by the list, this name and getrefcount's argument only: free
        if array.size == size and sys.getrefcount(array) <= 3:
            return array
    array = np.empty(size)
    spares.insert(0, array)
    del spares[keep:]
    return array
