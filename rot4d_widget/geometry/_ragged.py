"""Ragged tables: rows of different lengths stored back to back, with start offsets.

A table of n rows is ``(ptr, flat)``: ``ptr`` (n + 1,) intp offsets, row i is
``flat[ptr[i]:ptr[i + 1]]``.  `Polytope` keeps its faces and cells this way, and the
mesh checks and the slicer work on them without a Python loop over rows.

>>> ptr = row_offsets(np.array([2, 3])); ptr.tolist(), row_owners(ptr).tolist()
([0, 2, 5], [0, 0, 1, 1, 1])
"""

from __future__ import annotations

import numpy as np

__all__: list = []


def row_offsets(sizes: np.ndarray) -> np.ndarray:
    """(n,) sizes -> (n + 1,) start offsets."""
    ptr = np.zeros(len(sizes) + 1, dtype=np.intp)
    np.cumsum(sizes, out=ptr[1:])
    return ptr


def row_owners(ptr: np.ndarray) -> np.ndarray:
    """For offsets ``ptr`` (n + 1,), the owner (0..n-1) of every entry."""
    return np.repeat(np.arange(len(ptr) - 1, dtype=np.intp), np.diff(ptr))


def gather_rows(ptr: np.ndarray, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Entries of the rows ``which`` of a ragged table with offsets ``ptr``, back to back:
    (entry indices, position in ``which`` of each)."""
    sizes = ptr[which + 1] - ptr[which]
    row = np.repeat(np.arange(len(which), dtype=np.intp), sizes)
    first = row_offsets(sizes)
    return ptr[which][row] + np.arange(first[-1], dtype=np.intp) - first[row], row
