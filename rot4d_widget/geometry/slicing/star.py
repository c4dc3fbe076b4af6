"""The general slicer: a polytope with star faces or non-convex (star) cells cut by w = c0.

`Polytope.star` is not None (some face is not a convex polygon or some cell not a convex
polyhedron, or the polytope has no inside): `rot4d_widget.geometry.slicing` sends every level
here.  The slice's points are the edges' crossings of H; a face's crossings sorted along its line
are paired by the even-odd rule into segments; each cell's section is the cycles its segments
chain into, fanned when the cell is convex and otherwise filled even-odd (from centroids, by
`rot4d_widget.geometry.slicing.even_odd_fill`, or by slabs: extra corners after the slice's
points, `Slice.n_fill`); the volume is winding-weighted.  A vertex on H counts as just above it
for all of these, yet every vertex on H and edge in H is in the slice.  Per level no Python loop
over geometry (per-polytope tables built once).  The rules and why: docs/design.md, "Slicing
polytopes" (Star faces and non-convex cells).
"""

from __future__ import annotations

import weakref

import numpy as np

from ...core import tolerances as tol_
from .._ragged import row_offsets
from .even_odd_fill import arrangement_fill, upper_pairs
from .single_level import touching
from .tables import Inconsistent, Slice, SliceTables, fan, inplane_axes, scaled, scaled_volume

__all__: list = []


class _StarTables:
    """What the general slicer adds to `tables.SliceTables`, once per polytope."""

    def __init__(self, p, t: SliceTables):
        st = p.star
        inc = p.incidence
        n = len(inc.face_vidx)
        nxt = np.arange(1, n + 1, dtype=np.intp)
        nxt[inc.face_ptr[1:] - 1] = inc.face_ptr[:-1]
        self.fv_next = nxt  # the next corner of each face corner's cycle
        order = np.argsort(inc.cell_fidx, kind="stable")  # each face's two (cell, face) entries, cells ascending
        self.face_rho = st.pair_rho[order].reshape(-1, 2).astype(np.float64)  # aligned with p.face_cells
        self.face_basis = st.face_basis
        self.cell_convex = st.cell_convex
        # no star face: fill the crossing sections first (see `_cut`; only the speed depends on it)
        self.crossing_first = not np.any(st.face_star)
        # each (face side k, cell j of the face) slot 2k + j: the slot of the other face of that cell
        # at that edge (a closed cell has two faces at each of its edges), -1 where it has not one
        E = len(p.edges)
        key = (p.face_cells[t.fe_face] * E + t.fe_edge[:, None]).ravel()
        o = np.argsort(key, kind="stable")
        ks = key[o]
        new = np.ones(len(ks), dtype=bool)
        new[1:] = ks[1:] != ks[:-1]
        size = np.diff(np.append(np.flatnonzero(new), len(ks)))[np.cumsum(new) - 1]
        pos = np.arange(len(ks)) - np.flatnonzero(new)[np.cumsum(new) - 1]
        mate = np.where(size == 2, o[np.minimum(np.arange(len(ks)) + 1 - 2 * pos, len(ks) - 1)], -1)
        self.slot_mate = np.empty(len(ks), dtype=np.intp)
        self.slot_mate[o] = mate


_STAR: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def star_tables(p, t: SliceTables) -> _StarTables:
    s = _STAR.get(p)
    if s is None:
        s = _STAR[p] = _StarTables(p, t)
    return s


def slice_star(p, t: SliceTables, x: np.ndarray, m: np.ndarray, c0: float) -> Slice:
    """One level of a polytope with star faces or non-convex cells (docs/design.md, "Slicing polytopes")."""
    st = star_tables(p, t)
    h = x[:, 3] - c0
    on = np.abs(h) <= t.tol
    out = None
    for nudge in (0.0, tol_.NUDGE * t.radius, -tol_.NUDGE * t.radius):  # a hair off, if rounding disagrees
        try:
            if nudge:
                h = x[:, 3] - (c0 + nudge)
                on = np.abs(h) <= t.tol
            out = _cut(st, t, x, m, h, on, 1)
            if on.any() and np.logical_and.reduceat(on[t.cv_vert], t.c_starts).any():
                other = _cut(st, t, x, m, h, on, -1)
                if other is not None and (out is None or abs(other.volume) > abs(out.volume)):
                    out = other
            break
        except Inconsistent:
            continue
    if out is not None:
        return out
    on_idx = on.nonzero()[0]
    vert = np.full(len(h), -1, dtype=np.intp)
    vert[on_idx] = np.arange(len(on_idx))
    e_on = on[t.ea] & on[t.eb]
    edges = np.stack([vert[t.ea[e_on]], vert[t.eb[e_on]]], axis=1) if e_on.any() else t.empty_i2
    f_on = np.logical_and.reduceat(on[t.fv_vert], t.f_starts)
    return touching(t, x[on_idx, :3], edges, on_idx, f_on)


def _cut(st: _StarTables, t: SliceTables, x, m, h, on, side: int):
    """The slice with the vertices on H counted above (``side`` 1) or below (-1); None if no edge crosses."""
    above = (h > 0) & ~on if side < 0 else (h > 0) | on
    cross = above[t.ea] != above[t.eb]
    ce = np.flatnonzero(cross)
    if not len(ce):
        return None
    a, b = t.ea[ce], t.eb[ce]
    ha, hb = h[a], h[b]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(on[a], 0.0, np.where(on[b], 1.0, ha / (ha - hb)))
    xa = x[a, :3]
    dx = x[b, :3] - xa
    pts = xa + s[:, None] * dx
    dpdc = dx / (x[b, 3] - x[a, 3])[:, None]  # how a crossing moves with the level (ties on H)
    cid = np.full(len(t.ea), -1, dtype=np.intp)
    cid[ce] = np.arange(len(ce))
    # one slice vertex per crossing point, then every vertex on H (a vertex of S, whether or not an
    # edge crosses at it: one whose neighbours are all on the side it is counted on has none), in
    # vertex order; the crossings at a vertex on H merged into it.  No sort
    on_idx = np.flatnonzero(on)
    vid = np.arange(len(ce))
    vnum = None
    if len(on_idx):
        at_v = np.where(on[a], a, np.where(on[b], b, -1))
        own = at_v < 0
        vid = np.cumsum(own) - 1
        vnum = np.full(len(h), -1, dtype=np.intp)
        vnum[on_idx] = int(own.sum()) + np.arange(len(on_idx))
        vid[~own] = vnum[at_v[~own]]
        vertices = np.concatenate([pts[own], x[on_idx, :3]])
    else:
        vertices = pts

    # each crossing face's points along its line w = c0, sorted; paired even-odd
    ks = np.flatnonzero(cross[t.fe_edge])
    fk = t.fe_face[ks]
    pk = cid[t.fe_edge[ks]]
    delta = np.where(above[t.fv_vert[st.fv_next[ks]]], 1, -1)  # +1 where the side rises through H
    newf = np.ones(len(fk), dtype=bool)
    newf[1:] = fk[1:] != fk[:-1]  # fk ascending (face sides in face order)
    uf = fk[newf]
    cnt = np.diff(np.append(np.flatnonzero(newf), len(fk)))
    if (cnt % 2).any():
        raise Inconsistent
    rb = (st.face_basis[uf].reshape(-1, 4) @ m.T).reshape(-1, 2, 4)  # (nf, 2, 4) each face's plane, rotated
    d = rb[:, 1, :3] * rb[:, 0, 3:4] - rb[:, 0, :3] * rb[:, 1, 3:4]  # the line's direction (J grad w)
    two = len(fk) == 2 * len(uf)  # every face cut twice (convex faces always are)
    if two:  # each pair in order along its line; equal positions (a vertex on H) as they move
        t0, t1 = np.einsum("ij,ij->i", pts[pk[0::2]], d), np.einsum("ij,ij->i", pts[pk[1::2]], d)
        swap = t0 > t1
        eq = np.flatnonzero(t0 == t1)
        if len(eq):
            z = -side * np.einsum("ijk,ik->ij", dpdc[pk.reshape(-1, 2)[eq]], d[eq])
            swap[eq] = z[:, 0] > z[:, 1]
        order = np.empty(len(fk), dtype=np.intp)
        order[0::2] = np.arange(0, len(fk), 2) + swap
        order[1::2] = order[0::2] ^ 1
        fr = None
    else:  # by face, then along its line: a float sort, then a stable (radix) one by face
        fr = np.repeat(np.arange(len(uf)), cnt)
        dfr = d[fr]
        tpos = np.einsum("ij,ij->i", pts[pk], dfr)
        order = np.argsort(tpos)
        order = order[np.argsort(fr[order].astype(np.uint16) if len(uf) < 65536 else fr[order], kind="stable")]
        if (tpos[order[1:]] == tpos[order[:-1]]).any():  # equal positions (a vertex on H): ordered as it moves
            tie = -side * np.einsum("ij,ij->i", dpdc[pk], dfr)
            order = np.lexsort((tie, tpos, fr))
    pk, delta = pk[order], delta[order]
    seg = pk.reshape(-1, 2)  # even-odd: 1st-2nd, 3rd-4th, ... of each face (counts are even)
    seg_face = uf if two else uf[fr[0::2]]
    fcells = t.face_cells[seg_face]  # (ns, 2)

    # volume: winding-weighted stretches of every crossing face, in both its cells
    if two:  # a face cut twice winds once round its one stretch, the segment
        W0 = Wi = delta[0::2]
        fi, P, Q = seg_face, pts[seg[:, 0]], pts[seg[:, 1]]
    else:
        W = np.cumsum(delta)
        ptr = row_offsets(cnt)
        base = np.zeros(len(uf), dtype=W.dtype)
        base[1:] = W[ptr[1:-1] - 1]
        W = W - base[fr]
        W0 = W[0::2]  # the winding along each segment
        last = np.zeros(len(pk), dtype=bool)
        last[ptr[1:] - 1] = True
        i = np.flatnonzero(~last & (W != 0))
        Wi, fi, P, Q = W[i], uf[fr[i]], pts[pk[i]], pts[pk[i + 1]]
    centre = vertices.mean(axis=0)
    anchor = np.zeros((t.C, 3))
    anchor[fcells.ravel()] = np.repeat(pts[seg[:, 0]], 2, axis=0) - centre
    PxQ = _cross(P - centre, Q - centre)
    vol = float((Wi[:, None] * st.face_rho[fi] * np.einsum("ijk,ik->ij", anchor[t.face_cells[fi]], PxQ)).sum())
    volume = vol / 6.0

    # cycles of each cell: chain the segments' ends at the crossing points (pointer jumping)
    ns = len(seg)
    rec_cell = fcells.ravel()
    rec_seg = np.repeat(np.arange(ns), 2)
    end_cell = np.repeat(rec_cell, 2)
    end_pt = seg[rec_seg].ravel()
    n_end = len(end_pt)
    # the two ends at each (cell, crossing edge): the other face of the cell at that edge
    # (`_StarTables.slot_mate`), found by the face side's place in the sorted sides, no search
    side = ks[order]  # the face side of each sorted crossing: end n of record r is side[2 (r >> 1) + (n & 1)]
    at = np.full(len(t.fe_edge), -1, dtype=np.intp)
    at[side] = np.arange(len(side))
    q = np.arange(n_end)
    mate = st.slot_mate[2 * side[((q >> 2) << 1) + (q & 1)] + ((q >> 1) & 1)]
    q2 = at[mate >> 1]
    partner = 4 * (q2 >> 1) + 2 * (mate & 1) + (q2 & 1)
    if (mate < 0).any() or (q2 < 0).any() or (partner == q).any() or (partner[partner] != q).any():
        raise Inconsistent
    nxt = partner ^ 1  # along the other segment at this point, to its far end
    lab = np.arange(n_end)
    J = nxt.copy()
    # an orbit stays in its cell: no longer than the cell's records (one end of each)
    rounds = max(1, int(np.ceil(np.log2(max(2, int(np.bincount(rec_cell).max()))))) + 1)
    for _ in range(rounds):
        lab = np.minimum(lab, lab[J])
        J = J[J]
    normals = t.cell_normals @ m[:3].T  # (C, 3) each cell's outward normal, restricted to H
    # each cycle run the way its segments bound the cell's section (rho times the sign of the face's
    # winding along the segment: for faces winding at most once every segment then runs opposite
    # ways in its two cells' cycles); by signed area where they disagree (a star face), then by label
    nat = (st.face_rho[seg_face] * np.sign(W0)[:, None]).ravel()  # per (segment, cell) record
    agree = np.where(((np.arange(n_end) & 1) == 1) == (nat[np.arange(n_end) >> 1] > 0), 1.0, -1.0)
    rev_lab = lab[np.arange(n_end) ^ 1]
    score = np.bincount(lab, weights=agree, minlength=n_end)
    fs, rs = score[lab], score[rev_lab]
    keep = fs > rs
    e = np.flatnonzero(fs == rs)  # whole orbits, each with its reverse: their signed areas
    if len(e):
        ec = end_cell[e]
        pe, pn = pts[end_pt[e]] - centre - anchor[ec], pts[end_pt[nxt[e]]] - centre - anchor[ec]
        orbit_area = np.bincount(lab[e], weights=np.einsum("ij,ij->i", normals[ec], _cross(pe, pn)),
                                 minlength=n_end)
        fwd, rev = orbit_area[lab[e]], orbit_area[rev_lab[e]]
        keep[e] = (fwd > rev) | ((fwd == rev) & (lab[e] < rev_lab[e]))
    term = nxt == lab  # the end before its orbit's first
    J = np.where(term, np.arange(n_end), nxt)
    dist = (~term).astype(np.intp)
    for _ in range(rounds):
        dist = dist + dist[J]
        J = J[J]
    # each kept orbit's ends in cycle order, orbits by their first end: placed, not sorted
    kept = np.flatnonzero(keep)
    size = np.bincount(lab[kept], minlength=n_end)
    start = row_offsets(size)[:-1]
    place = np.empty(len(kept), dtype=np.intp)
    place[start[lab[kept]] + size[lab[kept]] - 1 - dist[kept]] = np.arange(len(kept))
    kept = kept[place]
    flat = vid[end_pt[kept]]
    plab = lab[kept]
    # drop repeats (crossings merged at a vertex on H), then polygons of fewer than 3 corners
    newp = np.ones(len(kept), dtype=bool)
    newp[1:] = plab[1:] != plab[:-1]
    startp = np.flatnonzero(newp)
    pid = np.cumsum(newp) - 1
    prev = np.arange(len(kept)) - 1
    prev[startp] = np.append(startp[1:], len(kept)) - 1
    good = flat != flat[prev]
    flat, pid, kcell = flat[good], pid[good], end_cell[kept][good]
    counts = np.bincount(pid, minlength=len(startp))
    big = counts >= 3
    sel = big[pid]
    flat, pid, kcell = flat[sel], pid[sel], kcell[sel]
    counts = counts[big]
    prank = np.cumsum(big) - 1
    pid = prank[pid]
    if not len(counts):  # every cycle shrank to a vertex or an edge on H: H only touches
        return None
    offsets = row_offsets(counts)
    cell_ids = kcell[offsets[:-1]]

    # triangles: a convex cell's cycle fanned; a non-convex cell's section that is one cycle
    # winding once, always the same way, round its corners' centroid (a star-shaped polygon: its
    # even-odd fill) fanned from that centroid, an extra corner, wound counter-clockwise about
    # the normal as the slabs are; every other section filled even-odd by slabs
    conv = st.cell_convex[cell_ids]
    pconv = conv[pid]
    fo = row_offsets(counts[conv])
    ftri, fpoly = fan(flat[pconv], (np.cumsum(conv) - 1)[pid[pconv]], fo, counts[conv])
    tri = [ftri]
    tcell = [cell_ids[conv][fpoly]]
    # the sections of crossing cycles by the segments' arrangement, the others star-shaped round
    # centroids by fans, the rest by slabs.  The first two take disjoint cells (crossing cycles
    # are never star-shaped apart), so their order is only for speed: with convex faces (and star
    # cells) most sections cross, and the arrangement goes first; with star faces most are
    # star-shaped tips, and the fans go first
    g = np.flatnonzero(~st.cell_convex[rec_cell])
    n_new = len(vertices)
    extra = []
    xings = None
    for step in ("arrangement", "fans") if st.crossing_first else ("fans", "arrangement"):
        if step == "fans":
            filled = np.zeros(t.C, dtype=bool)
            filled[rec_cell] = True
            filled[rec_cell[g]] = False  # (cells filled already, or convex)
            turn, centroid = _star_alone(vertices, flat, pid, counts, cell_ids, normals, rec_cell, t.C,
                                         conv | filled[cell_ids])
            sp = np.flatnonzero(turn)
            if not len(sp):
                continue
            done = np.zeros(t.C, dtype=bool)
            done[cell_ids[sp]] = True
            rank = np.full(len(counts), -1, dtype=np.intp)
            rank[sp] = n_new + np.arange(len(sp))
            nxt = np.arange(1, len(flat) + 1)
            nxt[offsets[1:] - 1] = offsets[:-1]
            j = np.flatnonzero(turn[pid])
            ccw = turn[pid[j]] > 0
            tri.append(np.stack([rank[pid[j]], np.where(ccw, flat[j], flat[nxt[j]]),
                                 np.where(ccw, flat[nxt[j]], flat[j])], axis=1))
            tcell.append(cell_ids[pid[j]])
            extra.append(centroid[sp])
            n_new += len(sp)
            g = g[~done[rec_cell[g]]]
        elif len(g) and not on.any():
            atri, ac, ax, rest, xings = arrangement_fill(g, rec_cell[g], end_pt, partner, pts, vid, normals,
                                                         anchor + centre, n_new)
            tri.append(atri)
            tcell.append(ac)
            extra.append(ax)
            n_new += len(ax)
            g = g[rest]
    if len(g):
        ttri, tc, sx = _slabs(rec_cell[g], seg[rec_seg[g]], pts, vid, normals, anchor + centre, n_new, xings)
        tri.append(ttri)
        tcell.append(tc)
        extra.append(sx)
    extra = np.concatenate(extra) if extra else t.empty3
    triangles = np.concatenate(tri)
    triangle_cells = np.concatenate(tcell)
    all_v = np.concatenate([vertices, extra]) if len(extra) else vertices
    ev = vid[seg]
    ev = ev[ev[:, 0] != ev[:, 1]]
    if vnum is not None:  # every edge lying in H is an edge of S; a chord along one (from each of its faces): once
        e_on = on[t.ea] & on[t.eb]
        ev = np.concatenate([ev, np.stack([vnum[t.ea[e_on]], vnum[t.eb[e_on]]], axis=1)])
        lo_hi = np.sort(ev, axis=1)
        ev = lo_hi[np.unique(lo_hi[:, 0] * len(vertices) + lo_hi[:, 1], return_index=True)[1]]
    edges = ev if len(ev) else t.empty_i2
    return Slice(scaled(t, all_v), edges, flat, offsets, cell_ids, triangles, triangle_cells,
                 scaled_volume(t, volume), 3, len(extra))


def _star_alone(vertices, flat, pid, counts, cell_ids, normals, rec_cell, C, conv):
    """Per polygon: 1 (-1) where it winds once counter-clockwise (clockwise) about its
    non-convex cell's normal round its corners' centroid, every corner strictly that way from the
    last (a star-shaped polygon with the centroid in its kernel), and so do the cell's other
    polygons, whose bounding boxes it meets none of, all the cell's segments in them (the cell's
    section is then their fills, side by side), else 0; and the (p, 3) centroids (of those that
    could be)."""
    npoly = np.bincount(cell_ids, minlength=C)
    cand = ~conv & (np.bincount(rec_cell, minlength=C) == np.bincount(cell_ids, weights=counts, minlength=C))[cell_ids]
    turn = np.zeros(len(counts), dtype=np.intp)
    centroid = np.zeros((len(counts), 3))
    if not cand.any():
        return turn, centroid
    sel = cand[pid]
    q = (np.cumsum(cand) - 1)[pid[sel]]
    cnt = counts[cand]
    off = row_offsets(cnt)
    P = vertices[flat[sel]]
    cen = np.add.reduceat(P, off[:-1], axis=0) / cnt[:, None]  # (each polygon's corners are together)
    nxt = np.arange(1, len(q) + 1)
    nxt[off[1:] - 1] = off[:-1]
    rel = P - cen[q]
    n = normals[cell_ids[cand]]
    n = (n / np.sqrt(np.einsum("ij,ij->i", n, n))[:, None])[q]
    y = np.einsum("ij,ij->i", _cross(rel, rel[nxt]), n)
    ang = np.arctan2(y, np.einsum("ij,ij->i", rel, rel[nxt]))
    once = np.abs(np.abs(np.bincount(q, weights=ang, minlength=len(cnt))) - 2 * np.pi) < 1e-6
    left = np.bincount(q, weights=y > 0, minlength=len(cnt)) == cnt
    right = np.bincount(q, weights=y < 0, minlength=len(cnt)) == cnt
    tc = np.where(once & left, 1, np.where(once & right, -1, 0))
    cc = cell_ids[cand]
    ok = np.bincount(cc[tc != 0], minlength=C) == npoly  # every polygon of the cell star-shaped
    many = np.flatnonzero(ok[cc] & (npoly[cc] > 1))
    if len(many):  # several: each pair's bounding boxes apart
        lo, hi = np.minimum.reduceat(P, off[:-1])[many], np.maximum.reduceat(P, off[:-1])[many]
        mc = cc[many]
        o = np.argsort(mc, kind="stable")
        k = np.bincount(mc, minlength=C)
        table = np.full((C, int(k.max())), -1, dtype=np.intp)
        table[mc[o], np.arange(len(o)) - row_offsets(k)[:-1][mc[o]]] = o
        iu, ju = upper_pairs(table.shape[1])
        i, j = table[:, iu].ravel(), table[:, ju].ravel()
        i, j = i[j >= 0], j[j >= 0]
        meet = ((lo[i] <= hi[j]) & (lo[j] <= hi[i])).all(axis=1)
        ok[mc[i[meet]]] = False
    turn[cand] = np.where(ok[cc], tc, 0)
    centroid[cand] = cen
    return turn, centroid


def _slabs(rcell, rseg, pts, vid, normals, anchor, n_vertices, crossings=None):
    """Even-odd fill of each cell's section from its segments: ((k, 3) triangles, (k,) cells,
    (n, 3) extra vertices numbered from ``n_vertices``).  ``crossings``: ((k,) cells, (k,) heights
    v) where the cells' segments cross, if known (`even_odd_fill.arrangement_fill` gives them).

    In each cell's plane (axes u, v of `inplane_axes`, right-handed about the outward normal),
    the segments are cut at every corner's height v; within each slab the segments crossing it,
    sorted by u, pair 1st-2nd, 3rd-4th, ... into trapezoids (even-odd), each two triangles wound
    counter-clockwise about the normal."""
    uv = inplane_axes(normals)[rcell]  # (r, 6)
    rel0 = pts[rseg[:, 0]] - anchor[rcell]
    rel1 = pts[rseg[:, 1]] - anchor[rcell]
    X0 = rel0[:, 0] * uv[:, 0] + rel0[:, 1] * uv[:, 1] + rel0[:, 2] * uv[:, 2]
    Y0 = rel0[:, 0] * uv[:, 3] + rel0[:, 1] * uv[:, 4] + rel0[:, 2] * uv[:, 5]
    X1 = rel1[:, 0] * uv[:, 0] + rel1[:, 1] * uv[:, 1] + rel1[:, 2] * uv[:, 2]
    Y1 = rel1[:, 0] * uv[:, 3] + rel1[:, 1] * uv[:, 4] + rel1[:, 2] * uv[:, 5]
    up = Y1 > Y0
    lo_p = np.where(up, rseg[:, 0], rseg[:, 1])
    hi_p = np.where(up, rseg[:, 1], rseg[:, 0])
    Xl, Yl, Xh, Yh = np.where(up, X0, X1), np.where(up, Y0, Y1), np.where(up, X1, X0), np.where(up, Y1, Y0)
    keep = Yh > Yl  # level segments bound no slab
    rcell, lo_p, hi_p, Xl, Yl, Xh, Yh = (a[keep] for a in (rcell, lo_p, hi_p, Xl, Yl, Xh, Yh))
    nr = len(rcell)
    # slab lines also where two segments cross (found already by the arrangement fill if given)
    ic, iy = _crossings(rcell, Xl, Yl, Xh, Yh) if crossings is None else crossings
    ev_cell = np.concatenate([rcell, rcell, ic])
    ev_y = np.concatenate([Yl, Yh, iy])
    o = np.argsort(ev_y)  # by cell, then height: a float sort, then a stable (radix) one by cell
    o = o[np.argsort(ev_cell[o].astype(np.uint16) if len(normals) < 65536 else ev_cell[o], kind="stable")]
    new = np.ones(len(o), dtype=bool)
    new[1:] = (ev_y[o][1:] != ev_y[o][:-1]) | (ev_cell[o][1:] != ev_cell[o][:-1])
    uidx = np.empty(len(o), dtype=np.intp)
    uidx[o] = np.cumsum(new) - 1
    uy = ev_y[o][new]
    ylo, yhi = uidx[:nr], uidx[nr:2 * nr]
    span = yhi - ylo
    # pieces: each segment cut at the slab lines it spans, numbered segment by segment, slab by slab
    n = int(span.sum())
    r = np.repeat(np.arange(nr), span)
    pstart = row_offsets(span)[:-1]
    slab = ylo[r] + np.arange(n) - pstart[r]
    slope = (Xh - Xl) / (Yh - Yl)
    xa = Xl[r] + (uy[slab] - Yl[r]) * slope[r]
    xb = Xl[r] + (uy[slab + 1] - Yl[r]) * slope[r]
    o = np.argsort(xa + xb)  # by slab, then left to right: a float sort, then a stable (radix) one by slab
    o = o[np.argsort(slab[o].astype(np.uint16) if len(uy) < 65536 else slab[o], kind="stable")]
    if (np.bincount(slab) % 2).any():
        raise Inconsistent
    # a trapezoid goes on up while the same two segments bound it in the next slab (nothing
    # happens between them there): merged, it needs corners only where it starts and ends.  It
    # goes on from left piece q to q + 1 (the same segment's next slab) when that is a left piece
    # with the same right segment: no sort, runs of pieces
    Lq, R = o[0::2], r[o[1::2]]
    rr = np.append(r, -1)
    rpart = np.full(n + 1, -1, dtype=np.intp)
    rpart[Lq] = R
    cont = np.zeros(n + 1, dtype=bool)
    cont[Lq] = (rr[Lq + 1] == rr[Lq]) & (rpart[Lq + 1] == R)
    isleft = rpart[:n] >= 0
    sq = np.flatnonzero(isleft & ~cont[np.arange(-1, n - 1)])  # cont[-1] is the pad: False
    eq = np.flatnonzero(isleft & ~cont[:n])
    L, R, y0, y1 = r[sq], rpart[sq], slab[sq], slab[eq] + 1
    # corners: a segment's end where the trapezoid's line passes through it, else a new point on
    # it, one per (segment, slab line): numbered by the piece starting there, no sort
    cr = np.concatenate([L, R, R, L])
    cy = np.concatenate([y0, y0, y1, y1])
    at_lo, at_hi = cy == ylo[cr], cy == yhi[cr]
    mid = ~(at_lo | at_hi)
    piece = (pstart[cr] + cy - ylo[cr])[mid]
    mark = np.zeros(n, dtype=bool)
    mark[piece] = True
    corner = np.where(at_lo, vid[lo_p[cr]], vid[hi_p[cr]])
    corner[mid] = n_vertices + (np.cumsum(mark) - 1)[piece]
    mq = np.flatnonzero(mark)
    mr, my = r[mq], slab[mq]
    lam = ((uy[my] - Yl[mr]) / (Yh[mr] - Yl[mr]))[:, None]
    extra = pts[lo_p[mr]] + lam * (pts[hi_p[mr]] - pts[lo_p[mr]])
    a, b, c, d = corner.reshape(4, -1)  # lower left, lower right, upper right, upper left
    tri = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    cells = np.tile(rcell[L], 2)
    ok = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return tri[ok], cells[ok], extra


def _crossings(rcell, Xl, Yl, Xh, Yh):
    """Where two segments of one cell cross inside both: ((k,) cells, (k,) heights Y).

    Every pair of segments of a cell is tested (a cell's section has a few dozen at most): the
    cells' segments in the rows of a padded table, its pairs of columns taken at once."""
    o = np.argsort(rcell.astype(np.uint16) if rcell.max(initial=0) < 65536 else rcell, kind="stable")
    cnt = np.bincount(rcell)
    start = row_offsets(cnt)[:-1]
    table = np.full((len(cnt), int(cnt.max(initial=0))), -1, dtype=np.intp)
    table[rcell[o], np.arange(len(o)) - start[rcell[o]]] = o
    iu, ju = upper_pairs(table.shape[1])
    i, j = table[:, iu].ravel(), table[:, ju].ravel()
    ok = j >= 0  # (a row's entries are packed to the left)
    i, j = i[ok], j[ok]
    d1x, d1y = Xh[i] - Xl[i], Yh[i] - Yl[i]
    d2x, d2y = Xh[j] - Xl[j], Yh[j] - Yl[j]
    ex, ey = Xl[j] - Xl[i], Yl[j] - Yl[i]
    den = d1x * d2y - d1y * d2x
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (ex * d2y - ey * d2x) / den
        u = (ex * d1y - ey * d1x) / den
    eps = 1e-12
    hit = (den != 0) & (s > eps) & (s < 1 - eps) & (u > eps) & (u < 1 - eps)
    return rcell[i[hit]], Yl[i[hit]] + s[hit] * d1y[hit]


def _cross(a, b):
    """Row-wise 3-D cross product (np.cross's checks cost more than the work at these sizes)."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out
