"""Exact slice of a 4-polytope (convex or not) by the hyperplane H: w = c0.

The polytope is rotated (``vertices @ matrix.T``) and cut by H.  Its pieces are
classified against H with ONE tolerance, `TOLERANCE` times the polytope's
circumradius: a vertex is *on* H when ``|w - c0| <= tol``, otherwise above or
below.  An edge, 2-face or cell **crosses** H when it has vertices strictly on
both sides, and **lies in** H when all its vertices are on H.

The explicit case table (what becomes what in the solid ``S = P ∩ H``):

====================  =========================  ==============================
polytope piece        crosses H                  lies in H
====================  =========================  ==============================
vertex                --                         a vertex of S
edge                  a vertex of S (lerp)       an edge of S
2-face                an edge of S (its chord)   a polygon of S if it bounds S
cell                  a polygon of S             a 3-D part of S (no polygon)
====================  =========================  ==============================

Nothing here assumes the polytope convex; only its cells are (each crossing
cell gives ONE convex polygon, whose corners are ordered by angle about their
own mean, and oriented by the cell's outward normal -- from the boundary's
orientation, see `Polytope`).  Where convexity was once relied on, and what
replaced it:

* A 2-face lying in H was always a polygon, oriented away from the slice's
  vertex centroid.  Now it is a polygon only if it bounds S: seen in the plane
  orthogonal to the face, the polytope fills the angle between its two cells on
  their inner side; the face bounds S when exactly one of the two directions
  along H from it is filled (or runs along a cell lying in H), and faces the
  other way (`_faces_in_h`).  A convex polytope cut through its interior always
  has one cell above and one below (no change); a non-convex one may have the
  face inside S (at a reflex ridge, or between coplanar cells lying in H) or
  only touching it.
* "Vertices on both sides" meant "solid".  A polytope in separate pieces can
  have pieces above and below and none crossing: S is then empty (or only
  touches), decided by whether any polygon comes out.
* In a solid slice every vertex on H and every edge in H was on S's boundary.
  It is still a vertex (an edge) of the slice, as the table says, but may be
  on no polygon: where P touches H away from the solid part (a vertex whose
  cells all lie on one side, a face of P lying in H that bounds nothing), or
  inside it.  The slice is P ∩ H whole, its solid part given by the polygons;
  for a convex polytope every one is on a polygon.  (Issue 11 dropped those
  no polygon used; issue 33 keeps them: a user cutting at a vertex's height
  sees that vertex.)
* H touching P: the dimension is 2 if a face lies in H, else 1 if an edge
  does, else 0 (a convex polytope touches in one face, edge or vertex).

A polytope with no inside (`Polytope.volume_defined` False: a hemi or non-orientable
polychoron) is cut like a star one (`rot4d_widget.geometry.slicing.star`: the edges' crossings, even-odd
segments, each cell's section filled even-odd), and every slice's ``volume`` is None.

The volume (divergence theorem over the outward triangles, about any point)
and the per-cell polygons never relied on convexity: S may have several
pieces and holes and tunnels.  Where H passes through a reflex vertex of P, or
holds a reflex edge, S may not be a manifold there: two solids touching at that
vertex, or along that edge.  The slice keeps the vertex (the edge) ONCE, shared
by both: two fans of polygons meet at the vertex, four polygons at the edge
(two of each solid, wound against each other).  The surface is still closed
(every directed edge as often as its reverse) and outward, and the volume
exact; V - E + F counts the shared part once (3 for two balls touching).

S is solid (3-D) when some polygon comes out: some cell crosses H, or some
2-face lying in H bounds a 3-D part (a cell lying in H, as the 8-cell at
c0 = ±1).  Otherwise H only touches P (in vertices, edges or 2-faces: the
slice keeps those vertices and edges, with no polygons and volume 0) or
misses it (empty arrays).

For a 2-face lying in H, ``cell_ids`` names a cell containing it that lies in
H if there is one, otherwise the lower-numbered of its two cells.

Everything per step is vectorised over precomputed incidence tables (built
once per polytope): no Python loop over edges, faces or cells.

Scale: the slicer cuts the polytope's *unit vertices* (its vertices divided by
a power of two, so the largest |coordinate| is in [1, 2); exact) at
``c0 / unit`` and multiplies the slice's vertices by ``unit`` (exact) and its
volume by ``unit**3``: a polytope scaled by ``s`` (any scale in
`rot4d_widget.geometry.mesh.COORDINATE_RANGE`, 1e-150 to 1e150) has the slices
of the unscaled one at ``c0 / s``, scaled by ``s``.  Only the volume can leave
float64's range (coordinates beyond about 5e102 give ``inf``, below about
2e-103 it underflows towards 0; ``dim`` still says the slice is solid).

Many levels at once (a stack of parallel slices): ``slice_polytope(p, m, c0s)``
with a 1-D array of levels rotates once, classifies every vertex against every
level in one (L, V) comparison, finds the crossing faces and cells of all
levels from their w-ranges, and runs the single slice's steps on arrays that
carry a level index; each level's `Slice` is a read-only view of the shared
arrays, equal to the single slice at that level.  Levels within the tolerance
of a vertex height (the on-H cases), and levels with vertices on both sides
but no crossing edge (a polytope in pieces), take the single-slice path.
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
