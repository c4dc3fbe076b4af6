"""The batched slicer: many parallel hyperplanes w = c0_i in one pass (trimesh's ``mesh_multiplane``).

The vertices are rotated once, every vertex is classified against every level in one (L, V)
comparison, the crossing faces and cells of all levels come from their w-ranges, and the single
slicer's steps run on arrays that carry a level index; each level's `Slice` is a read-only view of
the shared arrays, equal to the single slice at that level.  Levels within the tolerance of a
vertex height (the on-H cases), and levels with vertices on both sides but no crossing edge (a
polytope in pieces), take the single slicer (`rot4d_widget.geometry.slicing.single_level`).
"""

from __future__ import annotations

import numpy as np

from ...core._arrays import sealed as _sealed
from .single_level import slice_level
from .tables import Inconsistent, Slice, SliceTables, fan, inplane_axes, scaled, scaled_volume

__all__: list = []


class _NoCrossing(Exception):
    """Levels with vertices on both sides but no crossing edge (a polytope in separate pieces)."""

    def __init__(self, levels: np.ndarray):
        super().__init__()
        self.levels = levels


def slice_many(t: SliceTables, x: np.ndarray, m: np.ndarray, levels: np.ndarray, radius: float) -> tuple:
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
        except Inconsistent:
            for i in gi:
                out[i] = slice_level(t, x, m, float(levels[i]), radius)
        except _NoCrossing as exc:  # pieces on both sides, none crossing: single path for those
            generic[gi[exc.levels]] = False
            gi = generic.nonzero()[0]
            continue
        break
    for i in (~generic).nonzero()[0]:
        out[i] = slice_level(t, x, m, float(levels[i]), radius)
    return tuple(out)


def _nonzero2(a: np.ndarray) -> tuple:
    """``a.nonzero()`` of a 2-D array, row-major (flatnonzero is several times faster)."""
    k = np.flatnonzero(a)
    row = k // a.shape[1]
    return row, k - row * a.shape[1]


def _slice_generic(t: SliceTables, x: np.ndarray, m: np.ndarray, levels: np.ndarray, h: np.ndarray,
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
    vertices = _sealed(xa + s * (x[b, :3] - xa))
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
        raise Inconsistent
    seg = edge_sv[lf[rr], fe[rr, kk]]
    seg -= voff[lf[rr]]
    edges = _sealed(seg).reshape(-1, 2)
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
    uv = inplane_axes(t.cell_normals @ m[:3].T)
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
    triangles, poly_of = fan(flat, prank, offsets, counts)
    t_level = p_level[poly_of]
    triangle_cells = _sealed(cell_ids[poly_of])

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
    triangles = _sealed(triangles)
    flat -= voff[p_level[prank]]
    flat = _sealed(flat)
    cell_ids = _sealed(cell_ids)
    poff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(np.bincount(p_level, minlength=G), out=poff[1:])
    toff = np.zeros(G + 1, dtype=np.intp)
    np.cumsum(np.bincount(t_level, minlength=G), out=toff[1:])
    if t.unit != 1.0:
        vertices = _sealed(scaled(t, vertices))
        volumes = scaled_volume(t, volumes)
    out = []
    new = object.__new__
    for g in range(G):
        p0, p1, t0, t1 = poff[g], poff[g + 1], toff[g], toff[g + 1]
        # every array a view of a sealed one (read-only already) or sealed here: the fields are set
        # directly, without the frozen dataclass's per-field __setattr__ and __post_init__
        sl = new(Slice)
        sl.__dict__.update(
            vertices=vertices[voff[g] : voff[g + 1]], edges=edges[eoff[g] : eoff[g + 1]],
            polygon_indices=flat[offsets[p0] : offsets[p1]],
            polygon_offsets=_sealed(offsets[p0 : p1 + 1] - offsets[p0]),
            cell_ids=cell_ids[p0:p1], triangles=triangles[t0:t1], triangle_cells=triangle_cells[t0:t1],
            volume=float(volumes[g]), dim=3,
        )
        out.append(sl)
    return out
