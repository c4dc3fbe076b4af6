"""What the single and the batched slicer share: the per-polytope tables, the `Slice` result,
and the steps both take alike (fan triangulation, in-plane axes, scaling back).

`tables(p)` builds (once per polytope, kept while the polytope lives) the incidence arrays of
`Polytope.incidence` in the shapes the slicers index with, in the scale of the polytope's
`Polytope.unit_vertices`.  Everything here is read-only.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from ...core import tolerances as tol_
from ...core._arrays import sealed as _sealed
from .._ragged import row_owners
from ..mesh import Polytope

__all__ = ["Slice"]


class SliceTables:
    """Incidence arrays for vectorised slicing, built once per polytope."""

    def __init__(self, p: Polytope):
        V, C = len(p.vertices), len(p.cells)
        F = len(p.faces)
        self.V, self.F, self.C = V, F, C
        self.ea = np.ascontiguousarray(p.edges[:, 0])
        self.eb = np.ascontiguousarray(p.edges[:, 1])
        # the polytope's flat incidence tables (`Polytope.incidence`): each face's corners and
        # sides in cycle order, each cell's vertices and edges ascending
        inc = p.incidence
        self.fv_face = row_owners(inc.face_ptr)
        self.fv_vert = inc.face_vidx
        self.fe_face = self.fv_face
        self.fe_edge = inc.face_eidx
        self.f_starts = inc.face_ptr[:-1]
        self.cv_cell = row_owners(inc.cell_vptr)
        self.cv_vert = inc.cell_vidx
        self.ce_cell = row_owners(inc.cell_eptr)
        self.ce_edge = inc.cell_eidx
        self.c_starts = inc.cell_vptr[:-1]
        # first three vertices of each face cycle: two non-parallel edge vectors
        self.face_abc = inc.face_vidx[inc.face_ptr[:-1, None] + np.arange(3)]
        self.face_cells = p.face_cells
        self.cell_normals = np.ascontiguousarray(p.cell_normals)
        # each cell's vertex mean (a point inside the convex cell), for 2-faces lying in H
        nv = np.diff(np.append(self.c_starts, len(self.cv_vert)))
        # everything here is in the scale of the polytope's unit vertices (its vertices divided by
        # the power of two `unit`, largest |coordinate| in [1, 2)): a slice is cut there and its
        # vertices and volume are scaled back (`scaled`), so any scale in COORDINATE_RANGE slices alike
        self.unit = float(p.unit)
        self.vertices = p.unit_vertices
        self.radius = p.circumradius / self.unit
        self.cell_centres = np.stack([np.bincount(self.cv_cell, weights=self.vertices[self.cv_vert, k], minlength=C)
                                      for k in range(4)], axis=1) / nv[:, None]
        self.tol = tol_.ON_HYPERPLANE * self.radius
        # fixed-width rows for many levels at once: each face's / cell's edges, padded with the
        # index E (a column that never crosses)
        self.fe_pad = _padded(self.fe_face, self.fe_edge, F, len(self.ea))
        self.ce_pad = _padded(self.ce_cell, self.ce_edge, C, len(self.ea))
        self.empty3 = np.zeros((0, 3))
        self.empty_i2 = np.zeros((0, 2), dtype=np.intp)
        self.empty_i3 = np.zeros((0, 3), dtype=np.intp)
        self.empty_i = np.zeros(0, dtype=np.intp)
        self.offsets0 = np.zeros(1, dtype=np.intp)
        # shared by every slice of this polytope (the empty ones go into Slices): sealed
        for name, a in vars(self).items():
            if isinstance(a, np.ndarray) and a.flags.writeable:
                setattr(self, name, _sealed(a))


def _padded(owner: np.ndarray, item: np.ndarray, n: int, pad: int) -> np.ndarray:
    """Rows ``owner -> items`` (owner sorted) as an (n, widest) table padded with ``pad``."""
    counts = np.bincount(owner, minlength=n)
    table = np.full((n, int(counts.max()) if n else 0), pad, dtype=np.intp)
    starts = np.zeros(n, dtype=np.intp)
    np.cumsum(counts[:-1], out=starts[1:])
    table[owner, np.arange(len(owner)) - starts[owner]] = item
    return table


_TABLES: "weakref.WeakKeyDictionary[Polytope, SliceTables]" = weakref.WeakKeyDictionary()


def tables(p: Polytope) -> SliceTables:
    t = _TABLES.get(p)
    if t is None:
        t = _TABLES[p] = SliceTables(p)
    return t


@dataclass(frozen=True, eq=False)
class Slice:
    """The solid P ∩ H described by its boundary (all arrays computed eagerly).

    vertices : (n, 3) float64 -- corners (x, y, z) of the slice
    edges : (m, 2) intp -- pairs of indices into `vertices`
    polygon_indices : (N,) intp -- all polygons' vertex cycles, concatenated
    polygon_offsets : (P + 1,) intp -- polygon i is
        ``polygon_indices[polygon_offsets[i]:polygon_offsets[i + 1]]``, wound
        counter-clockwise seen from outside
    cell_ids : (P,) intp -- the 4-D cell each polygon comes from
    triangles : (k, 3) intp -- the polygons fanned into a closed surface, CCW
        seen from outside
    triangle_cells : (k,) intp -- the 4-D cell of each triangle
    volume : float or None -- the 3-volume (0 unless the slice is solid; inf, or 0, when it is
        beyond float64's range: coordinates above ~5e102 or below ~2e-103); None for every slice
        of a polytope with no inside (`Polytope.volume_defined` False: hemi or non-orientable)
    dim : int -- 3 solid, 2/1/0 when H only touches a face/edge/vertex, -1 empty
    n_fill : int -- the last ``n_fill`` vertices are not points of the slice but extra corners of
        the triangles that fill a non-convex or self-intersecting section even-odd (0 unless
        the polytope has star faces or non-convex cells: `rot4d_widget.geometry.slicing.star`)

    Every array is read-only (a missed slice shares its empty arrays with
    every other missed slice of the polytope); copy one to edit it.
    """

    vertices: np.ndarray
    edges: np.ndarray
    polygon_indices: np.ndarray
    polygon_offsets: np.ndarray
    cell_ids: np.ndarray
    triangles: np.ndarray
    triangle_cells: np.ndarray
    volume: float | None
    dim: int
    n_fill: int = 0

    def __post_init__(self):
        for name in ("vertices", "edges", "polygon_indices", "polygon_offsets", "cell_ids", "triangles",
                     "triangle_cells"):
            object.__setattr__(self, name, _sealed(getattr(self, name)))  # as is if sealed already

    @property
    def polygons(self) -> list:
        """The polygons as a list of (read-only) vertex-index arrays (for iteration; not on the hot path)."""
        return np.split(self.polygon_indices, self.polygon_offsets[1:-1]) if len(self.cell_ids) else []

    @property
    def polygon_sizes(self) -> np.ndarray:
        """(P,) intp, read-only: the number of corners of each polygon."""
        return _sealed(np.diff(self.polygon_offsets))

    def face_census(self) -> dict:
        """``{number of sides: number of polygons}``, e.g. ``{3: 8, 4: 6}``."""
        sizes, counts = np.unique(self.polygon_sizes, return_counts=True)
        return {int(s): int(c) for s, c in zip(sizes, counts)}

    def __repr__(self) -> str:
        return (
            f"Slice(dim={self.dim}, V={len(self.vertices)}, E={len(self.edges)}, "
            f"F={len(self.cell_ids)}, census={self.face_census()}, "
            f"volume={'none' if self.volume is None else format(self.volume, '.6g')})"
        )


class Inconsistent(Exception):
    """A face chord without exactly two ends: classification hit a near-degenerate case."""


def scaled(t: SliceTables, vertices: np.ndarray) -> np.ndarray:
    """Slice vertices from the unit vertices' scale back to the polytope's (exact: a power of 2)."""
    return vertices if t.unit == 1.0 else vertices * t.unit


def scaled_volume(t: SliceTables, volume):
    """A volume from the unit vertices' scale back to the polytope's: times unit**3, one factor at
    a time (a volume beyond float64's range becomes inf, or 0 below it; never nan)."""
    if t.unit == 1.0:
        return volume
    u = t.unit
    with np.errstate(over="ignore", under="ignore"):
        return volume * u * u * u


def fan(flat, prank, offsets, counts):
    """Fan triangulation of polygons stored back to back: corners 1..k-2 of each open a triangle.

    ``flat`` the corners in order, ``prank`` the polygon of each, ``offsets`` where each
    polygon starts, ``counts`` its corners.  Returns ((t, 3) corner ids, (t,) polygon of each).
    """
    start = offsets[prank]
    pos_in = np.arange(len(flat)) - start
    j = ((pos_in >= 1) & (pos_in <= counts[prank] - 2)).nonzero()[0]
    triangles = np.empty((len(j), 3), dtype=np.intp)
    triangles[:, 0] = flat[start[j]]
    triangles[:, 1] = flat[j]
    triangles[:, 2] = flat[j + 1]
    return triangles, prank[j]

def inplane_axes(n):
    """(k, 3) plane normals -> (k, 6): two in-plane axes u (columns 0-2) and v (3-5) per plane.

    u is n crossed with the coordinate axis least aligned with n, v = n x u; neither is unit
    (ordering directions by angle needs only a positive-determinant frame).  One formula for
    the single and the batched slicer, so both round a corner on the angle's branch cut alike.
    """
    nx, ny, nz = n[:, 0], n[:, 1], n[:, 2]
    use_x = nx * nx < 0.5 * (ny * ny + nz * nz + nx * nx)
    uv = np.empty((len(n), 6))
    uv[:, 0] = np.where(use_x, 0.0, -nz)
    uv[:, 1] = np.where(use_x, nz, 0.0)
    uv[:, 2] = np.where(use_x, -ny, nx)
    uv[:, 3] = np.where(use_x, -(ny * ny + nz * nz), nx * ny)
    uv[:, 4] = np.where(use_x, nx * ny, -(nx * nx + nz * nz))
    uv[:, 5] = np.where(use_x, nx * nz, ny * nz)
    return uv
