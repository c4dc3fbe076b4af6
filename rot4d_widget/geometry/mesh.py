"""The `Polytope` class: a 4-polytope's vertices and combinatorics, convex from points or any
closed mesh given whole.

`Polytope(vertices)` finds everything else once: the cells are the facets of
scipy's 4-D convex hull (coplanar simplices merged), the 2-faces are the
intersections of pairs of cells that share three or more vertices, each
ordered as a cycle, and the edges are consecutive vertices of those cycles.

`Polytope(vertices, faces, cells)` takes the 2-faces (vertex cycles) and the
cells (lists of face indices) as given and checks them (`rot4d_widget.geometry.meshcheck`):
such a polytope need not be convex.

Its flat incidence tables (what the slicer works on) are public and read-only:
`Polytope.incidence`, with `Polytope.unit` and `Polytope.unit_vertices` (the vertices divided
by a power of two, the scale every check and slice is computed in).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from ..core import tolerances as tol_
from ..core._arrays import sealed as _sealed
from ._ragged import gather_rows, row_offsets, row_owners
from .meshcheck import MAX_TOLERANCE, MeshError, duplicate_in_rows, index_lists, mesh_geometry
from .offfile import read_off, write_off

__all__ = ["Polytope", "Incidence", "MeshError", "MESH_TOLERANCE", "MAX_TOLERANCE", "COORDINATE_RANGE",
           "check_scale", "order_cycle"]

#: Relative tolerance of a mesh's geometric checks: `rot4d_widget.core.tolerances.MESH`.
MESH_TOLERANCE = tol_.MESH

#: The scale of an object (a polytope's largest absolute coordinate, a field box's half widths and
#: the ends of its extent) must lie in this range: (smallest, largest).  Within it the square of
#: every coordinate, distance or dot product is a normal float64 (1e-300 to 1e300), so any code
#: that measures lengths stays exact to rounding; outside it a ValueError names the range.  Each
#: object is normalised by a power of two (exact) before the hull, the checks and the slicer, and
#: every tolerance is relative to its scale, so the results are the unit object's, scaled.
COORDINATE_RANGE = (1e-150, 1e150)


def check_scale(scale: float, what: str) -> None:
    """ValueError unless ``COORDINATE_RANGE[0] <= scale <= COORDINATE_RANGE[1]`` (``what`` names it), the
    bounds taken with a relative slack of 1e-9: an object scaled by 1e150 whose largest coordinate
    rounds to 1.0000000000000002e150 is in (its squares stay far from float64's limits)."""
    lo, hi = COORDINATE_RANGE
    if not lo * (1 - 1e-9) <= scale <= hi * (1 + 1e-9):
        shown = f"{scale:.3g}"  # with every digit where three would look like a bound (1.0000000000000002e+150)
        shown = repr(float(scale)) if float(shown) in (lo, hi) else shown
        raise ValueError(f"{what} is {shown}; expected {lo:g} to {hi:g} "
                         f"(rot4d_widget.geometry.mesh.COORDINATE_RANGE: "
                         f"squares of coordinates must stay normal float64 numbers; rescale the data, e.g. to "
                         f"other units)")



def _check_tolerance(tolerance) -> float:
    """The mesh checks' relative tolerance: None gives `MESH_TOLERANCE`; else a finite number in
    (0, `MAX_TOLERANCE`], as a float (TypeError / ValueError naming what is allowed)."""
    if tolerance is None:
        return float(MESH_TOLERANCE)
    allowed = f"None (the default {MESH_TOLERANCE:g}) or a number in (0, {MAX_TOLERANCE:g}]"
    if isinstance(tolerance, (bool, np.bool_)) or not isinstance(tolerance, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `tolerance` to be {allowed}, relative to the vertices' extent; got {tolerance!r}")
    t = float(tolerance)
    if not (np.isfinite(t) and 0.0 < t <= MAX_TOLERANCE):
        raise ValueError(f"Expected `tolerance` to be {allowed}, relative to the vertices' extent; got {tolerance!r}")
    return t


def _all_inside(v, normals, offsets, tol, chunk: int = 256) -> bool:
    """True when every point of ``v`` (V, 4) lies on the inner side (within ``tol``) of every
    hyperplane ``normals[c] . x = offsets[c]``: the cells' hyperplanes support the polytope."""
    for lo in range(0, len(normals), chunk):
        if np.any(v @ normals[lo:lo + chunk].T > offsets[lo:lo + chunk] + tol):
            return False
    return True


def power_of_two_unit(amax: float) -> float:
    """The power of two 2**k with ``1 <= amax / 2**k < 2`` (dividing by it is exact)."""
    return math.ldexp(1.0, math.frexp(amax)[1] - 1)


def order_cycle(points: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """The vertices ``idx`` of a planar convex polygon (points in any dimension) ordered as a cycle (intp)."""
    p = points[idx]
    c = p.mean(axis=0)
    _, _, vt = np.linalg.svd(p - c)
    xy = (p - c) @ vt[:2].T
    return idx[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))].astype(np.intp)



@dataclass(frozen=True)
class Incidence:
    """A polytope's flat incidence tables: ragged tables (offsets ``*_ptr`` / ``cell_vptr`` /
    ``cell_eptr`` of length n + 1, entries back to back), every array read-only intp.

    face_ptr, face_vidx : each face's vertex cycle
    face_eidx : the edge of each side of each face (corner k to k + 1), parallel to ``face_vidx``
    cell_ptr, cell_fidx : each cell's faces
    cell_vptr, cell_vidx : each cell's vertices, ascending
    cell_eptr, cell_eidx : each cell's edges, ascending
    cell_ecount : for each (cell, edge) entry, the number of the cell's faces that have the edge
    """

    face_ptr: np.ndarray
    face_vidx: np.ndarray
    face_eidx: np.ndarray
    cell_ptr: np.ndarray
    cell_fidx: np.ndarray
    cell_vptr: np.ndarray
    cell_vidx: np.ndarray
    cell_eptr: np.ndarray
    cell_eidx: np.ndarray
    cell_ecount: np.ndarray


class Polytope:
    """A 4-polytope: vertices, edges, 2-faces and cells.

    ``Polytope(vertices)`` builds a convex polytope from its points (the cells
    are the facets of scipy's 4-D convex hull).  ``Polytope(vertices, faces,
    cells)`` takes the combinatorics as given, so the polytope need not be
    convex:

    vertices : (V, 4) array of real numbers
    faces : F vertex cycles (sequences of vertex indices, in order around the face)
    cells : C sequences of face indices, the faces bounding each cell

    and checks it (ValueError / TypeError naming the first offence; the geometric
    checks use ``tolerance`` -- default `MESH_TOLERANCE` -- times the vertices' largest extent; a
    looser one, up to 1e-2, takes coordinates written with few digits, and a planarity error says
    which would do):

    * every face has >= 3 distinct vertices, is planar, its corners not all collinear, and its
      sides turn through some net angle in the order given (convex, or a star such as {5/2},
      {8/3}; a figure eight is refused);
    * every face is in exactly two cells (the boundary is closed), every vertex in a face;
    * every cell has >= 4 distinct faces, lies in a hyperplane, spans 3-D, is closed
      (each of its edges in exactly two of its faces); convex or not (a star polyhedron, a
      hemi-polyhedron too), but a convex cell strictly so (only a face's own corners on its plane);
    * where the boundary is orientable and no cell is a hemi-polyhedron, the outward normals
      come from that orientation, not from the origin: each boundary component is oriented so
      that it encloses positive 4-volume, and a component inside another (a cavity, found by
      casting a ray) the other way.  Otherwise (a hemi or non-orientable polychoron, issue 22) the
      polytope loads with `volume_defined` False, its normals a documented choice
      (`rot4d_widget.geometry.meshcheck.mesh_geometry`), and its slices have no volume.

    Scale: the largest absolute coordinate must lie in `COORDINATE_RANGE` (1e-150 to 1e150; else
    a ValueError naming the range).  Within it any scale works alike: the vertices are divided by
    a power of two (exactly) before qhull, the checks and the slicer, and every tolerance is
    relative, so ``Polytope(s * v)`` has the combinatorics of ``Polytope(v)``, its offsets and
    circumradius times ``s``, and its slices are those of ``Polytope(v)`` (at ``c0 / s``) times ``s``.

    Two cells sharing a face may lie in one hyperplane (a flat ridge, as where two
    cubes of glued tesseracts meet side by side): that is allowed, and the slicer
    gives their slices as two polygons.  Not checked: that the boundary does not
    intersect itself, or is a manifold at its vertices and edges (two pieces may touch
    there).  Everything is vectorised, no loop over pairs (build times of the biggest,
    the omnitruncated 120-cell: docs/performance.md).  ``validate=False`` skips the per-cell
    closedness and convexity checks (for combinatorics known to be right, e.g. from a
    Wythoff construction); the faces' geometry and the orientation are still derived
    and checked, and a non-convex cell with convex faces then gives wrong normals, or the
    boundary seems not orientable (loaded with no volume).

    Attributes
    ----------
    vertices : (V, 4) float64
    edges : (E, 2) intp, each row sorted, rows sorted
    faces : tuple of F intp arrays, each an ordered cycle of vertex indices
    cells : tuple of C tuples of face indices
    face_cells : (F, 2) intp, the two cells of each face, ascending
    circumradius : float, max distance of a vertex from the origin
    convex : bool, the polytope is convex (always from the hull; for a mesh: one
        boundary component, no reflex ridge -- each cell's neighbours across its faces on
        its inner side -- and every vertex on the inner side of every cell's hyperplane, so
        a self-intersecting star polychoron, locally convex everywhere, is not convex)
    self_intersecting : bool, found to wind round more than once: connected, closed and
        locally convex but not convex (a star polychoron), or with star faces or cells, or with no
        inside (hemi cells, not orientable: `volume_defined`); False for a convex polytope and
        where not detected (a polytope with reflex ridges is not checked for it).  A slice's
        volume is then the volume weighted by the winding number (the divergence theorem over
        its outward faces), each region counted as often as the boundary winds round it
    star : None, or `rot4d_widget.geometry.meshcheck.StarData` when some face or cell is not
        convex, or the volume is not defined (its slices then come from
        `rot4d_widget.geometry.slicing.star`: even-odd chords and fill, winding-weighted volume or
        None); such a polytope is not convex, and self-intersecting when a face is a star, a
        cell's faces wind round its centre more than once, or it has no inside
    volume_defined, why_no_volume : see the properties (False / the reason for a hemi or
        non-orientable polychoron, whose slices' volume is None)
    cell_normals : (C, 4) float64 outward unit normals; ``cell_offsets`` (C,)
        so that cell c lies in ``vertices @ cell_normals[c] == cell_offsets[c]``

    Every array is read-only and the sequences are tuples: a polytope is
    shared (``polytope(name)`` is cached, slicing tables are built from it
    once), so an edit anywhere would corrupt every later slice.
    """

    def __init__(self, vertices, faces=None, cells=None, name: str = "polytope", *, validate: bool = True,
                 tolerance: float | None = None):
        if isinstance(faces, str) and cells is None:
            raise TypeError("Expected `faces` to be a sequence of vertex cycles; pass the name as name=...")
        try:
            v = np.array(vertices, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError("Expected `vertices` to be a (V, 4) array of real numbers") from None
        if v.ndim != 2 or v.shape[1] != 4 or v.shape[0] < 5:
            raise ValueError(f"Expected `vertices` to have shape (V, 4) with V >= 5, got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("Expected `vertices` to be finite")
        if (faces is None) != (cells is None):
            raise TypeError("Expected both `faces` and `cells`, or neither (then the convex hull of the vertices)")
        self.tolerance = _check_tolerance(tolerance)
        amax = float(np.abs(v).max())
        if amax == 0:
            raise ValueError("`vertices` are all the origin: they do not span a 4-D convex polytope" if faces is None
                             else "`vertices` are all the same point")
        check_scale(amax, "The largest absolute coordinate of `vertices`")
        self.name = str(name)
        self.vertices = _sealed(v)
        # the vertices divided by a power of two (exactly) so that the largest |coordinate| is in
        # [1, 2): the hull, the mesh checks and the slicer work on these, at any scale
        self._unit = power_of_two_unit(amax)
        vn = v / self._unit
        self._unit_vertices = _sealed(vn)
        self.circumradius = float(np.sqrt((vn * vn).sum(axis=1)).max()) * self._unit
        if faces is None:
            self._build_hull()
        else:
            self._build_mesh(faces, cells, bool(validate), self.tolerance)

    # -- construction ------------------------------------------------------
    def _build_hull(self) -> None:
        v = self._unit_vertices  # largest |coordinate| in [1, 2): qhull and the tolerances see one scale
        tol = tol_.HULL * float(np.abs(v).max())
        try:
            hull = ConvexHull(v)
        except Exception as exc:  # qhull: flat or degenerate input
            raise ValueError(f"`vertices` do not span a 4-D convex polytope: {exc}") from None
        if len(hull.vertices) != len(v):
            raise ValueError("Every vertex must be a corner of the convex hull (found interior or repeated points)")
        # cells: distinct facet hyperplanes of the hull (unit normals, offsets of order 1)
        eq = hull.equations
        key = np.round(eq, tol_.HULL_DECIMALS)
        _, first = np.unique(key, axis=0, return_index=True)
        first = np.sort(first)
        normals, offsets = eq[first, :4], -eq[first, 4]
        inc = np.abs(v @ normals.T - offsets) <= tol * 10  # (V, C) vertex-in-cell
        cell_vertices = inc.T
        # 2-faces: pairs of cells sharing >= 3 vertices
        shared = cell_vertices.astype(np.int32) @ cell_vertices.T.astype(np.int32)
        ci, cj = np.nonzero(np.triu(shared >= 3, k=1))
        face_sets = cell_vertices[ci] & cell_vertices[cj]  # (F, V)
        faces = [order_cycle(v, np.flatnonzero(row)) for row in face_sets]
        face_sizes = np.array([len(f) for f in faces], dtype=np.intp)
        # each cell's faces in ascending order: face f is in cells ci[f] < cj[f]
        both = np.concatenate([ci, cj])
        face_of = np.tile(np.arange(len(ci), dtype=np.intp), 2)
        cell_fidx = face_of[np.lexsort((face_of, both))]
        cell_sizes = np.bincount(both, minlength=len(first))
        self._set_combinatorics(row_offsets(face_sizes), np.concatenate(faces), row_offsets(cell_sizes), cell_fidx)
        self.cell_normals = _sealed(np.ascontiguousarray(normals))
        self.cell_offsets = _sealed(np.ascontiguousarray(offsets) * self._unit)
        self.face_cells = _sealed(np.stack([ci, cj], axis=1).astype(np.intp))  # (F, 2), ascending
        self.convex = True
        self.self_intersecting = False
        self._star = None

    def _set_combinatorics(self, face_ptr, face_vidx, cell_ptr, cell_fidx) -> None:
        """Edges, faces, cells and the flat incidence tables (`incidence`, also read by the slicer)."""
        V = len(self.vertices)
        C = len(cell_ptr) - 1
        nxt = np.arange(1, len(face_vidx) + 1, dtype=np.intp)
        nxt[face_ptr[1:] - 1] = face_ptr[:-1]
        a, b = face_vidx, face_vidx[nxt]
        ekey, face_eidx = np.unique(np.minimum(a, b) * V + np.maximum(a, b), return_inverse=True)
        E = len(ekey)
        self.edges = _sealed(np.stack([ekey // V, ekey % V], axis=1).astype(np.intp).reshape(-1, 2))
        # each face a read-only view of one sealed array (cannot be unlocked: its base is read-only)
        flat = _sealed(face_vidx.astype(np.intp))
        bounds = face_ptr.tolist()
        self.faces = tuple(flat[a:b] for a, b in zip(bounds[:-1], bounds[1:]))
        cf = cell_fidx.tolist()
        bounds = cell_ptr.tolist()
        self.cells = tuple(tuple(cf[a:b]) for a, b in zip(bounds[:-1], bounds[1:]))
        # (cell, face corner) entries: each cell's vertices and edges, with multiplicity
        idx, row = gather_rows(face_ptr, cell_fidx)
        cell_of = row_owners(cell_ptr)[row]
        vkey = np.unique(cell_of * V + face_vidx[idx])
        ekeys, ecount = np.unique(cell_of * E + face_eidx.reshape(-1)[idx], return_counts=True)
        self._incidence = Incidence(
            face_ptr=_sealed(face_ptr), face_vidx=_sealed(face_vidx.astype(np.intp)),
            face_eidx=_sealed(face_eidx.reshape(-1).astype(np.intp)),
            cell_ptr=_sealed(cell_ptr), cell_fidx=_sealed(cell_fidx.astype(np.intp)),
            cell_vptr=_sealed(row_offsets(np.bincount(vkey // V, minlength=C))),
            cell_vidx=_sealed((vkey % V).astype(np.intp)),
            cell_eptr=_sealed(row_offsets(np.bincount(ekeys // E, minlength=C))),
            cell_eidx=_sealed((ekeys % E).astype(np.intp)),
            cell_ecount=_sealed(ecount.astype(np.intp)))
        self._mask = None

    def _build_mesh(self, faces, cells, validate: bool, tolerance: float) -> None:
        v = self.vertices
        V = len(v)
        face_sizes, face_vidx = index_lists(faces, "faces", "vertex", V)
        F = len(face_sizes)
        cell_sizes, cell_fidx = index_lists(cells, "cells", "face", max(F, 1))
        C = len(cell_sizes)
        if F < 10 or C < 5:
            raise ValueError(f"Expected at least 10 faces and 5 cells (a 4-polytope's least), got {F} and {C}")
        face_ptr, cell_ptr = row_offsets(face_sizes), row_offsets(cell_sizes)
        small = np.flatnonzero(face_sizes < 3)
        if len(small):
            raise MeshError(f"`faces[{small[0]}]` has {face_sizes[small[0]]} vertices; a face needs at least 3",
                            item=("face", int(small[0])))
        small = np.flatnonzero(cell_sizes < 4)
        if len(small):
            raise MeshError(f"`cells[{small[0]}]` has {cell_sizes[small[0]]} faces; a cell needs at least 4",
                            item=("cell", int(small[0])))
        dup = duplicate_in_rows(face_ptr, face_vidx, V)
        if dup:
            raise MeshError(f"`faces[{dup[0]}]` has vertex {dup[1]} twice; a face is a cycle of distinct vertices",
                            item=("face", dup[0]))
        dup = duplicate_in_rows(cell_ptr, cell_fidx, F)
        if dup:
            raise MeshError(f"`cells[{dup[0]}]` has face {dup[1]} twice", item=("cell", dup[0]))
        use = np.bincount(cell_fidx, minlength=F)
        bad = np.flatnonzero(use != 2)
        if len(bad):
            f = int(bad[0])
            holders = row_owners(cell_ptr)[cell_fidx == f].tolist()
            raise MeshError(f"face {f} is in {use[f]} cell(s) {holders}; every face must be in exactly two "
                            f"cells (a closed boundary)", item=("face", f))
        unused = np.flatnonzero(np.bincount(face_vidx, minlength=V) == 0)
        if len(unused):
            raise MeshError(f"vertex {unused[0]} is in no face; every vertex must be a corner of some face",
                            item=("vertex", int(unused[0])))
        self._set_combinatorics(face_ptr, face_vidx, cell_ptr, cell_fidx)
        order = np.argsort(cell_fidx, kind="stable")
        cell_of = row_owners(cell_ptr)
        self.face_cells = _sealed(cell_of[order].reshape(F, 2))  # ascending (stable sort of ascending cells)
        normals, offsets, centres, ncomp, tol, star = mesh_geometry(self, validate, tolerance)  # unit scale
        self.cell_normals = _sealed(normals)
        self.cell_offsets = _sealed(offsets * self._unit)
        self._star = star
        if star is not None:  # a star face, a non-convex cell or no inside: not convex, self-intersecting
            for name in ("face_convex", "cell_convex", "face_star", "cell_star", "face_basis", "pair_rho",
                         "hemi_cells"):
                _sealed(getattr(star, name))
            self.convex = False
            # a hemi cell's faces pass through each other, and a non-orientable closed hypersurface
            # cannot be embedded in R^4: both intersect themselves
            self.self_intersecting = bool(star.face_star.any() or star.cell_star.any() or not star.volume_defined)
            return
        c1, c2 = self.face_cells[:, 0], self.face_cells[:, 1]
        locally = bool(ncomp == 1 and np.all(np.einsum("fd,fd->f", normals[c1], centres[c2]) <= offsets[c1] + tol)
                       and np.all(np.einsum("fd,fd->f", normals[c2], centres[c1]) <= offsets[c2] + tol))
        # locally convex and connected is convex only if the boundary does not wind round more than
        # once (a star polychoron such as the grand 600-cell is locally convex everywhere): every
        # vertex on the inner side of every cell's hyperplane, checked, never assumed
        self.convex = locally and _all_inside(self._unit_vertices, normals, offsets, tol)
        # connected, closed and locally convex but not convex: the boundary winds round more than once
        self.self_intersecting = locally and not self.convex

    # -- files -------------------------------------------------------------
    @classmethod
    def from_off(cls, path_or_text, name: str | None = None, *, validate: bool = True,
                 tolerance: float | None = None) -> "Polytope":
        """A polytope from Stella4D's 4OFF format: a path, or the file's text (see `rot4d_widget.geometry.offfile`).

        The faces and cells are taken as written and checked as by ``Polytope(vertices, faces,
        cells)``; every error is a ValueError naming the file's line.  Colours are read and
        checked, then dropped.  A Geomview 4OFF (homogeneous 3-D coordinates) is refused.
        ``name`` defaults to the file's stem (or "4OFF" for text).  ``tolerance``: the mesh checks'
        relative tolerance (`Polytope`; None: `MESH_TOLERANCE`), looser for a file written with few
        digits.  A counts line whose edge count E is wrong is read with a warning (E = 0: not counted).
        """
        data = read_off(path_or_text)
        if name is None:
            is_path = isinstance(path_or_text, os.PathLike) or (
                isinstance(path_or_text, str) and "\n" not in path_or_text
                and not path_or_text.lstrip().startswith("4OFF"))
            name = os.path.splitext(os.path.basename(os.fspath(path_or_text)))[0] if is_path else "4OFF"
        try:
            p = cls(data.vertices, data.faces, data.cells, name=name, validate=validate, tolerance=tolerance)
        except MeshError as exc:
            if exc.item is None:
                raise ValueError(f"lines {data.cell_lines[0]}-{data.cell_lines[-1]} (the cells): {exc}") from None
            kind, i = exc.item
            line = {"face": data.face_lines, "cell": data.cell_lines, "vertex": data.vertex_lines}[kind][i]
            raise ValueError(f"line {line} ({kind} {i}): {exc}") from None
        if data.edge_count and data.edge_count != len(p.edges):  # other tools count E their own way
            warnings.warn(f"line {data.counts_line}: E = {data.edge_count} but the faces have {len(p.edges)} edges; "
                          f"read with the faces' edges", stacklevel=2)
        return p

    def to_off(self, path=None) -> str:
        """This polytope in Stella4D's 4OFF format (exact coordinates); also written to ``path`` if given."""
        text = write_off(self.vertices, [f.tolist() for f in self.faces], self.cells, comment=self.name)
        if path is not None:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
        return text

    # -- the tables, read-only -------------------------------------------
    @property
    def incidence(self) -> Incidence:
        """The flat incidence tables (`Incidence`: faces, cells, their vertices and edges, read-only)."""
        return self._incidence

    @property
    def star(self):
        """`rot4d_widget.geometry.meshcheck.StarData` (read-only arrays) when some face is not a convex
        polygon or some cell not a convex polyhedron (the slicer then takes its general path:
        `rot4d_widget.geometry.slicing.star`), else None."""
        return self._star

    @property
    def volume_defined(self) -> bool:
        """False for a polytope with no inside to measure: its boundary is not orientable, or a cell is
        a hemi-polyhedron (`why_no_volume`).  It still loads and slices (points, even-odd segments,
        each cell's section drawn and filled even-odd, as for a star polychoron), but every `Slice`
        of it has ``volume`` None."""
        return self._star is None or self._star.volume_defined

    @property
    def why_no_volume(self) -> str | None:
        """Why `volume_defined` is False: ``"not orientable"`` (the boundary is one-sided, or a cell
        is: a tetrahemihexahedron), ``"hemi cells"`` (orientable, but a cell's faces enclose no
        volume: an octahemioctahedron, faces through its centre); None when it is defined."""
        return None if self._star is None else self._star.why_no_volume

    @property
    def unit(self) -> float:
        """The power of two the vertices are divided by (exactly) for the hull, the checks and the
        slicer: the largest |coordinate| of `unit_vertices` is in [1, 2)."""
        return self._unit

    @property
    def unit_vertices(self) -> np.ndarray:
        """(V, 4) float64, read-only: ``vertices / unit`` (exact)."""
        return self._unit_vertices

    # -- conveniences ------------------------------------------------------
    @property
    def counts(self) -> tuple[int, int, int, int]:
        """(V, E, F, C)."""
        return len(self.vertices), len(self.edges), len(self.faces), len(self.cells)

    def cell_vertices(self, c: int) -> np.ndarray:
        """Vertex indices of cell ``c``, ascending (a fresh array)."""
        c = range(len(self.cells))[c]
        inc = self._incidence
        return inc.cell_vidx[inc.cell_vptr[c] : inc.cell_vptr[c + 1]].copy()

    @property
    def _cell_vertex_mask(self) -> np.ndarray:
        """(C, V) bool, read-only: vertex v is in cell c (built on first use)."""
        if self._mask is None:
            mask = np.zeros((len(self.cells), len(self.vertices)), dtype=bool)
            mask[row_owners(self._incidence.cell_vptr), self._incidence.cell_vidx] = True
            self._mask = _sealed(mask)
        return self._mask

    def __repr__(self) -> str:
        v, e, f, c = self.counts
        return f"Polytope({self.name!r}, V={v}, E={e}, F={f}, C={c}, circumradius={self.circumradius:.4g})"
