"""The checks of an explicit mesh given to `Polytope(vertices, faces, cells)`, and its orientation.

`index_lists` reads the faces and cells (sequences of index sequences) into ragged tables,
`duplicate_in_rows` finds a repeated index; `mesh_geometry` checks the faces' and cells' geometry
(planar strictly convex faces, flat 3-D cells, closed and convex cells when asked) and derives
the outward cell normals from the boundary's orientation (a cavity, found by casting a ray, the
other way); a hemi or non-orientable polychoron has none, and loads flagged so (`StarData`).
Every failure is a `MeshError` naming the first offending face, cell or vertex.
Lengths are in the scale of the polytope's `Polytope.unit_vertices`; the tolerance is
`rot4d_widget.core.tolerances.MESH` times their largest extent.  Everything is vectorised.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..core import tolerances as tol_
from ._ragged import gather_rows, row_offsets, row_owners

__all__ = ["MeshError", "StarData", "index_lists", "duplicate_in_rows", "mesh_geometry"]


class MeshError(ValueError):
    """An explicit mesh given to `Polytope` is not a valid 4-polytope.

    ``item`` is the offending ``("face" | "cell" | "vertex", index)`` when there is one
    (the 4OFF reader turns it into a line number), else None.
    """

    def __init__(self, message: str, item: tuple | None = None):
        super().__init__(message)
        self.item = item


def index_lists(seq, what: str, item: str, n_max: int) -> tuple[np.ndarray, np.ndarray]:
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
        i = int(np.searchsorted(row_offsets(sizes), bad[0], side="right") - 1)
        raise MeshError(f"`{what}[{i}]` has {item} index {int(flat[bad[0]])}; expected integers 0 to {n_max - 1}",
                        item=("face" if what == "faces" else "cell", i))
    return sizes, flat


def duplicate_in_rows(ptr: np.ndarray, flat: np.ndarray, n: int):
    """First (row, value) that occurs twice in one row of a ragged table, or None."""
    key = row_owners(ptr) * n + flat
    s = np.sort(key)
    dup = np.flatnonzero(s[1:] == s[:-1])
    if len(dup):
        return int(s[dup[0]] // n), int(s[dup[0]] % n)
    return None


#: The loosest relative tolerance a mesh may be checked with (`Polytope(..., tolerance=)`).
MAX_TOLERANCE = 1e-2


def loosen_hint(off, extent) -> str:
    """How to accept a corner ``off`` from its plane on a mesh of ``extent`` (same units): the
    relative ``tolerance`` that would take it (its first significant digit rounded up, then
    doubled), e.g. for a file written with few digits; beyond `MAX_TOLERANCE` it is no rounding,
    and the hint says so instead of suggesting a tolerance that would be refused."""
    rel = 2.0 * float(off) / float(extent)
    digits = 10.0 ** np.floor(np.log10(rel))
    suggest = float(np.ceil(rel / digits) * digits)
    if suggest > MAX_TOLERANCE:
        return (f"; {float(off) / float(extent):.2g} of the mesh's extent is more than rounding (the loosest "
                f"tolerance allowed is {MAX_TOLERANCE:g}): a number in the file or the face's corners are wrong")
    return (f"; coordinates written with few digits (another program's file) load with a looser relative "
            f"tolerance, e.g. tolerance={suggest:.1g} (Polytope(..., tolerance=...), Polytope.from_off(path, "
            f"tolerance=...))")


def mesh_geometry(p, validate: bool, tolerance: float | None = None) -> tuple:
    """Check an explicit mesh's geometry: (outward cell normals, offsets, cell centres, number of
    boundary components, the tolerance used, `StarData` or None); lengths in the scale of
    ``p.unit_vertices``.  ``tolerance``: relative to the vertices' largest extent (None:
    `rot4d_widget.core.tolerances.MESH`).

    A polytope with no inside -- a hemi cell (one-sided, or its faces' oriented areas cancel) or a
    boundary that cannot be oriented (`StarData.volume_defined` False) -- is not refused: its cut is
    still defined.  Its normals are then a choice: an orientable component keeps its orientation
    (turned to positive divergence-theorem 4-volume where that is not 0), a cell of a component
    that cannot be oriented points away from the vertices' centroid (the SVD's sign where its
    hyperplane holds it), and a hemi cell's face normals are `_orient_cells`'; no cavity is looked
    for.  The slicer's even-odd cut does not depend on them; only which way round a section's
    cycles run does (and the volume, which is then None)."""
    v = p.unit_vertices
    V, F, C = len(v), len(p.incidence.face_ptr) - 1, len(p.incidence.cell_ptr) - 1
    extent = float(np.ptp(v, axis=0).max())
    tol = (tol_.MESH if tolerance is None else float(tolerance)) * extent
    if tol == 0:
        raise ValueError("`vertices` are all the same point")
    # distinct vertices
    key = np.round(v / tol).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    if len(first) < V:
        i = int(np.flatnonzero(first[inverse.reshape(-1)] != np.arange(V))[0])
        raise MeshError(f"vertices {int(first[inverse.reshape(-1)[i]])} and {i} coincide", item=("vertex", i))
    fptr, fv = p.incidence.face_ptr, p.incidence.face_vidx
    fsize = np.diff(fptr)
    face_c = np.empty((F, 4))
    face_e = np.empty((F, 2, 4))
    face_area = np.empty(F)
    face_convex = np.empty(F, dtype=bool)
    face_star = np.empty(F, dtype=bool)
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
            raise MeshError(f"face {f} is not planar: a corner is {off[bad[0]] * p.unit:.3g} from its plane "
                            f"(tolerance {tol * p.unit:.3g}){loosen_hint(off.max(), extent)}", item=("face", f))
        spread = np.abs(xy[..., 1]).max(axis=1)  # the second principal axis: 0 when collinear
        bad = np.flatnonzero(spread <= tol)
        if len(bad):
            f = int(fs[bad[0]])
            raise MeshError(f"face {f} {p.faces[f].tolist()} is degenerate: its corners are collinear",
                            item=("face", f))
        e = np.roll(xy, -1, axis=1) - xy  # side k: corner k -> k + 1
        e2 = np.roll(e, -1, axis=1)
        cross = e[..., 0] * e2[..., 1] - e[..., 1] * e2[..., 0]
        dot = (e * e2).sum(axis=2)
        chord = np.linalg.norm(e + e2, axis=2)
        dist = np.abs(cross) / np.maximum(chord, tol_.TINY)  # corner k + 1 from the line of its neighbours
        turning = np.arctan2(cross, dot).sum(axis=1)
        sign = np.sign(cross)
        convex = ((dist > tol).all(axis=1) & (sign == sign[:, :1]).all(axis=1)
                  & (np.abs(np.abs(turning) - 2 * np.pi) < 1))
        wind = np.rint(turning / (2 * np.pi)).astype(np.intp)  # the turning number: +-1 convex, +-2 a {5/2}
        bad = np.flatnonzero(~convex & (wind == 0))
        if len(bad):
            f = int(fs[bad[0]])
            raise MeshError(f"face {f} {p.faces[f].tolist()} is not a convex polygon in the order given, nor a "
                            f"star polygon: its sides turn through no net angle (a figure eight: two corners "
                            f"swapped?); faces must be polygons with their vertices in cyclic order",
                            item=("face", f))
        area2 = (xy[..., 0] * np.roll(xy[..., 1], -1, axis=1) - np.roll(xy[..., 0], -1, axis=1) * xy[..., 1]).sum(1)
        B[area2 < 0, 1] *= -1.0  # the plane's axes oriented so that the cycle winds positively
        face_c[fs] = c
        face_e[fs] = B
        face_area[fs] = 0.5 * np.abs(area2)  # a star's inner parts counted as often as the cycle winds round
        face_convex[fs] = convex
        face_star[fs] = np.abs(wind) >= 2
    if validate:  # before the cells' geometry: an open cell is a mistake in the lists, named as such
        _check_closed(p)
    # cells: flat, 3-D, normal
    cptr, cfx = p.incidence.cell_ptr, p.incidence.cell_fidx
    vptr, cvx = p.incidence.cell_vptr, p.incidence.cell_vidx
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
            raise MeshError(f"cell {c} does not lie in a hyperplane: a vertex is {off[bad[0]] * p.unit:.3g} "
                            f"from it (tolerance {tol * p.unit:.3g}){loosen_hint(off.max(), extent)}",
                            item=("cell", c))
        bad = np.flatnonzero(s[:, 2] <= tol)
        if len(bad):
            raise MeshError(f"cell {int(cs[bad[0]])} is degenerate: its vertices span less than 3-D",
                            item=("cell", int(cs[bad[0]])))
        g[cs] = gc
        n[cs] = normal
    pc = row_owners(cptr)  # the (cell, face) pairs, cell by cell
    pf = cfx
    m = face_c[pf] - g[pc]
    for basis in (n[pc], face_e[pf, 0], face_e[pf, 1]):
        m -= np.einsum("id,id->i", m, basis)[:, None] * basis
    height = np.linalg.norm(m, axis=1)  # the cell's centroid from each face's plane, in the cell
    # a cell is convex when its faces are and every vertex lies on the inner side of every face; a
    # face whose plane holds the cell's vertex centre (a hemi-polyhedron's) makes it non-convex: a
    # strictly convex 3-D cell has its centre strictly inside
    cell_convex = ~np.logical_or.reduceat(~face_convex[pf] | (height <= tol), cptr[:-1])
    m /= np.maximum(height, tol_.TINY)[:, None]  # each face's outward normal within each of its cells
    if validate:
        cell_convex &= _convex_cells(p, v, tol, pc, pf, m, face_c, cell_convex)
    cell_star = hemi = one_sided = np.zeros(C, dtype=bool)
    if not cell_convex.all():  # outward normals from the faces' orientation, not from the centre
        cell_star, hemi, one_sided = _orient_cells(p, v, tol, n, g, pc, pf, m, face_e, face_c, face_area,
                                                   cell_convex)
    # orientation: the sign of det[n_c, m_cf, plane of f] relates the two cells of each face
    sigma = np.sign(np.linalg.det(np.stack([n[pc], m, face_e[pf, 0], face_e[pf, 1]], axis=1)))
    order = np.argsort(pf, kind="stable")
    c1, c2 = pc[order[0::2]], pc[order[1::2]]
    same = -sigma[order[0::2]] * sigma[order[1::2]] > 0  # s_c1 == s_c2 for a consistent orientation
    a = np.concatenate([c1, c1 + C])
    b = np.concatenate([np.where(same, c2, c2 + C), np.where(same, c2 + C, c2)])
    _, lab = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(2 * C, 2 * C)), directed=False)
    twisted = lab[:C] == lab[C:]  # cells of a boundary component that cannot be oriented
    orientable = not (twisted.any() or one_sided.any())
    defined = orientable and not hemi.any()  # else no inside: no outward side, no volume (StarData)
    s = np.where(lab[:C] < lab[C:], 1.0, -1.0)
    # where it cannot be oriented, each cell's normal points away from the vertices' centroid (the
    # SVD's sign where its hyperplane holds the centroid): a choice, consistent only cell by cell
    away = np.einsum("cd,cd->c", n, g - v.mean(axis=0))
    s[twisted] = np.where(away[twisted] < -tol, -1.0, 1.0)
    ncomp, comp = connected_components(coo_matrix((np.ones(F), (c1, c2)), shape=(C, C)), directed=False)
    # each cell's 3-volume (winding-weighted for a star cell): the divergence theorem over its faces
    vol3 = np.bincount(pc, weights=face_area[pf] * np.einsum("id,id->i", face_c[pf] - g[pc], m), minlength=C) / 3.0
    offsets = np.einsum("cd,cd->c", n, g)
    vol4 = np.bincount(comp, weights=s * offsets * vol3, minlength=ncomp) / 4.0
    small = np.abs(vol4) <= tol * tol * tol * tol
    if defined and small.any():
        raise MeshError(f"the boundary component of cell {int(np.flatnonzero(comp == np.argmax(small))[0])} "
                        f"encloses no 4-volume")
    flip = (vol4 < 0) & ~small
    if defined and ncomp > 1:
        flip ^= _cavities(n * s[:, None], offsets * s, g, comp, ncomp, pc, pf, m, face_c)
    flip &= ~np.bincount(comp, weights=twisted, minlength=ncomp).astype(bool)  # "away" is kept there
    s = np.where(flip[comp], -s, s)
    normals = np.ascontiguousarray(n * s[:, None])
    star = None
    if not (cell_convex.all() and defined):
        # the direction of each face's chord along w = c0 in each of its cells (slicer): -sign det[n, m, e0, e1]
        rho = -(s[pc] * sigma).astype(np.intp)
        star = StarData(face_convex=face_convex, cell_convex=cell_convex, face_star=face_star, cell_star=cell_star,
                        face_basis=face_e, pair_rho=rho, hemi_cells=hemi, orientable=orientable)
    return normals, np.ascontiguousarray(offsets * s), g, ncomp, tol, star


@dataclass(frozen=True)
class StarData:
    """What the slicer of a polytope with a non-convex face or cell needs (`Polytope.star`).

    face_convex (F,), cell_convex (C,) : strictly convex (a cell: its faces too, and every vertex
        on the inner side of each face's plane)
    face_star (F,) : the face winds round some point more than once (a {5/2}, {8/3})
    cell_star (C,) : the cell's faces wind round its vertex centre more than once (a star polyhedron)
    face_basis (F, 2, 4) : orthonormal axes of each face's plane (unit vertices' scale), oriented so
        that the face's cycle winds positively
    pair_rho (P,) : for each (cell, face) entry of ``incidence.cell_fidx``, +-1: the face's chord
        along a hyperplane runs along ``e1 * (e0 . w) - e0 * (e1 . w)`` (rho = +1) or against it,
        as the boundary of the cell's section seen from its outward normal
    hemi_cells (C,) : the cell is a hemi-polyhedron: its faces are one-sided (no orientation of
        them agrees across every edge) or enclose no volume (their oriented areas cancel, as some
        pass through its centre): it has no inside, so neither has the polytope
    orientable : the boundary can be oriented (no one-sided cell, and the cells' orientations agree
        across every face).  When it cannot, or some cell is hemi, there is no volume to measure
        (`volume_defined` False, `Polytope.volume_defined`): the normals and ``pair_rho`` are then
        a choice (`mesh_geometry`), and the slices' volume is None; their cut is the same even-odd
        one as a star's
    """

    face_convex: np.ndarray
    cell_convex: np.ndarray
    face_star: np.ndarray
    cell_star: np.ndarray
    face_basis: np.ndarray
    pair_rho: np.ndarray
    hemi_cells: np.ndarray
    orientable: bool = True

    @property
    def volume_defined(self) -> bool:
        """The polytope has an inside to measure: its boundary is orientable and no cell is hemi."""
        return self.orientable and not bool(self.hemi_cells.any())

    @property
    def why_no_volume(self) -> str | None:
        """``"not orientable"``, ``"hemi cells"`` or None (the volume is defined)."""
        if not self.orientable:
            return "not orientable"
        return "hemi cells" if self.hemi_cells.any() else None


def _check_closed(p) -> None:
    """Every cell closed: each of its edges in exactly two of its faces (MeshError naming the cell)."""
    open_ = np.flatnonzero(p.incidence.cell_ecount != 2)
    if len(open_):
        i = int(open_[0])
        c = int(np.searchsorted(p.incidence.cell_eptr, i, side="right") - 1)
        e = p.edges[p.incidence.cell_eidx[i]].tolist()
        raise MeshError(f"cell {c} is not closed: its edge {tuple(e)} is in {p.incidence.cell_ecount[i]} of its faces; "
                        f"each edge of a cell must be in exactly two of its faces", item=("cell", c))


def _convex_cells(p, v, tol, pc, pf, m, face_c, candidate=None) -> np.ndarray:
    """(C,) bool: the cell is one of the ``candidate`` (C,) cells (None: all) and convex (every vertex on the
    inner side of each face's plane).

    A convex cell must also be strictly convex: only a face's own corners on its plane (else a
    MeshError naming the cell: two coplanar faces).  A non-convex cell may have coplanar faces."""
    cptr, vptr, cvx = p.incidence.cell_ptr, p.incidence.cell_vptr, p.incidence.cell_vidx
    nf, nv = np.diff(cptr), np.diff(vptr)
    fsize = np.diff(p.incidence.face_ptr)
    out_c = np.zeros(len(nf), dtype=bool)
    kinds, kind = np.unique(nf * (nv.max() + 1) + nv, return_inverse=True)
    for j in range(len(kinds)):
        cells_j = np.flatnonzero((kind.reshape(-1) == j) & (True if candidate is None else candidate))
        if not len(cells_j):
            continue
        q, k = int(nf[cells_j[0]]), int(nv[cells_j[0]])
        step = max(1, 2_000_000 // (q * k))
        for lo in range(0, len(cells_j), step):
            cs = cells_j[lo : lo + step]
            P = v[cvx[vptr[cs][:, None] + np.arange(k)]]  # (n, k, 4)
            pairs = cptr[cs][:, None] + np.arange(q)  # (n, q)
            M = m[pairs]
            D = M @ P.transpose(0, 2, 1) - np.einsum("nqd,nqd->nq", M, face_c[pf[pairs]])[..., None]
            convex = ~(D > tol).any(axis=(1, 2))
            out_c[cs] = convex
            on = (D >= -tol).sum(axis=2)
            wrong = (on != fsize[pf[pairs]]) & convex[:, None]
            if wrong.any():
                i, j2 = np.argwhere(wrong)[0]
                raise MeshError(f"cell {int(cs[i])} is not strictly convex: a vertex that is not a corner of its "
                                f"face {int(pf[pairs[i, j2]])} lies in that face's plane (two coplanar faces?)",
                                item=("cell", int(cs[i])))
    return out_c


def _cross4(a, b, c):
    """(n, 4) x3 -> (n, 4): the vector x with ``x . y = det[y, a, b, c]`` for every y."""
    M = np.stack([a, b, c], axis=1)  # (n, 3, 4)
    cols = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]
    return np.stack([(-1) ** k * np.linalg.det(M[:, :, cols[k]]) for k in range(4)], axis=1)


def _orient_cells(p, v, tol, n, g, pc, pf, m, face_e, face_c, face_area, cell_convex) -> np.ndarray:
    """Outward face normals ``m`` (written in place) of the non-convex cells, from their faces' orientation.

    Within each such cell the faces are oriented alike (every edge run through in opposite directions
    by its two faces, propagated as connected components), and each connected set of faces is turned
    so that it encloses positive (winding-weighted) volume; ``m`` of a face is then its plane's normal
    within the cell, signed by that orientation (for a convex cell it is the centroid's rule).
    A hemi-polyhedron has no such orientation: its faces are one-sided (no signs agree across every
    edge: the tetrahemihexahedron) or two-sided but enclosing no volume (their oriented areas cancel:
    the octahemioctahedron).  Its ``m`` are then signed as far as the faces' orientation goes, the
    rest (and the sign of a cancelling set) +1 times ``nu`` (det[n, nu, e0, e1] > 0: from the face's
    cycle): a choice, documented, that the slicer's even-odd cut does not depend on.
    Returns three (C,) bool: the cell winds round its vertex centre more than once (a star
    polyhedron); the cell is hemi (one-sided or enclosing no volume); the cell is one-sided."""
    inc = p.incidence
    C, E = len(cell_convex), len(p.edges)
    sel = np.flatnonzero(~cell_convex[pc])  # the (cell, face) entries of non-convex cells
    P = len(sel)
    idx, row = gather_rows(inc.face_ptr, pf[sel])
    nxt = idx + 1
    ends = np.isin(nxt, inc.face_ptr[1:])
    nxt[ends] = inc.face_ptr[:-1][np.searchsorted(inc.face_ptr, idx[ends], side="right") - 1]
    direction = np.where(inc.face_vidx[idx] < inc.face_vidx[nxt], 1, -1)
    key = pc[sel][row] * E + inc.face_eidx[idx]
    order = np.argsort(key, kind="stable")
    k1, k2 = order[0::2], order[1::2]
    if len(order) % 2 or (key[k1] != key[k2]).any():
        c = int(pc[sel][row][order[0]])
        raise MeshError(f"cell {c} is not closed: an edge is not in exactly two of its faces", item=("cell", c))
    i, j = row[k1], row[k2]
    same = direction[k1] != direction[k2]  # then the two faces keep the same sign
    a = np.concatenate([i, i + P])
    b = np.concatenate([np.where(same, j, j + P), np.where(same, j + P, j)])
    _, lab = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(2 * P, 2 * P)), directed=False)
    twisted = lab[:P] == lab[P:]  # the faces of a one-sided set (a hemi-polyhedron's)
    one_sided = np.zeros(C, dtype=bool)
    one_sided[pc[sel[twisted]]] = True
    s0 = np.where(twisted | (lab[:P] < lab[P:]), 1.0, -1.0)
    comp = np.unique(np.minimum(lab[:P], lab[P:]), return_inverse=True)[1].reshape(-1)
    cs, fs = pc[sel], pf[sel]
    nu = _cross4(n[cs], face_e[fs, 0], face_e[fs, 1])
    nu /= -np.linalg.norm(nu, axis=1)[:, None]  # det[n, nu, e0, e1] > 0
    part = s0 * face_area[fs] * np.einsum("id,id->i", face_c[fs] - g[cs], nu) / 3.0
    vol = np.bincount(comp, weights=part)
    cancel = np.abs(vol) <= tol * tol * tol  # (a one-sided set's "volume" has no meaning: counted here too)
    cancel[np.unique(comp[twisted])] = True
    hemi = np.zeros(C, dtype=bool)
    hemi[cs[cancel[comp]]] = True
    s = s0 * np.where(cancel, 1.0, np.sign(vol))[comp]
    m[sel] = s[:, None] * nu
    # the winding number of each cell's faces about its vertex centre: solid angles of their fans
    fptr = inc.face_ptr
    size = fptr[fs + 1] - fptr[fs]
    tri_row = np.repeat(np.arange(P), size - 2)
    first = row_offsets(size - 2)
    kk = np.arange(first[-1]) - first[tri_row] + 1
    base = fptr[fs][tri_row]
    q0, q1, q2 = (v[inc.face_vidx[base + o]] - g[cs][tri_row] for o in (0 * kk, kk, kk + 1))
    triple = np.linalg.det(np.stack([n[cs][tri_row], q0, q1, q2], axis=1))
    l0, l1, l2 = (np.linalg.norm(q, axis=1) for q in (q0, q1, q2))
    den = (l0 * l1 * l2 + np.einsum("id,id->i", q0, q1) * l2 + np.einsum("id,id->i", q0, q2) * l1
           + np.einsum("id,id->i", q1, q2) * l0)
    omega = 2 * np.arctan2(triple, den) * s[tri_row]
    # det[n, nu, e0, e1] > 0 and the fans wind as the cycle (positively in e0, e1): signs agree
    wind = np.bincount(cs[tri_row], weights=omega, minlength=C) / (4 * np.pi)
    return np.abs(np.rint(wind)) >= 2, hemi, one_sided


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
    t = (offsets[None, :] - q @ normals.T) / np.where(np.abs(nr) > tol_.TINY, nr, tol_.TINY)[None, :]  # (K, C)
    hit_pt = q[:, None, :] + t[..., None] * r  # (K, C, 4)
    for k in range(ncomp):
        x = hit_pt[k]  # (C, 4)
        inside_face = np.einsum("id,id->i", x[pc] - face_c[pf], m) <= 0
        inside = np.logical_and.reduceat(inside_face, np.searchsorted(pc, np.arange(C)))
        ok = inside & (t[k] > 0) & (comp != k) & (np.abs(nr) > tol_.PARALLEL)
        crossings = np.bincount(comp[ok], minlength=ncomp)
        depth[k] = int((crossings % 2).sum())
    return depth % 2 == 1


_check_cells = _convex_cells  # its name before non-convex cells were accepted (re-exported by polytopes)
