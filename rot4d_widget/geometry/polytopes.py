"""4-polytopes: vertices plus combinatorics, convex from points or any closed mesh given whole.

`Polytope(vertices)` finds everything else once: the cells are the facets of
scipy's 4-D convex hull (coplanar simplices merged), the 2-faces are the
intersections of pairs of cells that share three or more vertices, each
ordered as a cycle, and the edges are consecutive vertices of those cycles.
So any convex 4-polytope can be given, and the six regular polychora are
built with the same code.

`Polytope(vertices, faces, cells)` takes the 2-faces (vertex cycles) and the
cells (lists of face indices) as given, checks them (closed, orientable, convex
cells; vectorised, so tens of thousands of faces take a fraction of a second)
and derives the outward normals from the boundary's orientation: such a
polytope need not be convex.

`polytope(name)` gives the six regular polychora, all with edge length 2 and
centred on the origin, from the textbook coordinates (scaled to edge 2):

========  ==========  ===================================================
name      Schläfli    vertices before scaling
========  ==========  ===================================================
5-cell    {3,3,3}     the paper's eqs. (8)-(12) with a = 2
8-cell    {4,3,3}     (±1, ±1, ±1, ±1)
16-cell   {3,3,4}     permutations of (±1, 0, 0, 0)
24-cell   {3,4,3}     permutations of (±1, ±1, 0, 0)
600-cell  {3,3,5}     permutations of (±1,0,0,0), (±½,±½,±½,±½), even
                      permutations of ½(±φ, ±1, ±1/φ, 0)
120-cell  {5,3,3}     the 600 points of circumradius √8 (see `_cell120`)
========  ==========  ===================================================
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ..core._arrays import sealed as _sealed
from scipy.spatial import ConvexHull

__all__ = ["Polytope", "MeshError", "polytope", "pentachoron", "POLYTOPE_NAMES", "MESH_TOLERANCE",
           "COORDINATE_RANGE"]

PHI = (1.0 + math.sqrt(5.0)) / 2.0

#: Canonical names, in order of vertex count.
POLYTOPE_NAMES = ("5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell")

_ALIASES = {
    "5-cell": ("5cell", "pentachoron", "simplex", "4-simplex", "pentatope", "hypertetrahedron", "{3,3,3}"),
    "8-cell": ("8cell", "tesseract", "hypercube", "octachoron", "4-cube", "{4,3,3}"),
    "16-cell": ("16cell", "hexadecachoron", "orthoplex", "cross-polytope", "4-orthoplex", "{3,3,4}"),
    "24-cell": ("24cell", "icositetrachoron", "octaplex", "{3,4,3}"),
    "120-cell": ("120cell", "hecatonicosachoron", "dodecaplex", "{5,3,3}"),
    "600-cell": ("600cell", "hexacosichoron", "tetraplex", "{3,3,5}"),
}
_NAME_OF = {}
for _canon, _aliases in _ALIASES.items():
    for _alias in (_canon, *_aliases):
        _NAME_OF[_alias] = _canon


def _normalise_name(name: str) -> str:
    return "".join(name.lower().split()).replace("_", "-")


def pentachoron(a: float = 2.0) -> "Polytope":
    """The regular pentachoron of the paper's eqs. (8)-(12), edge ``a``, centroid at the origin."""
    if isinstance(a, bool) or not isinstance(a, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected edge length `a` to be a positive number, got {type(a).__name__}")
    a = float(a)
    if not (math.isfinite(a) and a > 0):
        raise ValueError(f"Expected edge length `a` to be a positive finite number, got {a}")
    s3, s6, s10 = math.sqrt(3.0), math.sqrt(6.0), math.sqrt(10.0)
    w = -a / (2 * s10)
    vertices = np.array(
        [
            [-a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [0.0, a / s3, -a / (2 * s6), w],
            [0.0, 0.0, a * s3 / (2 * math.sqrt(2.0)), w],
            [0.0, 0.0, 0.0, 2 * a / s10],
        ]
    )
    return Polytope(vertices, name="5-cell" if a == 2.0 else f"5-cell (a={a:g})")


def _even_permutations():
    out = []
    for p in itertools.permutations(range(4)):
        inversions = sum(p[i] > p[j] for i in range(4) for j in range(i + 1, 4))
        if inversions % 2 == 0:
            out.append(p)
    return out


def _orbit(base, even_only: bool = False) -> np.ndarray:
    """All sign changes of the non-zero entries of ``base`` under (even) permutations."""
    perms = _even_permutations() if even_only else list(itertools.permutations(range(4)))
    base = np.asarray(base, dtype=float)
    signs = np.array(list(itertools.product((1.0, -1.0), repeat=4)))
    pts = np.concatenate([signs * base[list(p)] for p in perms])
    return pts


def _unique_rows(points: np.ndarray) -> np.ndarray:
    _, idx = np.unique(np.round(points, 9), axis=0, return_index=True)
    return points[np.sort(idx)]


def _cell8() -> np.ndarray:
    return np.array(list(itertools.product((-1.0, 1.0), repeat=4)))


def _cell16() -> np.ndarray:
    return _unique_rows(_orbit((1, 0, 0, 0))) * math.sqrt(2.0)


def _cell24() -> np.ndarray:
    return _unique_rows(_orbit((1, 1, 0, 0))) * math.sqrt(2.0)


def _cell600() -> np.ndarray:
    pts = np.concatenate(
        [
            _orbit((1, 0, 0, 0)),
            _orbit((0.5, 0.5, 0.5, 0.5)),
            _orbit((PHI / 2, 0.5, 1 / (2 * PHI), 0.0), even_only=True),
        ]
    )
    return _unique_rows(pts) * (2.0 * PHI)  # edge 1/phi -> 2


def _cell120() -> np.ndarray:
    """The 600 vertices of circumradius sqrt(8): permutations of (0,0,±2,±2),
    (±1,±1,±1,±√5), (±φ⁻²,±φ,±φ,±φ), (±φ⁻¹,±φ⁻¹,±φ⁻¹,±φ²) and even permutations
    of (0,±φ⁻²,±1,±φ²), (0,±φ⁻¹,±φ,±√5), (±φ⁻¹,±1,±φ,±2); edge 2/φ² scaled to 2."""
    s5 = math.sqrt(5.0)
    ip, ip2 = 1 / PHI, 1 / PHI**2
    pts = np.concatenate(
        [
            _orbit((0, 0, 2, 2)),
            _orbit((1, 1, 1, s5)),
            _orbit((ip2, PHI, PHI, PHI)),
            _orbit((ip, ip, ip, PHI**2)),
            _orbit((0, ip2, 1, PHI**2), even_only=True),
            _orbit((0, ip, PHI, s5), even_only=True),
            _orbit((ip, 1, PHI, 2), even_only=True),
        ]
    )
    return _unique_rows(pts) * PHI**2


_BUILDERS = {
    "5-cell": lambda: pentachoron(2.0).vertices,
    "8-cell": _cell8,
    "16-cell": _cell16,
    "24-cell": _cell24,
    "600-cell": _cell600,
    "120-cell": _cell120,
}


#: Relative tolerance of a mesh's geometric checks (planar faces, flat and convex cells,
#: distinct vertices): this times the largest extent of the vertices' bounding box.  Looser
#: than the slicer's `TOLERANCE` so that coordinates written with 7 significant digits pass.
MESH_TOLERANCE = 1e-6


#: The scale of an object (a polytope's largest absolute coordinate, a field box's half widths and
#: the ends of its extent) must lie in this range: (smallest, largest).  Within it the square of
#: every coordinate, distance or dot product is a normal float64 (1e-300 to 1e300), so any code
#: that measures lengths stays exact to rounding; outside it a ValueError names the range.  Each
#: object is normalised by a power of two (exact) before the hull, the checks and the slicer, and
#: every tolerance is relative to its scale, so the results are the unit object's, scaled.
COORDINATE_RANGE = (1e-150, 1e150)


def check_scale(scale: float, what: str) -> None:
    """ValueError unless ``COORDINATE_RANGE[0] <= scale <= COORDINATE_RANGE[1]`` (``what`` names it)."""
    lo, hi = COORDINATE_RANGE
    if not lo <= scale <= hi:
        raise ValueError(f"{what} is {scale:.3g}; expected {lo:g} to {hi:g} (rot4d_widget.geometry.polytopes.COORDINATE_RANGE: "
                         f"squares of coordinates must stay normal float64 numbers; rescale the data, e.g. to "
                         f"other units)")


def _power_of_two_unit(amax: float) -> float:
    """The power of two 2**k with ``1 <= amax / 2**k < 2`` (dividing by it is exact)."""
    return math.ldexp(1.0, math.frexp(amax)[1] - 1)


class MeshError(ValueError):
    """An explicit mesh given to `Polytope` is not a valid 4-polytope.

    ``item`` is the offending ``("face" | "cell" | "vertex", index)`` when there is one
    (the 4OFF reader turns it into a line number), else None.
    """

    def __init__(self, message: str, item: tuple | None = None):
        super().__init__(message)
        self.item = item


def _ptr(sizes: np.ndarray) -> np.ndarray:
    """(n,) sizes -> (n + 1,) start offsets."""
    ptr = np.zeros(len(sizes) + 1, dtype=np.intp)
    np.cumsum(sizes, out=ptr[1:])
    return ptr


def _owner(ptr: np.ndarray) -> np.ndarray:
    """For offsets ``ptr`` (n + 1,), the owner (0..n-1) of every entry."""
    return np.repeat(np.arange(len(ptr) - 1, dtype=np.intp), np.diff(ptr))


def _gather(ptr: np.ndarray, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Entries of the rows ``which`` of a ragged table with offsets ``ptr``, back to back:
    (entry indices, position in ``which`` of each)."""
    sizes = ptr[which + 1] - ptr[which]
    row = np.repeat(np.arange(len(which), dtype=np.intp), sizes)
    first = _ptr(sizes)
    return ptr[which][row] + np.arange(first[-1], dtype=np.intp) - first[row], row


def _index_lists(seq, what: str, item: str, n_max: int) -> tuple[np.ndarray, np.ndarray]:
    """A sequence of sequences of indices -> (sizes (n,) intp, flat (sum,) intp), checked:
    integers in ``0 .. n_max - 1``.  TypeError / ValueError name the first bad entry."""
    expected = f"a sequence of sequences of {item} indices (integers 0 to {n_max - 1})"
    if isinstance(seq, (str, bytes)):
        raise TypeError(f"Expected `{what}` to be {expected}, got {type(seq).__name__}")
    if isinstance(seq, np.ndarray) and seq.ndim == 2 and seq.dtype.kind in "iu":
        sizes = np.full(len(seq), seq.shape[1], dtype=np.intp)
        flat = seq.astype(np.intp).ravel()
    else:
        try:
            items = list(seq)
        except TypeError:
            raise TypeError(f"Expected `{what}` to be {expected}, got {type(seq).__name__}") from None
        sizes = np.empty(len(items), dtype=np.intp)
        for i, it in enumerate(items):
            if isinstance(it, (str, bytes)):
                raise TypeError(f"Expected `{what}[{i}]` to be a sequence of {item} indices, got {it!r}")
            try:
                sizes[i] = len(it)
            except TypeError:
                raise TypeError(f"Expected `{what}[{i}]` to be a sequence of {item} indices, "
                                f"got {type(it).__name__}") from None
        if items and all(isinstance(it, np.ndarray) and it.ndim == 1 for it in items):
            flat = np.concatenate(items)  # e.g. a Wythoff construction's cycles: no Python loop over entries
        else:
            flat = np.array(list(itertools.chain.from_iterable(items)))
        if flat.size == 0:
            flat = np.zeros(0, dtype=np.intp)
        if flat.ndim != 1 or flat.dtype.kind not in "iu":
            for i, it in enumerate(items):
                a = np.asarray(it)
                if a.ndim != 1 or (a.size and a.dtype.kind not in "iu"):
                    raise TypeError(f"Expected `{what}[{i}]` to be a sequence of integer {item} indices, "
                                    f"got {np.asarray(it).tolist()[:8]!r}")
            raise TypeError(f"Expected `{what}` to be {expected}")
        flat = flat.astype(np.intp)
    bad = np.flatnonzero((flat < 0) | (flat >= n_max))
    if len(bad):
        i = int(np.searchsorted(_ptr(sizes), bad[0], side="right") - 1)
        raise MeshError(f"`{what}[{i}]` has {item} index {int(flat[bad[0]])}; expected integers 0 to {n_max - 1}",
                        item=("face" if what == "faces" else "cell", i))
    return sizes, flat


def _duplicate_in_rows(ptr: np.ndarray, flat: np.ndarray, n: int):
    """First (row, value) that occurs twice in one row of a ragged table, or None."""
    key = _owner(ptr) * n + flat
    s = np.sort(key)
    dup = np.flatnonzero(s[1:] == s[:-1])
    if len(dup):
        return int(s[dup[0]] // n), int(s[dup[0]] % n)
    return None


def order_cycle(points: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """The vertices ``idx`` of a planar convex polygon (points in any dimension) ordered as a cycle (intp)."""
    p = points[idx]
    c = p.mean(axis=0)
    _, _, vt = np.linalg.svd(p - c)
    xy = (p - c) @ vt[:2].T
    return idx[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))].astype(np.intp)


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
    checks use `MESH_TOLERANCE` times the vertices' largest extent):

    * every face has >= 3 distinct vertices, is planar and a strictly convex polygon
      in the order given (no three consecutive corners collinear, no star);
    * every face is in exactly two cells (the boundary is closed), every vertex in a face;
    * every cell has >= 4 distinct faces, lies in a hyperplane, spans 3-D, is closed
      (each of its edges in exactly two of its faces) and strictly convex (every
      vertex of the cell on the inner side of each face's plane, and only the face's
      own corners on it);
    * the boundary is consistently orientable.  The outward normals then come from that
      orientation, not from the origin: each boundary component is oriented so that it
      encloses positive 4-volume, and a component inside another (a cavity, found by
      casting a ray) the other way.

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
    the omnitruncated 120-cell: docs/uniform.md).  ``validate=False`` skips the per-cell
    closedness and convexity checks (for combinatorics known to be right, e.g. from a
    Wythoff construction); the faces' geometry and the orientation are still derived
    and checked, and a non-convex cell then gives wrong normals or an orientation error.

    Attributes
    ----------
    vertices : (V, 4) float64
    edges : (E, 2) intp, each row sorted, rows sorted
    faces : tuple of F intp arrays, each an ordered cycle of vertex indices
    cells : tuple of C tuples of face indices
    face_cells : (F, 2) intp, the two cells of each face, ascending
    circumradius : float, max distance of a vertex from the origin
    convex : bool, the polytope is convex (always from the hull; for a mesh: one
        boundary component and no reflex ridge, i.e. each cell's neighbours across
        its faces on its inner side -- locally convex and connected is convex)
    cell_normals : (C, 4) float64 outward unit normals; ``cell_offsets`` (C,)
        so that cell c lies in ``vertices @ cell_normals[c] == cell_offsets[c]``

    Every array is read-only and the sequences are tuples: a polytope is
    shared (``polytope(name)`` is cached, slicing tables are built from it
    once), so an edit anywhere would corrupt every later slice.
    """

    def __init__(self, vertices, faces=None, cells=None, name: str = "polytope", *, validate: bool = True):
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
        amax = float(np.abs(v).max())
        if amax == 0:
            raise ValueError("`vertices` are all the origin: they do not span a 4-D convex polytope" if faces is None
                             else "`vertices` are all the same point")
        check_scale(amax, "The largest absolute coordinate of `vertices`")
        self.name = str(name)
        self.vertices = _sealed(v)
        # the vertices divided by a power of two (exactly) so that the largest |coordinate| is in
        # [1, 2): the hull, the mesh checks and the slicer work on these, at any scale
        self._unit = _power_of_two_unit(amax)
        vn = v / self._unit
        self._unit_vertices = _sealed(vn)
        self.circumradius = float(np.sqrt((vn * vn).sum(axis=1)).max()) * self._unit
        if faces is None:
            self._build_hull()
        else:
            self._build_mesh(faces, cells, bool(validate))

    # -- construction ------------------------------------------------------
    def _build_hull(self) -> None:
        v = self._unit_vertices  # largest |coordinate| in [1, 2): qhull and the tolerances see one scale
        tol = 1e-9 * float(np.abs(v).max())
        try:
            hull = ConvexHull(v)
        except Exception as exc:  # qhull: flat or degenerate input
            raise ValueError(f"`vertices` do not span a 4-D convex polytope: {exc}") from None
        if len(hull.vertices) != len(v):
            raise ValueError("Every vertex must be a corner of the convex hull (found interior or repeated points)")
        # cells: distinct facet hyperplanes of the hull (unit normals, offsets of order 1)
        eq = hull.equations
        key = np.round(eq, 7)
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
        self._set_combinatorics(_ptr(face_sizes), np.concatenate(faces), _ptr(cell_sizes), cell_fidx)
        self.cell_normals = _sealed(np.ascontiguousarray(normals))
        self.cell_offsets = _sealed(np.ascontiguousarray(offsets) * self._unit)
        self.face_cells = _sealed(np.stack([ci, cj], axis=1).astype(np.intp))  # (F, 2), ascending
        self.convex = True


    def _set_combinatorics(self, face_ptr, face_vidx, cell_ptr, cell_fidx) -> None:
        """Edges, faces, cells and the flat incidence tables (also used by the slicer).

        Private tables (all read-only):  ``_face_ptr``/``_face_vidx`` the face cycles back to back;
        ``_face_eidx`` the edge of each side (corner k to k + 1);  ``_cell_ptr``/``_cell_fidx``
        each cell's faces;  ``_cell_vptr``/``_cell_vidx`` each cell's vertices, ascending;
        ``_cell_eptr``/``_cell_eidx`` each cell's edges, ascending, with ``_cell_ecount`` the
        number of the cell's faces that have each.
        """
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
        idx, row = _gather(face_ptr, cell_fidx)
        cell_of = _owner(cell_ptr)[row]
        vkey = np.unique(cell_of * V + face_vidx[idx])
        ekeys, ecount = np.unique(cell_of * E + face_eidx.reshape(-1)[idx], return_counts=True)
        self._face_ptr, self._face_vidx = _sealed(face_ptr), _sealed(face_vidx.astype(np.intp))
        self._face_eidx = _sealed(face_eidx.reshape(-1).astype(np.intp))
        self._cell_ptr, self._cell_fidx = _sealed(cell_ptr), _sealed(cell_fidx.astype(np.intp))
        self._cell_vptr = _sealed(_ptr(np.bincount(vkey // V, minlength=C)))
        self._cell_vidx = _sealed((vkey % V).astype(np.intp))
        self._cell_eptr = _sealed(_ptr(np.bincount(ekeys // E, minlength=C)))
        self._cell_eidx = _sealed((ekeys % E).astype(np.intp))
        self._cell_ecount = _sealed(ecount.astype(np.intp))
        self._mask = None

    def _build_mesh(self, faces, cells, validate: bool) -> None:
        v = self.vertices
        V = len(v)
        face_sizes, face_vidx = _index_lists(faces, "faces", "vertex", V)
        F = len(face_sizes)
        cell_sizes, cell_fidx = _index_lists(cells, "cells", "face", max(F, 1))
        C = len(cell_sizes)
        if F < 10 or C < 5:
            raise ValueError(f"Expected at least 10 faces and 5 cells (a 4-polytope's least), got {F} and {C}")
        face_ptr, cell_ptr = _ptr(face_sizes), _ptr(cell_sizes)
        small = np.flatnonzero(face_sizes < 3)
        if len(small):
            raise MeshError(f"`faces[{small[0]}]` has {face_sizes[small[0]]} vertices; a face needs at least 3",
                            item=("face", int(small[0])))
        small = np.flatnonzero(cell_sizes < 4)
        if len(small):
            raise MeshError(f"`cells[{small[0]}]` has {cell_sizes[small[0]]} faces; a cell needs at least 4",
                            item=("cell", int(small[0])))
        dup = _duplicate_in_rows(face_ptr, face_vidx, V)
        if dup:
            raise MeshError(f"`faces[{dup[0]}]` has vertex {dup[1]} twice; a face is a cycle of distinct vertices",
                            item=("face", dup[0]))
        dup = _duplicate_in_rows(cell_ptr, cell_fidx, F)
        if dup:
            raise MeshError(f"`cells[{dup[0]}]` has face {dup[1]} twice", item=("cell", dup[0]))
        use = np.bincount(cell_fidx, minlength=F)
        bad = np.flatnonzero(use != 2)
        if len(bad):
            f = int(bad[0])
            holders = _owner(cell_ptr)[cell_fidx == f].tolist()
            raise MeshError(f"face {f} is in {use[f]} cell(s) {holders}; every face must be in exactly two "
                            f"cells (a closed boundary)", item=("face", f))
        unused = np.flatnonzero(np.bincount(face_vidx, minlength=V) == 0)
        if len(unused):
            raise MeshError(f"vertex {unused[0]} is in no face; every vertex must be a corner of some face",
                            item=("vertex", int(unused[0])))
        self._set_combinatorics(face_ptr, face_vidx, cell_ptr, cell_fidx)
        order = np.argsort(cell_fidx, kind="stable")
        cell_of = _owner(cell_ptr)
        self.face_cells = _sealed(cell_of[order].reshape(F, 2))  # ascending (stable sort of ascending cells)
        normals, offsets, centres, ncomp, tol = _mesh_geometry(self, validate)  # in the unit vertices' scale
        self.cell_normals = _sealed(normals)
        self.cell_offsets = _sealed(offsets * self._unit)
        c1, c2 = self.face_cells[:, 0], self.face_cells[:, 1]
        self.convex = bool(ncomp == 1 and np.all(np.einsum("fd,fd->f", normals[c1], centres[c2]) <= offsets[c1] + tol)
                           and np.all(np.einsum("fd,fd->f", normals[c2], centres[c1]) <= offsets[c2] + tol))

    # -- files -------------------------------------------------------------
    @classmethod
    def from_off(cls, path_or_text, name: str | None = None, *, validate: bool = True) -> "Polytope":
        """A polytope from Stella4D's 4OFF format: a path, or the file's text (see `rot4d_widget.geometry.offfile`).

        The faces and cells are taken as written and checked as by ``Polytope(vertices, faces,
        cells)``; every error is a ValueError naming the file's line.  Colours are read and
        checked, then dropped.  A Geomview 4OFF (homogeneous 3-D coordinates) is refused.
        ``name`` defaults to the file's stem (or "4OFF" for text).
        """
        import os

        from .offfile import read_off

        data = read_off(path_or_text)
        if name is None:
            is_path = isinstance(path_or_text, os.PathLike) or (
                isinstance(path_or_text, str) and "\n" not in path_or_text
                and not path_or_text.lstrip().startswith("4OFF"))
            name = os.path.splitext(os.path.basename(os.fspath(path_or_text)))[0] if is_path else "4OFF"
        try:
            p = cls(data.vertices, data.faces, data.cells, name=name, validate=validate)
        except MeshError as exc:
            if exc.item is None:
                raise ValueError(f"lines {data.cell_lines[0]}-{data.cell_lines[-1]} (the cells): {exc}") from None
            kind, i = exc.item
            line = {"face": data.face_lines, "cell": data.cell_lines, "vertex": data.vertex_lines}[kind][i]
            raise ValueError(f"line {line} ({kind} {i}): {exc}") from None
        if data.edge_count and data.edge_count != len(p.edges):
            raise ValueError(f"line {data.counts_line}: E = {data.edge_count} but the faces have {len(p.edges)} "
                             f"edges (E may be 0 when not counted)")
        return p

    def to_off(self, path=None) -> str:
        """This polytope in Stella4D's 4OFF format (exact coordinates); also written to ``path`` if given."""
        from .offfile import write_off

        text = write_off(self.vertices, [f.tolist() for f in self.faces], self.cells, comment=self.name)
        if path is not None:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
        return text

    # -- conveniences ------------------------------------------------------
    @property
    def counts(self) -> tuple[int, int, int, int]:
        """(V, E, F, C)."""
        return len(self.vertices), len(self.edges), len(self.faces), len(self.cells)

    def cell_vertices(self, c: int) -> np.ndarray:
        """Vertex indices of cell ``c``, ascending (a fresh array)."""
        c = range(len(self.cells))[c]
        return self._cell_vidx[self._cell_vptr[c] : self._cell_vptr[c + 1]].copy()

    @property
    def _cell_vertex_mask(self) -> np.ndarray:
        """(C, V) bool, read-only: vertex v is in cell c (built on first use)."""
        if self._mask is None:
            mask = np.zeros((len(self.cells), len(self.vertices)), dtype=bool)
            mask[_owner(self._cell_vptr), self._cell_vidx] = True
            self._mask = _sealed(mask)
        return self._mask

    def __repr__(self) -> str:
        v, e, f, c = self.counts
        return f"Polytope({self.name!r}, V={v}, E={e}, F={f}, C={c}, circumradius={self.circumradius:.4g})"


def _mesh_geometry(p: Polytope, validate: bool) -> tuple:
    """Check an explicit mesh's geometry: (outward cell normals, offsets, cell centres, number of
    boundary components, the tolerance used); lengths in the scale of ``p._unit_vertices``."""
    v = p._unit_vertices
    V, F, C = len(v), len(p._face_ptr) - 1, len(p._cell_ptr) - 1
    tol = MESH_TOLERANCE * float(np.ptp(v, axis=0).max())
    if tol == 0:
        raise ValueError("`vertices` are all the same point")
    # distinct vertices
    key = np.round(v / tol).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    if len(first) < V:
        i = int(np.flatnonzero(first[inverse.reshape(-1)] != np.arange(V))[0])
        raise MeshError(f"vertices {int(first[inverse.reshape(-1)[i]])} and {i} coincide", item=("vertex", i))
    fptr, fv = p._face_ptr, p._face_vidx
    fsize = np.diff(fptr)
    face_c = np.empty((F, 4))
    face_e = np.empty((F, 2, 4))
    face_area = np.empty(F)
    for k in np.unique(fsize).tolist():
        fs = np.flatnonzero(fsize == k)
        P = v[fv[fptr[fs][:, None] + np.arange(k)]]  # (n, k, 4)
        c = P.mean(axis=1)
        Q = P - c[:, None]
        _, s, vt = np.linalg.svd(Q, full_matrices=False)
        B = vt[:, :2]  # (n, 2, 4) the face's plane
        xy = np.einsum("nkd,njd->nkj", Q, B)
        off = np.linalg.norm(Q - np.einsum("nkj,njd->nkd", xy, B), axis=2).max(axis=1)
        bad = np.flatnonzero(off > tol)
        if len(bad):
            f = int(fs[bad[0]])
            raise MeshError(f"face {f} is not planar: a corner is {off[bad[0]] * p._unit:.3g} from its plane "
                            f"(tolerance {tol * p._unit:.3g})", item=("face", f))
        e = np.roll(xy, -1, axis=1) - xy  # side k: corner k -> k + 1
        e2 = np.roll(e, -1, axis=1)
        cross = e[..., 0] * e2[..., 1] - e[..., 1] * e2[..., 0]
        dot = (e * e2).sum(axis=2)
        chord = np.linalg.norm(e + e2, axis=2)
        dist = np.abs(cross) / np.maximum(chord, 1e-300)  # corner k + 1 from the line of its neighbours
        turning = np.arctan2(cross, dot).sum(axis=1)
        sign = np.sign(cross)
        ok = (dist > tol).all(axis=1) & (sign == sign[:, :1]).all(axis=1) & (np.abs(np.abs(turning) - 2 * np.pi) < 1)
        bad = np.flatnonzero(~ok)
        if len(bad):
            f = int(fs[bad[0]])
            raise MeshError(f"face {f} {p.faces[f].tolist()} is not a convex polygon in the order given "
                            f"(collinear or repeated corners, a reflex corner, or a star); faces must be "
                            f"strictly convex polygons with their vertices in cyclic order", item=("face", f))
        face_c[fs] = c
        face_e[fs] = B
        face_area[fs] = 0.5 * np.abs((xy[..., 0] * np.roll(xy[..., 1], -1, axis=1)
                                      - np.roll(xy[..., 0], -1, axis=1) * xy[..., 1]).sum(axis=1))
    if validate:  # before the cells' geometry: an open cell is a mistake in the lists, named as such
        _check_closed(p)
    # cells: flat, 3-D, normal
    cptr, cfx = p._cell_ptr, p._cell_fidx
    vptr, cvx = p._cell_vptr, p._cell_vidx
    nv = np.diff(vptr)
    g = np.empty((C, 4))
    n = np.empty((C, 4))
    for k in np.unique(nv).tolist():
        cs = np.flatnonzero(nv == k)
        P = v[cvx[vptr[cs][:, None] + np.arange(k)]]
        gc = P.mean(axis=1)
        Q = P - gc[:, None]
        R = np.linalg.qr(Q, mode="r") if k > 4 else Q
        _, s, vt = np.linalg.svd(R, full_matrices=True)
        normal = vt[:, 3]
        off = np.abs(np.einsum("nkd,nd->nk", Q, normal)).max(axis=1)
        bad = np.flatnonzero(off > tol)
        if len(bad):
            c = int(cs[bad[0]])
            raise MeshError(f"cell {c} does not lie in a hyperplane: a vertex is {off[bad[0]] * p._unit:.3g} "
                            f"from it (tolerance {tol * p._unit:.3g})", item=("cell", c))
        bad = np.flatnonzero(s[:, 2] <= tol)
        if len(bad):
            raise MeshError(f"cell {int(cs[bad[0]])} is degenerate: its vertices span less than 3-D",
                            item=("cell", int(cs[bad[0]])))
        g[cs] = gc
        n[cs] = normal
    pc = _owner(cptr)  # the (cell, face) pairs, cell by cell
    pf = cfx
    m = face_c[pf] - g[pc]
    for basis in (n[pc], face_e[pf, 0], face_e[pf, 1]):
        m -= np.einsum("id,id->i", m, basis)[:, None] * basis
    height = np.linalg.norm(m, axis=1)  # the cell's centroid from each face's plane, in the cell
    bad = np.flatnonzero(height <= tol)
    if len(bad):
        raise MeshError(f"cell {int(pc[bad[0]])} is degenerate: its centre lies in the plane of its face "
                        f"{int(pf[bad[0]])}", item=("cell", int(pc[bad[0]])))
    m /= height[:, None]  # each face's outward normal within each of its cells
    if validate:
        _check_cells(p, v, tol, pc, pf, m, face_c)
    # orientation: the sign of det[n_c, m_cf, plane of f] relates the two cells of each face
    sigma = np.sign(np.linalg.det(np.stack([n[pc], m, face_e[pf, 0], face_e[pf, 1]], axis=1)))
    order = np.argsort(pf, kind="stable")
    c1, c2 = pc[order[0::2]], pc[order[1::2]]
    same = -sigma[order[0::2]] * sigma[order[1::2]] > 0  # s_c1 == s_c2 for a consistent orientation
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a = np.concatenate([c1, c1 + C])
    b = np.concatenate([np.where(same, c2, c2 + C), np.where(same, c2 + C, c2)])
    _, lab = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(2 * C, 2 * C)), directed=False)
    bad = np.flatnonzero(lab[:C] == lab[C:])
    if len(bad):
        raise MeshError(f"the boundary is not orientable: the cells around cell {int(bad[0])} cannot all be "
                        f"given outward normals that agree across their shared faces", item=("cell", int(bad[0])))
    s = np.where(lab[:C] < lab[C:], 1.0, -1.0)
    ncomp, comp = connected_components(coo_matrix((np.ones(F), (c1, c2)), shape=(C, C)), directed=False)
    vol3 = np.bincount(pc, weights=face_area[pf] * height, minlength=C) / 3.0
    offsets = np.einsum("cd,cd->c", n, g)
    vol4 = np.bincount(comp, weights=s * offsets * vol3, minlength=ncomp) / 4.0
    small = np.flatnonzero(np.abs(vol4) <= tol * tol * tol * tol)
    if len(small):
        raise MeshError(f"the boundary component of cell {int(np.flatnonzero(comp == small[0])[0])} encloses "
                        f"no 4-volume")
    flip = vol4 < 0
    if ncomp > 1:
        flip ^= _cavities(n * s[:, None], offsets * s, g, comp, ncomp, pc, pf, m, face_c)
    s = np.where(flip[comp], -s, s)
    normals = np.ascontiguousarray(n * s[:, None])
    return normals, np.ascontiguousarray(offsets * s), g, ncomp, tol


def _check_closed(p: Polytope) -> None:
    """Every cell closed: each of its edges in exactly two of its faces (MeshError naming the cell)."""
    open_ = np.flatnonzero(p._cell_ecount != 2)
    if len(open_):
        i = int(open_[0])
        c = int(np.searchsorted(p._cell_eptr, i, side="right") - 1)
        e = p.edges[p._cell_eidx[i]].tolist()
        raise MeshError(f"cell {c} is not closed: its edge {tuple(e)} is in {p._cell_ecount[i]} of its faces; "
                        f"each edge of a cell must be in exactly two of its faces", item=("cell", c))


def _check_cells(p, v, tol, pc, pf, m, face_c) -> None:
    """Every cell strictly convex (MeshError naming the cell)."""
    cptr, vptr, cvx = p._cell_ptr, p._cell_vptr, p._cell_vidx
    nf, nv = np.diff(cptr), np.diff(vptr)
    fsize = np.diff(p._face_ptr)
    kinds, kind = np.unique(nf * (nv.max() + 1) + nv, return_inverse=True)
    for j in range(len(kinds)):
        cells_j = np.flatnonzero(kind.reshape(-1) == j)
        q, k = int(nf[cells_j[0]]), int(nv[cells_j[0]])
        step = max(1, 2_000_000 // (q * k))
        for lo in range(0, len(cells_j), step):
            cs = cells_j[lo : lo + step]
            P = v[cvx[vptr[cs][:, None] + np.arange(k)]]  # (n, k, 4)
            pairs = cptr[cs][:, None] + np.arange(q)  # (n, q)
            M = m[pairs]
            D = M @ P.transpose(0, 2, 1) - np.einsum("nqd,nqd->nq", M, face_c[pf[pairs]])[..., None]
            out = D > tol
            if out.any():
                i, j2, k2 = np.argwhere(out)[0]
                raise MeshError(f"cell {int(cs[i])} is not convex: its vertex {int(cvx[vptr[cs[i]] + k2])} is "
                                f"outside the plane of its face {int(pf[pairs[i, j2]])}", item=("cell", int(cs[i])))
            on = (D >= -tol).sum(axis=2)
            wrong = on != fsize[pf[pairs]]
            if wrong.any():
                i, j2 = np.argwhere(wrong)[0]
                raise MeshError(f"cell {int(cs[i])} is not strictly convex: a vertex that is not a corner of its "
                                f"face {int(pf[pairs[i, j2]])} lies in that face's plane (two coplanar faces?)",
                                 item=("cell", int(cs[i])))


def _cavities(normals, offsets, g, comp, ncomp, pc, pf, m, face_c) -> np.ndarray:
    """(ncomp,) bool: boundary components that lie inside an odd number of the others.

    A ray from a point of each component (a cell's centre) in a fixed generic direction
    counts the cells of every other component it passes through.
    """
    C = len(g)
    rng = np.random.default_rng(12345)
    r = rng.normal(size=4)
    r /= np.linalg.norm(r)
    first = np.array([np.flatnonzero(comp == k)[0] for k in range(ncomp)])
    q = g[first]  # (K, 4)
    depth = np.zeros(ncomp, dtype=np.intp)
    nr = normals @ r  # (C,)
    t = (offsets[None, :] - q @ normals.T) / np.where(np.abs(nr) > 1e-300, nr, 1e-300)[None, :]  # (K, C)
    hit_pt = q[:, None, :] + t[..., None] * r  # (K, C, 4)
    for k in range(ncomp):
        x = hit_pt[k]  # (C, 4)
        inside_face = np.einsum("id,id->i", x[pc] - face_c[pf], m) <= 0
        inside = np.logical_and.reduceat(inside_face, np.searchsorted(pc, np.arange(C)))
        ok = inside & (t[k] > 0) & (comp != k) & (np.abs(nr) > 1e-12)
        crossings = np.bincount(comp[ok], minlength=ncomp)
        depth[k] = int((crossings % 2).sum())
    return depth % 2 == 1


@functools.lru_cache(maxsize=None)
def _named(canon: str) -> Polytope:
    if canon == "5-cell":
        return pentachoron(2.0)
    return Polytope(_BUILDERS[canon](), name=canon)


def polytope(name) -> Polytope:
    """A uniform polychoron with edge 2, centred on the origin, by name.

    The six regular ones by name, alias or Schläfli symbol: ``"5-cell"`` (pentachoron,
    ``"{3,3,3}"``), ``"8-cell"`` (tesseract), ``"16-cell"``, ``"24-cell"``, ``"120-cell"``,
    ``"600-cell"``; every other uniform one (`rot4d_widget.geometry.uniform`: the Wythoff families,
    the snub 24-cell, the grand antiprism, prisms, duoprisms, antiprismatic prisms) by its
    common name (``"rectified 5-cell"``, ``"5-7 duoprism"``) or linear Dynkin symbol
    (``"o3x3o3o"``, ``"x5x3x3x"``); ``rot4d_widget.polytope_names()`` lists them.  A
    `Polytope` is returned as is.  The result is built once and cached.
    """
    if isinstance(name, Polytope):
        return name
    if not isinstance(name, str):
        raise TypeError(f"Expected a polytope name (str) or a Polytope, got {type(name).__name__}")
    canon = _NAME_OF.get(_normalise_name(name))
    if canon is None:
        from . import uniform  # imported here: uniform imports this module

        if uniform.canonical_name(name) is not None:
            return uniform.build(name)
        allowed = ", ".join(f"{n!r} ({', '.join(_ALIASES[n][1:3])}, {_ALIASES[n][-1]})" for n in POLYTOPE_NAMES)
        raise ValueError(f"Unknown polytope {name!r}; expected one of {allowed}, or a uniform polychoron by "
                         "name or Dynkin symbol (rot4d_widget.polytope_names() lists them)")
    return _named(canon)
