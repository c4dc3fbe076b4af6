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
  Now a solid slice is given by its boundary alone: vertices on H and edges in
  H that no polygon uses (inside S, or where P touches H away from S) are
  dropped (`_boundary_only`; for a convex polytope nothing is dropped).
* H touching P: the dimension is 2 if a face lies in H, else 1 if an edge
  does, else 0 (a convex polytope touches in one face, edge or vertex).

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
`rot4d_widget.geometry.polytopes.COORDINATE_RANGE`, 1e-150 to 1e150) has the slices
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

import weakref
from dataclasses import dataclass

import numpy as np

from ..core._arrays import sealed as _sealed

from .polytopes import Polytope, _owner, polytope as _get_polytope
from ..core.rotation import as_rotation_matrix

__all__ = ["Slice", "slice_polytope", "TOLERANCE"]

#: The one tolerance for "on H", relative to the polytope's circumradius.
TOLERANCE = 1e-9

_TWO_PI_PLUS = 8.0  # > 2*pi: spacing of per-polygon sort keys


class _Tables:
    """Incidence arrays for vectorised slicing, built once per polytope."""

    def __init__(self, p: Polytope):
        V, C = len(p.vertices), len(p.cells)
        F = len(p.faces)
        self.V, self.F, self.C = V, F, C
        self.ea = np.ascontiguousarray(p.edges[:, 0])
        self.eb = np.ascontiguousarray(p.edges[:, 1])
        # the polytope's flat incidence tables (see Polytope._set_combinatorics): each face's
        # corners and sides in cycle order, each cell's vertices and edges ascending
        self.fv_face = _owner(p._face_ptr)
        self.fv_vert = p._face_vidx
        self.fe_face = self.fv_face
        self.fe_edge = p._face_eidx
        self.f_starts = p._face_ptr[:-1]
        self.cv_cell = _owner(p._cell_vptr)
        self.cv_vert = p._cell_vidx
        self.ce_cell = _owner(p._cell_eptr)
        self.ce_edge = p._cell_eidx
        self.c_starts = p._cell_vptr[:-1]
        # first three vertices of each face cycle: two non-parallel edge vectors
        self.face_abc = p._face_vidx[p._face_ptr[:-1, None] + np.arange(3)]
        self.face_cells = p.face_cells
        self.cell_normals = np.ascontiguousarray(p.cell_normals)
        # each cell's vertex mean (a point inside the convex cell), for 2-faces lying in H
        nv = np.diff(np.append(self.c_starts, len(self.cv_vert)))
        # everything here is in the scale of the polytope's unit vertices (its vertices divided by
        # the power of two `unit`, largest |coordinate| in [1, 2)): a slice is cut there and its
        # vertices and volume are scaled back (`_scaled`), so any scale in COORDINATE_RANGE slices alike
        self.unit = float(p._unit)
        self.vertices = p._unit_vertices
        self.radius = p.circumradius / self.unit
        self.cell_centres = np.stack([np.bincount(self.cv_cell, weights=self.vertices[self.cv_vert, k], minlength=C)
                                      for k in range(4)], axis=1) / nv[:, None]
        self.tol = TOLERANCE * self.radius
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


_TABLES: "weakref.WeakKeyDictionary[Polytope, _Tables]" = weakref.WeakKeyDictionary()


def _tables(p: Polytope) -> _Tables:
    t = _TABLES.get(p)
    if t is None:
        t = _TABLES[p] = _Tables(p)
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
    volume : float -- the 3-volume (0 unless the slice is solid; inf, or 0, when it is
        beyond float64's range: coordinates above ~5e102 or below ~2e-103)
    dim : int -- 3 solid, 2/1/0 when H only touches a face/edge/vertex, -1 empty

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
    volume: float
    dim: int

    def __post_init__(self):
        for a in (self.vertices, self.edges, self.polygon_indices, self.polygon_offsets,
                  self.cell_ids, self.triangles, self.triangle_cells):
            a.flags.writeable = False

    @property
    def polygons(self) -> list:
        """The polygons as a list of (read-only) vertex-index arrays (for iteration; not on the hot path)."""
        return np.split(self.polygon_indices, self.polygon_offsets[1:-1]) if len(self.cell_ids) else []

    @property
    def polygon_sizes(self) -> np.ndarray:
        """(P,) intp, read-only: the number of corners of each polygon."""
        sizes = np.diff(self.polygon_offsets)
        sizes.flags.writeable = False
        return sizes

    def face_census(self) -> dict:
        """``{number of sides: number of polygons}``, e.g. ``{3: 8, 4: 6}``."""
        sizes, counts = np.unique(self.polygon_sizes, return_counts=True)
        return {int(s): int(c) for s, c in zip(sizes, counts)}

    def __repr__(self) -> str:
        return (
            f"Slice(dim={self.dim}, V={len(self.vertices)}, E={len(self.edges)}, "
            f"F={len(self.cell_ids)}, census={self.face_census()}, volume={self.volume:.6g})"
        )


class _Inconsistent(Exception):
    """A face chord without exactly two ends: classification hit a near-degenerate case."""


class _NoCrossing(Exception):
    """Levels with vertices on both sides but no crossing edge (a polytope in separate pieces)."""

    def __init__(self, levels: np.ndarray):
        super().__init__()
        self.levels = levels


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
    if not many:
        return _slice_level(t, x, m, float(levels[0]), t.radius)
    return _slice_many(t, x, m, levels, t.radius)


def _as_levels(c0):
    """``c0`` -> (levels (L,) float64, many): a real number or 0-d array, or a 1-D array-like."""
    if isinstance(c0, (bool, np.bool_)) or isinstance(c0, (str, bytes)):
        raise TypeError(f"Expected `c0` to be a real number or a 1-D array of levels, got {type(c0).__name__}")
    if isinstance(c0, (int, float, np.integer, np.floating)):
        arr = np.array([float(c0)])
        many = False
    else:
        try:
            arr = np.asarray(c0)
        except (TypeError, ValueError):
            raise TypeError(f"Expected `c0` to be a real number or a 1-D array of levels, got {type(c0).__name__}") from None
        if arr.dtype.kind not in "iuf" or arr.ndim > 1:
            what = f"shape {arr.shape}" if arr.ndim > 1 else f"dtype {arr.dtype}"
            raise (ValueError if arr.ndim > 1 else TypeError)(
                f"Expected `c0` to be a real number or a 1-D array of levels, got {what}")
        many = arr.ndim == 1
        arr = np.array(arr, dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)][0]
        raise ValueError(f"Expected `c0` to be finite, got {bad}")
    return arr, many


def _slice_level(t: _Tables, x: np.ndarray, m: np.ndarray, c0: float, radius: float) -> Slice:
    """One level, with the fallbacks for near-degenerate classifications."""
    try:
        return _slice(t, x, m, c0, t.tol)
    except _Inconsistent:
        pass
    # A face almost parallel to H but not within the tolerance: classify by exact
    # sign instead, then (never seen) nudge the hyperplane by a hair.
    try:
        return _slice(t, x, m, c0, 0.0)
    except _Inconsistent:
        return _slice(t, x, m, c0 + 1e-7 * radius, t.tol)


def _slice_many(t: _Tables, x: np.ndarray, m: np.ndarray, levels: np.ndarray, radius: float) -> tuple:
    """Every level of ``levels`` in one pass; see `slice_polytope`."""
    L = len(levels)
    out = [None] * L
    if L == 0:
        return ()
    tol = t.tol
    h = x[:, 3][None, :] - levels[:, None]  # (L, V), the same numbers as a single slice's h
    pos = h > tol
    neg = h < -tol
    n_pos = pos.sum(axis=1)
    n_neg = neg.sum(axis=1)
    # generic: every vertex strictly off H and some on each side (solid, no on-H cases)
    generic = (n_pos + n_neg == t.V) & (n_pos > 0) & (n_neg > 0)
    gi = generic.nonzero()[0]
    while len(gi):
        try:
            for i, s in zip(gi, _slice_generic(t, x, m, levels[gi], h[gi], pos[gi])):
                out[i] = s
        except _Inconsistent:
            for i in gi:
                out[i] = _slice_level(t, x, m, float(levels[i]), radius)
        except _NoCrossing as exc:  # pieces on both sides, none crossing: single path for those
            generic[gi[exc.levels]] = False
            gi = generic.nonzero()[0]
            continue
        break
    for i in (~generic).nonzero()[0]:
        out[i] = _slice_level(t, x, m, float(levels[i]), radius)
    return tuple(out)


def _scaled(t: _Tables, vertices: np.ndarray) -> np.ndarray:
    """Slice vertices from the unit vertices' scale back to the polytope's (exact: a power of 2)."""
    return vertices if t.unit == 1.0 else vertices * t.unit


def _scaled_volume(t: _Tables, volume):
    """A volume from the unit vertices' scale back to the polytope's: times unit**3, one factor at
    a time (a volume beyond float64's range becomes inf, or 0 below it; never nan)."""
    if t.unit == 1.0:
        return volume
    u = t.unit
    with np.errstate(over="ignore", under="ignore"):
        return volume * u * u * u


def _seal(a: np.ndarray) -> np.ndarray:
    """Make an array that owns its data read-only (views taken from it cannot be unlocked)."""
    a.flags.writeable = False
    return a


def _nonzero2(a: np.ndarray) -> tuple:
    """``a.nonzero()`` of a 2-D array, row-major (flatnonzero is several times faster)."""
    k = np.flatnonzero(a)
    row = k // a.shape[1]
    return row, k - row * a.shape[1]


def _slice_generic(t: _Tables, x: np.ndarray, m: np.ndarray, levels: np.ndarray, h: np.ndarray,
                   pos: np.ndarray) -> list:
    """Slices of G levels whose vertices are all strictly above or below H, some on each side.

    ``h`` (G, V) heights above each level, ``pos`` (G, V) h > tol (every other vertex is below).
    The steps and their order are `_slice`'s restricted to the crossing case with no vertex on H,
    done for all levels at once (arrays carry a level index, level-major), so each level's
    vertices, edges, polygons and triangles come out in the same order as its single slice.
    """
    G = len(h)
    ea, eb = t.ea, t.eb
    cross = pos[:, ea] != pos[:, eb]  # (G, E): with no vertex on H, one end above and one below
    lv, e_idx = _nonzero2(cross)  # level-major: each level's crossing edges in edge order
    n_v = np.bincount(lv, minlength=G)
    if not n_v.all():
        raise _NoCrossing(n_v == 0)
    voff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(n_v, out=voff[1:])
    a, b = ea[e_idx], eb[e_idx]
    ha = h[lv, a]
    s = (ha / (ha - h[lv, b]))[:, None]
    xa = x[a, :3]
    vertices = _seal(xa + s * (x[b, :3] - xa))
    edge_sv = np.full(cross.shape, -1, dtype=np.intp)  # (G, E) -> global slice-vertex index
    edge_sv[lv, e_idx] = np.arange(len(e_idx))

    # which faces and cells cross each level, from their w-ranges: min(w) - c0 is the min of
    # the h above (rounding is monotone), so this agrees with pos exactly
    w = x[:, 3]
    lev = levels[:, None]
    cross_pad = np.zeros((G, len(ea) + 1), dtype=bool)
    cross_pad[:, :-1] = cross
    flat_cross = cross_pad.ravel()
    stride = len(ea) + 1

    # edges of S: the chords of crossing 2-faces, their two crossing edges in face order
    wf = w[t.fv_vert]
    f_cross = (np.minimum.reduceat(wf, t.f_starts)[None, :] - lev < -t.tol) & (
        np.maximum.reduceat(wf, t.f_starts)[None, :] - lev > t.tol)
    lf, fc = _nonzero2(f_cross)
    fe = t.fe_pad[fc]
    hit = np.take(flat_cross, fe + (lf * stride)[:, None])
    rr, kk = _nonzero2(hit)
    if len(rr) != 2 * len(fc) or (rr[0::2] != rr[1::2]).any():
        raise _Inconsistent
    seg = edge_sv[lf[rr], fe[rr, kk]]
    seg -= voff[lf[rr]]
    edges = _seal(seg).reshape(-1, 2)
    eoff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(np.bincount(lf, minlength=G), out=eoff[1:])

    # polygons of S: one per crossing cell, its corners the cell's crossing edges (level-major,
    # cells in order, as `_slice` numbers them)
    wc = w[t.cv_vert]
    c_cross = (np.minimum.reduceat(wc, t.c_starts)[None, :] - lev < -t.tol) & (
        np.maximum.reduceat(wc, t.c_starts)[None, :] - lev > t.tol)
    p_level, cell_ids = _nonzero2(c_cross)
    ce = t.ce_pad[cell_ids]
    rank, kk = _nonzero2(np.take(flat_cross, ce + (p_level * stride)[:, None]))
    cell_of = cell_ids[rank]
    poly_sv = edge_sv[p_level[rank], ce[rank, kk]]
    n_poly = len(cell_ids)
    counts = np.bincount(rank, minlength=n_poly)
    starts = np.zeros(n_poly, dtype=np.intp)
    np.cumsum(counts[:-1], out=starts[1:])
    # corner mean of each polygon, coordinate by coordinate (bincount sums in entry order, as `_slice`)
    px = np.take(vertices[:, 0], poly_sv)
    py = np.take(vertices[:, 1], poly_sv)
    pz = np.take(vertices[:, 2], poly_sv)
    cx = np.bincount(rank, weights=px) / counts
    cy = np.bincount(rank, weights=py) / counts
    cz = np.bincount(rank, weights=pz) / counts
    # in-plane axes u, v of every cell's outward normal restricted to H (`_slice`'s formulas),
    # computed once per cell for all levels
    uv = _inplane_axes(t.cell_normals @ m[:3].T)
    uvr = np.take(uv, cell_of, axis=0)
    # d . u and d . v with `_slice`'s very expressions (the same rounding, so a corner on the
    # branch cut of the angle lands on the same side of it)
    d = np.stack([px - np.take(cx, rank), py - np.take(cy, rank), pz - np.take(cz, rank)], axis=1)
    cu = np.einsum("ij,ij->i", d, uvr[:, :3])
    cv = np.einsum("ij,ij->i", d, uvr[:, 3:])
    # a pseudo-angle strictly increasing with arctan2(cv, cu) on (-pi, pi] (same order, cheaper):
    # cv / (|cu| + |cv|) for cu >= 0, else +-2 minus it
    r = cv / (np.abs(cu) + np.abs(cv))
    ang = np.where(cu >= 0, r, np.copysign(2.0, cv) - r)
    # the corners of each polygon by angle, the same order as argsort(rank * 8 + ang) in
    # `_slice`: a polygon has at most K corners (a few), so each corner's place is the number
    # of corners of its polygon with a smaller angle, counted column by column
    K = int(counts.max())
    at = np.arange(len(rank)) - np.take(starts, rank)
    table = np.full((n_poly, K), np.inf)
    table[rank, at] = ang
    place = np.zeros((n_poly, K), dtype=np.intp)
    for k in range(K):
        place += table[:, k : k + 1] < table
    order = np.empty(len(rank), dtype=np.intp)
    order[np.take(starts, rank) + place[rank, at]] = np.arange(len(rank))
    flat = poly_sv[order]
    offsets = np.zeros(n_poly + 1, dtype=np.intp)
    np.cumsum(counts, out=offsets[1:])

    prank = rank[order]
    triangles, poly_of = _fan(flat, prank, offsets, counts)
    t_level = p_level[poly_of]
    triangle_cells = _seal(cell_ids[poly_of])

    # volume by the divergence theorem about each level's vertex centroid
    vsum = np.add.reduceat(vertices, voff[:-1], axis=0)
    centre = vsum / n_v[:, None]
    tri = np.take(vertices - np.take(centre, lv, axis=0), triangles.ravel(), axis=0).reshape(-1, 3, 3)
    A, B, D = tri[:, 0], tri[:, 1], tri[:, 2]
    six = (
        A[:, 0] * (B[:, 1] * D[:, 2] - B[:, 2] * D[:, 1])
        + A[:, 1] * (B[:, 2] * D[:, 0] - B[:, 0] * D[:, 2])
        + A[:, 2] * (B[:, 0] * D[:, 1] - B[:, 1] * D[:, 0])
    )
    volumes = np.bincount(t_level, weights=six, minlength=G) / 6.0

    # indices local to each level, then one Slice per level (views of the sealed arrays)
    triangles -= voff[t_level][:, None]
    _seal(triangles)
    flat -= voff[p_level[prank]]
    _seal(flat)
    _seal(cell_ids)
    poff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(np.bincount(p_level, minlength=G), out=poff[1:])
    toff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(np.bincount(t_level, minlength=G), out=toff[1:])
    if t.unit != 1.0:
        vertices = _seal(_scaled(t, vertices))
        volumes = _scaled_volume(t, volumes)
    out = []
    new = object.__new__
    for g in range(G):
        p0, p1, t0, t1 = poff[g], poff[g + 1], toff[g], toff[g + 1]
        # every array a view of a sealed one (read-only already) or sealed here: the fields are set
        # directly, without the frozen dataclass's per-field __setattr__ and __post_init__
        sl = new(Slice)
        sl.__dict__.update(
            vertices=vertices[voff[g] : voff[g + 1]], edges=edges[eoff[g] : eoff[g + 1]],
            polygon_indices=flat[offsets[p0] : offsets[p1]], polygon_offsets=_seal(offsets[p0 : p1 + 1] - offsets[p0]),
            cell_ids=cell_ids[p0:p1], triangles=triangles[t0:t1], triangle_cells=triangle_cells[t0:t1],
            volume=float(volumes[g]), dim=3,
        )
        out.append(sl)
    return out




def _fan(flat, prank, offsets, counts):
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

def _inplane_axes(n):
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

def _slice(t: _Tables, x: np.ndarray, m: np.ndarray, c0: float, tol: float) -> Slice:
    h = x[:, 3] - c0
    pos = h > tol
    neg = h < -tol
    on = ~(pos | neg)
    ea, eb = t.ea, t.eb
    crossing = bool(pos.any() and neg.any())
    on_idx = on.nonzero()[0]
    fv_on = on[t.fv_vert]
    c_on = np.logical_and.reduceat(on[t.cv_vert], t.c_starts) if len(on_idx) else None  # cells lying in H
    if crossing:
        cross_e = (pos[ea] & neg[eb]) | (neg[ea] & pos[eb])
        ce_idx = cross_e.nonzero()[0]
        a, b = ea[ce_idx], eb[ce_idx]
        ha = h[a]
        s = (ha / (ha - h[b]))[:, None]
        xa = x[a, :3]
        vertices = np.concatenate([xa + s * (x[b, :3] - xa), x[on_idx, :3]])
        n_e = len(ce_idx)
        edge_sv = np.full(len(ea), -1, dtype=np.intp)
        edge_sv[ce_idx] = np.arange(n_e)
        solid = True  # unless no polygon comes out: pieces of a polytope may lie apart, none crossing
    else:
        cross_e = None
        n_e = 0
        vertices = x[on_idx, :3]
        solid = bool(len(on_idx)) and bool(c_on.any())
    vert_sv = np.full(len(h), -1, dtype=np.intp)
    vert_sv[on_idx] = np.arange(n_e, n_e + len(on_idx))

    # edges of S: chords of crossing 2-faces, then polytope edges lying in H
    e_on = on[ea] & on[eb]
    in_h_edges = vert_sv[np.stack([ea[e_on], eb[e_on]], axis=1)] if e_on.any() else t.empty_i2
    if crossing:
        fv_pos = pos[t.fv_vert]
        fv_neg = neg[t.fv_vert]
        f_cross = np.logical_or.reduceat(fv_pos, t.f_starts) & np.logical_or.reduceat(fv_neg, t.f_starts)
        m1 = cross_e[t.fe_edge]
        m2 = fv_on & f_cross[t.fv_face]
        seg_face = np.concatenate([t.fe_face[m1], t.fv_face[m2]])
        seg_sv = np.concatenate([edge_sv[t.fe_edge[m1]], vert_sv[t.fv_vert[m2]]])
        order = np.argsort(seg_face, kind="stable")
        sf = seg_face[order]
        if len(sf) % 2 or (sf[0::2] != sf[1::2]).any():
            raise _Inconsistent
        edges = np.concatenate([seg_sv[order].reshape(-1, 2), in_h_edges])
    else:
        edges = in_h_edges

    f_on = np.logical_and.reduceat(fv_on, t.f_starts) if len(on_idx) else None  # faces lying in H
    if not solid:
        return _touching(t, vertices, edges, on_idx, f_on)

    # polygons of S: one per crossing cell, one per 2-face lying in H on the boundary of S
    C = t.C
    face_ids = f_on.nonzero()[0] if f_on is not None else t.empty_i
    if len(face_ids):
        abc = x[t.face_abc[face_ids], :3]  # (nf, 3, 3)
        fn = np.cross(abc[:, 1] - abc[:, 0], abc[:, 2] - abc[:, 1])
        keep, outward = _faces_in_h(t, x, m, face_ids, fn, c_on)
        face_ids, fn = face_ids[keep], fn[keep]
        fn[~outward[keep]] *= -1.0
        k3 = np.zeros(t.F, dtype=bool)
        k3[face_ids] = True
        k3 = k3[t.fv_face]
    else:
        fn = t.empty3
        k3 = np.zeros(len(t.fv_face), dtype=bool)
    if crossing:
        cv_pos = pos[t.cv_vert]
        cv_neg = neg[t.cv_vert]
        c_cross = np.logical_or.reduceat(cv_pos, t.c_starts) & np.logical_or.reduceat(cv_neg, t.c_starts)
        k1 = cross_e[t.ce_edge]
        k2 = on[t.cv_vert] & c_cross[t.cv_cell]
        poly_id = np.concatenate([t.ce_cell[k1], t.cv_cell[k2], C + t.fv_face[k3]])
        poly_sv = np.concatenate([edge_sv[t.ce_edge[k1]], vert_sv[t.cv_vert[k2]], vert_sv[t.fv_vert[k3]]])
        normals = np.empty((C + t.F, 3))
        normals[:C] = t.cell_normals @ m[:3].T  # outward normals of the cells, restricted to H
    else:
        poly_id = C + t.fv_face[k3]
        poly_sv = vert_sv[t.fv_vert[k3]]
        normals = np.empty((C + t.F, 3))
    if not len(poly_id):  # no cell crosses H and no face in H bounds a solid part
        return _touching(t, vertices, edges, on_idx, f_on)
    normals[C + face_ids] = fn

    present = np.bincount(poly_id, minlength=C + t.F)
    ids = present.nonzero()[0]
    counts = present[ids]
    n_poly = len(ids)
    rank_of = np.empty(C + t.F, dtype=np.intp)
    rank_of[ids] = np.arange(n_poly)
    rank = rank_of[poly_id]
    pts = vertices[poly_sv]
    # Angular order about each polygon's outward normal n, around its corner mean (each
    # polygon is a section of one convex cell, or a face: convex).
    # In-plane axes u = n x e_x (or n x e_y when n is near e_x) and v = n x u,
    # written out: they need not be unit, a linear map of positive determinant
    # keeps the cyclic order of directions.
    centres = np.empty((n_poly, 3))
    centres[:, 0] = np.bincount(rank, weights=pts[:, 0])
    centres[:, 1] = np.bincount(rank, weights=pts[:, 1])
    centres[:, 2] = np.bincount(rank, weights=pts[:, 2])
    centres /= counts[:, None]
    uv = _inplane_axes(normals[ids])
    d = pts - centres[rank]
    uvr = uv[rank]
    ang = np.arctan2(
        np.einsum("ij,ij->i", d, uvr[:, 3:]), np.einsum("ij,ij->i", d, uvr[:, :3])
    )
    order = np.argsort(rank * _TWO_PI_PLUS + ang)
    flat = poly_sv[order]
    offsets = np.zeros(n_poly + 1, dtype=np.intp)
    np.cumsum(counts, out=offsets[1:])

    cell_ids = ids.copy()
    if ids[-1] >= C:
        is_face = ids >= C
        fc = t.face_cells[ids[is_face] - C]
        # prefer a cell lying in H (the whole-cell case), else the lower-numbered one
        cell_ids[is_face] = np.where(c_on[fc[:, 1]] & ~c_on[fc[:, 0]], fc[:, 1], fc[:, 0])

    triangles, poly_of = _fan(flat, rank[order], offsets, counts)
    triangle_cells = cell_ids[poly_of]

    # volume by the divergence theorem, about the vertex centroid (keeps slivers exact)
    centre = vertices.sum(axis=0) / len(vertices)
    tri = (vertices - centre)[triangles]
    A, B, D = tri[:, 0], tri[:, 1], tri[:, 2]
    volume = float(
        (
            A[:, 0] * (B[:, 1] * D[:, 2] - B[:, 2] * D[:, 1])
            + A[:, 1] * (B[:, 2] * D[:, 0] - B[:, 0] * D[:, 2])
            + A[:, 2] * (B[:, 0] * D[:, 1] - B[:, 1] * D[:, 0])
        ).sum()
    ) / 6.0
    if len(on_idx):
        vertices, edges, flat, triangles = _boundary_only(vertices, edges, flat, offsets, triangles)
    return Slice(_scaled(t, vertices), edges, flat, offsets, cell_ids, triangles, triangle_cells,
                 _scaled_volume(t, volume), 3)


def _touching(t: _Tables, vertices, edges, on_idx, f_on) -> Slice:
    """A slice with no polygons: H touches P in faces (dim 2), edges (1) or vertices (0), or misses it."""
    if not len(on_idx):
        dim = -1
    else:
        dim = 2 if f_on.any() else (1 if len(edges) else 0)
    return Slice(_scaled(t, vertices), edges, t.empty_i, t.offsets0, t.empty_i, t.empty_i3, t.empty_i, 0.0, dim)


def _faces_in_h(t: _Tables, x: np.ndarray, m: np.ndarray, face_ids: np.ndarray, fn: np.ndarray, c_on: np.ndarray):
    """Which 2-faces lying in H bound the solid slice, and on which side of each is the outside.

    Seen in the plane orthogonal to face f (axes: its normal ``fn`` within H, and w), each of
    its two cells is a ray from f (towards the cell's centre) and the polytope fills the angle
    between the rays on the inner side of the first cell (against its outward normal).  A
    direction ±fn along H is *filled* when it lies strictly inside that angle or along a cell
    lying in H.  f is a polygon of S when exactly one of ±fn is filled, and its outward normal
    is the other one.  (A convex polytope cut through its interior always has one cell above
    and one below: the filled side is the one towards the interior.  A non-convex one may
    have both sides filled -- f inside S, at a reflex ridge or between two coplanar cells
    lying in H -- or neither.)

    Returns ``keep`` (nf,) bool and ``outward`` (nf,) bool: +fn is the outside.
    """
    fc = t.face_cells[face_ids]  # (nf, 2)
    corners = x[t.fv_vert[np.isin(t.fv_face, face_ids)]]
    fcount = np.diff(np.append(t.f_starts, len(t.fv_face)))[face_ids]
    owner = np.repeat(np.arange(len(face_ids)), fcount)
    p_f = np.stack([np.bincount(owner, weights=corners[:, k]) for k in range(4)], axis=1) / fcount[:, None]
    g = t.cell_centres[fc] @ m.T  # (nf, 2, 4) the two cells' centres, rotated
    r = g - p_f[:, None, :]
    ra = np.einsum("fcd,fd->fc", r[..., :3], fn)  # the rays in (fn, w) coordinates
    rb = np.where(c_on[fc], 0.0, r[..., 3])
    nrm = t.cell_normals[fc[:, 0]] @ m.T  # first cell's outward normal
    na, nb = np.einsum("fd,fd->f", nrm[:, :3], fn), nrm[:, 3]
    a1, b1, a2, b2 = ra[:, 0], rb[:, 0], ra[:, 1], rb[:, 1]
    ccw = a1 * (-nb) - b1 * (-na) > 0  # the polytope lies counter-clockwise from ray 1

    def angle(ax, ay, bx, by):  # counter-clockwise angle from a to b in [0, 2 pi)
        return np.mod(np.arctan2(ax * by - ay * bx, ax * bx + ay * by), 2 * np.pi)

    filled = []
    for sgn in (1.0, -1.0):
        ang1x, ang12 = angle(a1, b1, sgn, 0.0), angle(a1, b1, a2, b2)
        angx1, ang21 = angle(sgn, 0.0, a1, b1), angle(a2, b2, a1, b1)
        inside = np.where(ccw, (ang1x > 0) & (ang1x < ang12), (angx1 > 0) & (angx1 < ang21))
        along = (c_on[fc[:, 0]] & (np.sign(a1) == sgn)) | (c_on[fc[:, 1]] & (np.sign(a2) == sgn))
        filled.append(inside | along)
    plus, minus = filled
    return plus != minus, minus


def _boundary_only(vertices, edges, flat, offsets, triangles):
    """Drop the on-H vertices and in-H edges that no polygon uses (a solid slice of a non-convex
    polytope is given by its boundary: a face inside S, or P touching H away from S, adds none).

    A convex polytope's solid slice uses them all: then nothing changes (same arrays)."""
    n = len(vertices)
    used = np.zeros(n, dtype=bool)
    used[flat] = True
    nxt = np.arange(1, len(flat) + 1)
    nxt[offsets[1:] - 1] = offsets[:-1]
    sides = np.minimum(flat, flat[nxt]) * n + np.maximum(flat, flat[nxt])
    ekey = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
    side = np.isin(ekey, sides)
    if used.all() and side.all():
        return vertices, edges, flat, triangles
    new = np.cumsum(used) - 1
    return vertices[used], new[edges[side]], new[flat], new[triangles]
