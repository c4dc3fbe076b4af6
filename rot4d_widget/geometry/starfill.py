"""The even-odd fill of a cell's section by its arrangement: the general slicer's fast fill.

`rot4d_widget.geometry.starslice` cuts a non-convex cell into segments (one per stretch of a face's
line inside the face) that chain into cycles; where the cycles cross, the section is their
**even-odd** region.  That region's boundary is every segment, split where segments cross: the
segments' *arrangement*.  Its faces (the pieces of the plane the split segments bound) are
alternately inside and outside (crossing any piece of a segment flips the parity), so the region
is the disjoint union of its odd faces, which touch only at crossings.  Here, vectorised over
every cell at once:

* **crossings**: every pair of a cell's segments (rows of a padded table, as in `_pairs`),
  crossing inside both; each crossing is one new corner (`Slice.n_fill`);
* **pieces**: each segment split at its crossings, in order along it (one float sort);
* **faces**: a half-piece (a piece run one way, its face on the left) goes on, at a crossing, along
  the other segment, the way that turns left (the sign of the two directions' cross product: no
  sort by angle round a point), and at a segment's end along the other segment ending there in
  the cell (the cycles' pairing); faces are labelled by pointer jumping, only the odd ones;
* **parity**: a half-piece's left side is odd when a ray from its segment's first piece, square to
  it on its left, crosses an odd number of the cell's other segments, each crossing along the
  segment flipping it.  Every half-piece and the next must agree (a check of the whole
  construction; a cell where they do not, or a crossing near a segment's end, goes to the slab
  fill instead);
* **triangles**: an odd face that is a convex polygon (every turn left, turning once) is fanned
  from its first corner, counter-clockwise about the cell's normal like its boundary; a cell with
  any other odd face (a reflex corner, a hole, a pinch) goes to the slab fill.

The fill's corners are the section's points and the crossings: no corner where a slab line
would cut a segment, and triangles about (segments + crossings) per cell, against slabs x
segments for the slab fill.
"""

from __future__ import annotations

import numpy as np

from ._ragged import _ptr
from .slicetables import _inplane_axes

__all__: list = []

_EPS = 1e-9  # a crossing this close (in segment parameter) to a segment's end: the cell goes to the slab fill


def _pairs(rcell, n_cells):
    """Every pair of records of one cell: ((k,) i, (k,) j), i before j in the cell's row of a padded table."""
    o = np.argsort(rcell.astype(np.uint16) if n_cells < 65536 else rcell, kind="stable")
    cnt = np.bincount(rcell, minlength=n_cells)
    start = _ptr(cnt)[:-1]
    table = np.full((n_cells, int(cnt.max(initial=0))), -1, dtype=np.intp)
    table[rcell[o], np.arange(len(o)) - start[rcell[o]]] = o
    iu, ju = np.triu_indices(table.shape[1], 1)
    i, j = table[:, iu].ravel(), table[:, ju].ravel()
    ok = j >= 0  # (a row's entries are packed to the left)
    return i[ok], j[ok]


def arrangement_fill(rec, rcell, end_pt, partner, pts, vid, normals, anchor, n_vertices):
    """Even-odd fill of the sections of the cells whose records are ``rec``.

    rec (r,) the records (global: record g is segment g >> 1 in one of its cells, its ends 2g and
    2g + 1), rcell (r,) their cells, end_pt (2R,) the crossing point of every end, partner (2R,)
    the other end at that point in that cell, pts (n, 3) the crossing points, vid (n,) their
    slice vertices, normals (C, 3) the cells' outward normals in H, anchor (C, 3) a point of each
    cell's plane, n_vertices the number of the first new corner.

    Returns ((k, 3) triangles, (k,) their cells, (x, 3) new corners numbered from ``n_vertices``,
    (r,) bool: the records whose cell was not filled here, for the slab fill).
    """
    nr = len(rec)
    C = len(normals)
    loc = np.full(len(partner) // 2, -1, dtype=np.intp)
    loc[rec] = np.arange(nr)
    p0, p1 = end_pt[2 * rec], end_pt[2 * rec + 1]
    uv = _inplane_axes(normals)[rcell]
    rel0 = pts[p0] - anchor[rcell]
    rel1 = pts[p1] - anchor[rcell]
    X0 = rel0[:, 0] * uv[:, 0] + rel0[:, 1] * uv[:, 1] + rel0[:, 2] * uv[:, 2]
    Y0 = rel0[:, 0] * uv[:, 3] + rel0[:, 1] * uv[:, 4] + rel0[:, 2] * uv[:, 5]
    dX = rel1[:, 0] * uv[:, 0] + rel1[:, 1] * uv[:, 1] + rel1[:, 2] * uv[:, 2] - X0
    dY = rel1[:, 0] * uv[:, 3] + rel1[:, 1] * uv[:, 4] + rel1[:, 2] * uv[:, 5] - Y0

    # crossings: every pair of a cell's records, inside both
    i, j = _pairs(rcell, C)
    ex, ey = X0[j] - X0[i], Y0[j] - Y0[i]
    den = dX[i] * dY[j] - dY[i] * dX[j]  # cross(d_i, d_j)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (ex * dY[j] - ey * dX[j]) / den
        u = (ex * dY[i] - ey * dX[i]) / den
    inner = (den != 0) & (s > 1e-12) & (s < 1 - 1e-12) & (u > 1e-12) & (u < 1 - 1e-12)  # (as the slab fill's)
    near = (den != 0) & (s > -_EPS) & (s < 1 + _EPS) & (u > -_EPS) & (u < 1 + _EPS)
    hit = inner & (s > _EPS) & (s < 1 - _EPS) & (u > _EPS) & (u < 1 - _EPS)
    # not generic: a crossing at (or near) a segment's end, other than the ends a cycle shares;
    # nor a section whose segments do not cross (cycles apart or nested: a hole is no convex face)
    bad = np.bincount(rcell[i[hit]], minlength=C) == 0
    shared = (p0[i] == p0[j]) | (p0[i] == p1[j]) | (p1[i] == p0[j]) | (p1[i] == p1[j])
    bad[rcell[i[near & ~hit & ~shared]]] = True
    hit &= ~bad[rcell[i]]
    bad0 = bad.copy()
    ii = np.flatnonzero(inner & bad[rcell[i]])  # the crossings of the cells left to the slab fill
    slab_x = (rcell[i[ii]], Y0[i[ii]] + s[ii] * dY[i[ii]])
    if not hit.any():
        return np.zeros((0, 3), dtype=np.intp), np.zeros(0, dtype=np.intp), np.zeros((0, 3)), bad[rcell], slab_x
    ci, cj, cs, cu, cc = i[hit], j[hit], s[hit], u[hit], den[hit]
    X = len(ci)

    # pieces: each record split at its crossings, in order along it
    orec = np.concatenate([ci, cj])
    order = np.argsort(orec + 0.5 * np.concatenate([cs, cu]))
    occ_rec = orec[order]
    occ_x = np.concatenate([np.arange(X), np.arange(X)])[order]
    occ_turn = np.concatenate([cc, -cc])[order] > 0  # cross(d_this, d_other) > 0: the other runs leftwards
    pos = np.empty(2 * X, dtype=np.intp)
    pos[order] = np.arange(2 * X)
    other = np.empty(2 * X, dtype=np.intp)
    other[pos[:X]] = pos[X:]
    other[pos[X:]] = pos[:X]
    k = np.bincount(occ_rec, minlength=nr)
    optr = _ptr(k)
    occ_t = np.arange(2 * X) - optr[occ_rec]  # its rank along its record
    base = _ptr(k + 1)  # record r's pieces base[r] .. base[r] + k[r]
    n_sub = int(base[-1])
    sub_rec = np.repeat(np.arange(nr), k + 1)
    sub_t = np.arange(n_sub) - base[sub_rec]

    # half-pieces: 2e runs piece e along its record, 2e + 1 against; the next of each round its left face
    def leave(q, turn):  # from occurrence q onto the other record, leftwards when ``turn``
        q2 = other[q]
        r2 = occ_rec[q2]
        return np.where(turn, 2 * (base[r2] + occ_t[q2] + 1), 2 * (base[r2] + occ_t[q2]) + 1)

    def at_end(r, kend):  # from record r's end kend onto its partner record, away from that end
        pe = partner[2 * rec[r] + kend]
        r2 = loc[pe >> 1]
        return np.where((pe & 1) == 0, 2 * base[r2], 2 * (base[r2] + k[r2]) + 1)

    nxt = np.empty(2 * n_sub, dtype=np.intp)
    fwd_mid = sub_t < k[sub_rec]
    e = np.flatnonzero(fwd_mid)
    q = optr[sub_rec[e]] + sub_t[e]
    nxt[2 * e] = leave(q, occ_turn[q])
    e = np.flatnonzero(~fwd_mid)
    nxt[2 * e] = at_end(sub_rec[e], 1)
    bwd_mid = sub_t > 0
    e = np.flatnonzero(bwd_mid)
    q = optr[sub_rec[e]] + sub_t[e] - 1
    nxt[2 * e + 1] = leave(q, ~occ_turn[q])
    e = np.flatnonzero(~bwd_mid)
    nxt[2 * e + 1] = at_end(sub_rec[e], 0)

    # parity of each half-piece's left side: a ray square to its record, leftwards from the middle
    # of the record's first piece, across the cell's other records (both ways of every pair)
    first = np.ones(nr)
    has = k > 0
    fq = optr[:-1][has]
    fx = occ_x[fq]
    first[has] = np.where(ci[fx] == np.flatnonzero(has), cs[fx], cu[fx])
    Mx, My = X0 + 0.5 * first * dX, Y0 + 0.5 * first * dY
    cnt = np.zeros(nr, dtype=np.intp)
    for a, b in ((i, j), (j, i)):  # the ray of a against record b
        ax, ay = dX[a], dY[a]
        a0 = (X0[b] - Mx[a]) * ax + (Y0[b] - My[a]) * ay
        a1 = a0 + dX[b] * ax + dY[b] * ay
        n0 = (Y0[b] - My[a]) * ax - (X0[b] - Mx[a]) * ay  # along the left normal (-ay, ax)
        n1 = n0 + dY[b] * ax - dX[b] * ay
        with np.errstate(divide="ignore", invalid="ignore"):
            cr = ((a0 > 0) != (a1 > 0)) & (n0 + a0 / (a0 - a1) * (n1 - n0) > 0)
        cnt += np.bincount(a[cr], minlength=nr)
    par = np.empty(2 * n_sub, dtype=bool)
    par[0::2] = ((cnt[sub_rec] + sub_t) & 1) == 1
    par[1::2] = ~par[0::2]
    h_cell = np.repeat(rcell[sub_rec], 2)
    bad[h_cell[par[nxt] != par]] = True

    # the odd faces, labelled by pointer jumping (each by its least half-piece)
    odd = np.flatnonzero(par & ~bad[h_cell])
    li = np.full(2 * n_sub, -1, dtype=np.intp)
    li[odd] = np.arange(len(odd))
    nx = li[nxt[odd]]
    lab = np.arange(len(odd))
    J = nx
    while len(odd) and (lab[nx] != lab).any():
        lab = np.minimum(lab, lab[J])
        J = J[J]
    # convex: every turn left, turning once in all
    hr = sub_rec[odd >> 1]
    sg = np.where(odd & 1, -1.0, 1.0)
    hx, hy = sg * dX[hr], sg * dY[hr]
    cross = hx * hy[nx] - hy * hx[nx]
    turn = np.arctan2(cross, hx * hx[nx] + hy * hy[nx])
    once = np.abs(np.bincount(lab, weights=turn, minlength=len(odd)) - 2 * np.pi) < 1e-6
    ok = once[lab] & (cross > 0)
    bad[h_cell[odd[~ok]]] = True

    # corners: a piece's low end (its record's start, or the crossing before it) and high end
    good_x = ~bad[rcell[ci]]
    xnum = np.cumsum(good_x) - 1 + n_vertices
    occ_node = np.append(xnum[occ_x], -1)  # (padded: read where a piece ends at its record's end)
    so = optr[sub_rec] + sub_t  # the occurrence at each piece's high end (if any)
    lo_node = np.where(sub_t > 0, occ_node[so - 1], vid[p0[sub_rec]])
    hi_node = np.where(sub_t < k[sub_rec], occ_node[so], vid[p1[sub_rec]])
    tail = np.where(odd & 1, hi_node[odd >> 1], lo_node[odd >> 1])
    head = np.where(odd & 1, lo_node[odd >> 1], hi_node[odd >> 1])
    use = np.flatnonzero(~bad[h_cell[odd]] & (lab != np.arange(len(odd))) & (nx != lab))
    tri = np.stack([tail[lab[use]], tail[use], head[use]], axis=1)
    tcell = h_cell[odd[use]]
    gi = ci[good_x]
    P = pts[p0[gi]]
    extra = P + cs[good_x, None] * (pts[p1[gi]] - P)
    if (bad & ~bad0).any():  # cells found bad after their crossings were taken: theirs too
        ii = np.flatnonzero(inner & (bad & ~bad0)[rcell[i]])
        slab_x = (np.concatenate([slab_x[0], rcell[i[ii]]]), np.concatenate([slab_x[1], Y0[i[ii]] + s[ii] * dY[i[ii]]]))
    return tri, tcell, extra, bad[rcell], slab_x
