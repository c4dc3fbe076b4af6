"""Exact slice of a 4-polytope (convex or not) by the hyperplane H: w = c0.

`slice_polytope` rotates the polytope, classifies its pieces against H with one tolerance
(`TOLERANCE` times the circumradius) and returns a `Slice`: P ∩ H whole (a vertex on H and an edge
in H are kept even where no polygon uses them), one convex polygon per crossing cell, oriented
outward, and the volume by the divergence theorem.  Only the cells are assumed convex; a polytope
with star faces, non-convex cells or no inside goes to `rot4d_widget.geometry.slicing.star`.  A
1-D array of levels is cut at once (`rot4d_widget.geometry.slicing.many_levels`), each level's
`Slice` equal to the single slice there.  Per step nothing loops over edges, faces or cells in
Python: the incidence tables are built once per polytope.  The case table, the scaling and the
non-manifold cases are in docs/design.md, "Slicing polytopes".
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ...core import tolerances as tol_
from ...core.rotation import as_rotation_matrix
from ...core.validate import is_real
from ..catalogue import polytope as _get_polytope
from .many_levels import slice_many
from .single_level import slice_level as _slice_level
from .star import slice_star
from .tables import tables as _tables

__all__ = ["slice_polytope", "TOLERANCE"]

#: The one tolerance for "on H", relative to the polytope's circumradius
#: (`rot4d_widget.core.tolerances.ON_HYPERPLANE`).
TOLERANCE = tol_.ON_HYPERPLANE

def slice_polytope(polytope, matrix, c0=0.0):
    """Cut ``polytope`` (a `Polytope` or a name), rotated by ``matrix``, with w = ``c0``.

    ``matrix`` is a (4, 4) rotation (validated: orthogonal, det +1); the rotated
    vertices are ``vertices @ matrix.T``.

    ``c0`` a real number (or a 0-d array): returns a `Slice`.  ``c0`` a 1-D
    array-like of levels (a stack of parallel hyperplanes): returns a tuple of
    `Slice`, one per level in the order given, each equal to the single slice
    at its level.  The levels are cut in one batched pass (the vertices rotated
    once, every vertex classified against every level at once, the crossing
    edges, face chords and cell polygons of all levels found and ordered by the
    same vectorised steps as a single slice, then split by level); a level
    within `TOLERANCE` of a vertex height, or one that does not cross the
    polytope, takes the single-slice path (its explicit on-H case table).
    """
    p = _get_polytope(polytope)
    m = as_rotation_matrix(matrix)
    levels, many = _as_levels(c0)
    t = _tables(p)
    x = t.vertices @ m.T  # the unit vertices: c0 and the results are scaled by t.unit (exact, a power of 2)
    if t.unit != 1.0:
        with np.errstate(over="ignore"):  # a level beyond float64 in the unit scale is inf: H misses
            levels = levels / t.unit
    if p.star is not None:  # star faces or non-convex cells: the general slicer, level by level
        out = tuple(slice_star(p, t, x, m, float(c)) for c in levels)
        if not p.volume_defined:  # a hemi or non-orientable polychoron: no inside, no volume
            out = tuple(dataclasses.replace(s, volume=None) for s in out)
        return out if many else out[0]
    if not many:
        return _slice_level(t, x, m, float(levels[0]), t.radius)
    return slice_many(t, x, m, levels, t.radius)


_LEVELS = "a real number or a 1-D array of levels"


def _as_levels(c0):
    """``c0`` -> (levels (L,) float64, many): a real number or 0-d array, or a 1-D array-like."""
    if isinstance(c0, (bool, np.bool_, str, bytes)):
        raise TypeError(f"Expected `c0` to be {_LEVELS}, got {type(c0).__name__}")
    if is_real(c0):
        arr = np.array([float(c0)])
        many = False
    else:
        try:
            arr = np.asarray(c0)
        except (TypeError, ValueError):
            raise TypeError(f"Expected `c0` to be {_LEVELS}, got {type(c0).__name__}") from None
        if arr.dtype.kind not in "iuf" or arr.ndim > 1:
            what = f"shape {arr.shape}" if arr.ndim > 1 else f"dtype {arr.dtype}"
            raise (ValueError if arr.ndim > 1 else TypeError)(
                f"Expected `c0` to be {_LEVELS}, got {what}")
        many = arr.ndim == 1
        arr = np.array(arr, dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)][0]
        raise ValueError(f"Expected `c0` to be finite, got {bad}")
    return arr, many
