"""The even-odd fill of a cell's section by its segments' arrangement: the general slicer's fill
for sections whose cycles cross.

Where a non-convex cell's cycles (`rot4d_widget.geometry.slicing.star`) cross, the section is their
even-odd region: the odd faces of the segments' arrangement (the segments split where they
cross).  Here, vectorised over every cell at once (no Python loop over geometry): the crossings
(each a new corner, `Slice.n_fill`), the pieces, their parity, the odd faces traced by turning
left, and the convex ones fanned.  A cell this cannot fill (no crossing, a crossing within `_EPS`
of a segment's end, a failed check, an odd face not convex) is left whole to the slab fill
(`star._slabs`).  The steps and why: docs/design.md, "Slicing polytopes" (The even-odd fill).
"""

from __future__ import annotations

import functools

import numpy as np

from .._ragged import row_offsets
from .tables import inplane_axes

__all__: list = []

_PARALLEL = 1e-12  # |d_i x d_j| below this times |d_i| |d_j|: two segments are parallel
_EPS = 1e-9  # a crossing this close (in segment parameter) to a segment's end: the cell goes to the slab fill


@functools.lru_cache(maxsize=64)
def upper_pairs(n: int) -> tuple:
    """``np.triu_indices(n, 1)``, read-only and kept (it costs more than the table it indexes)."""
    iu, ju = np.triu_indices(n, 1)
    iu.flags.writeable = False
    ju.flags.writeable = False
    return iu, ju


def _pairs(rcell, n_cells):
    """Every pair of records of one cell: ((k,) i, (k,) j), i before j in the cell's row of a padded table."""
    o = np.argsort(rcell.astype(np.uint16) if n_cells < 65536 else rcell, kind="stable")
    cnt = np.bincount(rcell, minlength=n_cells)
    start = row_offsets(cnt)[:-1]
    table = np.full((n_cells, int(cnt.max(initial=0))), -1, dtype=np.intp)
    table[rcell[o], np.arange(len(o)) - start[rcell[o]]] = o
    iu, ju = upper_pairs(table.shape[1])
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
    (r,) bool: the records whose cell was not filled here, ((m,) cells, (m,) heights v): where
    those cells' segments cross, in `star._slabs`' frame (`inplane_axes` about ``anchor``)).
    """
    nr = len(rec)
    C = len(normals)
    loc = np.full(len(partner) // 2, -1, dtype=np.intp)
    loc[rec] = np.arange(nr)
    p0, p1 = end_pt[2 * rec], end_pt[2 * rec + 1]
    uv = inplane_axes(normals)[rcell]
    rel0 = pts[p0] - anchor[rcell]
    rel1 = pts[p1] - anchor[rcell]
    X0 = rel0[:, 0] * uv[:, 0] + rel0[:, 1] * uv[:, 1] + rel0[:, 2] * uv[:, 2]
    Y0 = rel0[:, 0] * uv[:, 3] + rel0[:, 1] * uv[:, 4] + rel0[:, 2] * uv[:, 5]
    dX = rel1[:, 0] * uv[:, 0] + rel1[:, 1] * uv[:, 1] + rel1[:, 2] * uv[:, 2] - X0
    dY = rel1[:, 0] * uv[:, 3] + rel1[:, 1] * uv[:, 4] + rel1[:, 2] * uv[:, 5] - Y0

    # crossings: every pair of a cell's records, inside both (e = P_j - P_i; s along i, u along j)
    i, j = _pairs(rcell, C)
    ex, ey = X0[j] - X0[i], Y0[j] - Y0[i]
    dxi, dyi, dxj, dyj = dX[i], dY[i], dX[j], dY[j]
    den = dxi * dyj - dyi * dxj  # cross(d_i, d_j)
    cej = ex * dyj - ey * dxj  # cross(e, d_j)
    cei = ex * dyi - ey * dxi  # cross(e, d_i)
    # parallel (to rounding: a star face's line holds several segments, den ~ 1e-17 between them):
    # no crossing and no contact, not the quotient of two roundings
    dcut = np.where(np.abs(den) > _PARALLEL * np.sqrt((dxi * dxi + dyi * dyi) * (dxj * dxj + dyj * dyj)), den, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = cej / dcut
        u = cei / dcut
    lo, hi = np.minimum(s, u), np.maximum(s, u)
    inner = (lo > 1e-12) & (hi < 1 - 1e-12)  # (as the slab fill's; nan: never)
    hit = inner & (lo > _EPS) & (hi < 1 - _EPS)
    # not generic: a crossing at (or near) a segment's end, other than the ends a cycle shares;
    # nor a section whose segments do not cross (cycles apart or nested: a hole is no convex face)
    bad = np.bincount(rcell[i[hit]], minlength=C) == 0
    nb = np.flatnonzero((lo > -_EPS) & (hi < 1 + _EPS) & ~hit)
    ib, jb = i[nb], j[nb]
    bad[rcell[ib[(p0[ib] != p0[jb]) & (p0[ib] != p1[jb]) & (p1[ib] != p0[jb]) & (p1[ib] != p1[jb])]]] = True
    bad_pair = bad[rcell[i]]
    bad0 = bad.copy()
    ii = np.flatnonzero(inner & bad_pair)  # the crossings of the cells left to the slab fill
    slab_x = (rcell[i[ii]], Y0[i[ii]] + s[ii] * dyi[ii])
    hx = np.flatnonzero(hit & ~bad_pair)
    if not len(hx):
        return np.zeros((0, 3), dtype=np.intp), np.zeros(0, dtype=np.intp), np.zeros((0, 3)), bad[rcell], slab_x
    ci, cj, cs, cu, cc = i[hx], j[hx], s[hx], u[hx], den[hx]
    X = len(ci)

    # pieces: each record split at its crossings, in order along it
    orec = np.concatenate([ci, cj])
    order = np.argsort(orec + 0.5 * np.concatenate([cs, cu]))
    occ_rec = orec[order]
    on_j = order >= X
    occ_x = order - X * on_j
    occ_turn = (cc[occ_x] > 0) != on_j  # cross(d_this, d_other) > 0: the other runs leftwards
    pos = np.empty(2 * X, dtype=np.intp)
    pos[order] = np.arange(2 * X)
    other = np.empty(2 * X, dtype=np.intp)
    other[pos[:X]] = pos[X:]
    other[pos[X:]] = pos[:X]
    k = np.bincount(occ_rec, minlength=nr)
    optr = row_offsets(k)
    base = row_offsets(k + 1)  # record r's pieces base[r] .. base[r] + k[r]
    n_sub = int(base[-1])
    sub_rec = np.repeat(np.arange(nr), k + 1)
    sub_t = np.arange(n_sub) - base[sub_rec]
    # (base[r] = optr[r] + r: occurrence q sits at the high end of piece q + its record, and piece e
    # ends at occurrence e - its record if it ends at a crossing)
    so = np.arange(n_sub) - sub_rec
    mid = sub_t < k[sub_rec]  # piece e ends at a crossing (else at its record's end 1)

    # parity of each half-piece's left side: a ray square to its record, leftwards from the middle
    # of the record's first piece, across the cell's other records (both ways of every pair); in
    # the pair's terms (a0, a1 the other's ends along the ray's record from the ray's start, n0, n1
    # along the ray) it crosses where a0, a1 differ in sign and (a0 n1 - a1 n0) / (a0 - a1) > 0
    first = np.ones(nr)
    fq = optr[:-1][k > 0]
    fx = occ_x[fq]
    first[k > 0] = np.where(on_j[fq], cu[fx], cs[fx])
    L2 = dX * dX + dY * dY
    dd = dxi * dxj + dyi * dyj
    cnt = np.zeros(nr, dtype=np.intp)
    for a, a0, n0, dn in ((i, ex * dxi + ey * dyi - 0.5 * first[i] * L2[i], -cei, den),
                          (j, -(ex * dxj + ey * dyj) - 0.5 * first[j] * L2[j], cej, -den)):
        a1 = a0 + dd
        cr = ((a0 > 0) != (a1 > 0)) & ((a0 * (n0 + dn) - a1 * n0) * (a0 - a1) > 0)
        cnt += np.bincount(a[cr], minlength=nr)
    # each piece's odd half: along it (its left odd) or against it (``back``); the pieces stand for
    # their odd halves from here on
    back = ((cnt[sub_rec] + sub_t) & 1) == 0
    p_cell = rcell[sub_rec]

    # the next odd half round its face: at a crossing onto the other record, the way that turns
    # left; at a record's end onto the partner record, away from that end.  It must be that
    # record's odd half (``expect``): the parity and the faces agree, else the cell is left out
    nxt = np.empty(n_sub, dtype=np.intp)
    expect = np.empty(n_sub, dtype=bool)
    at_x = np.where(back, sub_t > 0, mid)  # the head is a crossing
    e = np.flatnonzero(at_x)
    q = so[e] - back[e]
    q2 = other[q]
    turn = occ_turn[q]
    nxt[e] = q2 + occ_rec[q2] + (turn != back[e])
    expect[e] = turn == back[e]
    e = np.flatnonzero(~at_x)
    r = sub_rec[e]
    pe = partner[2 * rec[r] + 1 - back[e]]
    r2 = loc[pe >> 1]
    start = (pe & 1) == 0
    nxt[e] = np.where(start, base[r2], base[r2 + 1] - 1)
    expect[e] = ~start
    bad[p_cell[back[nxt] != expect]] = True

    # the odd faces, labelled by pointer jumping (each by its least piece)
    live = ~bad[p_cell]
    nx = np.where(live, nxt, np.arange(n_sub))
    lab = np.arange(n_sub)
    J = nx
    for _ in range(2 + int(np.log2(max(n_sub, 2)))):
        if (lab[nx] == lab).all():
            break
        lab = np.minimum(lab, lab[J])
        J = J[J]
    # convex: every turn left (by less than a half turn), turning once in all: the heading passes
    # the direction +u once (from below the u axis to on or above it)
    hx, hy = np.where(back, -dX[sub_rec], dX[sub_rec]), np.where(back, -dY[sub_rec], dY[sub_rec])
    hy2 = hy[nx]
    cross = hx * hy2 - hy * hx[nx]
    once = np.bincount(lab, weights=(hy < 0) & (hy2 >= 0), minlength=n_sub) == 1
    bad[p_cell[~(once[lab] & (cross > 0)) & live]] = True

    # corners: each odd half's tail, the crossing before it or its record's end; fanned from the
    # tail of its face's least piece
    good_x = ~bad[rcell[ci]]
    xnum = np.cumsum(good_x) - 1 + n_vertices
    tq = so - 1 + back  # the crossing at the tail: the low end along, the high end against
    at_t = np.where(back, mid, sub_t > 0)
    tail = np.where(at_t, xnum[occ_x[np.minimum(tq, 2 * X - 1)]], vid[np.where(back, p1[sub_rec], p0[sub_rec])])
    use = np.flatnonzero(~bad[p_cell] & (lab != np.arange(n_sub)) & (nx != lab))
    tri = np.stack([tail[lab[use]], tail[use], tail[nx[use]]], axis=1)
    tcell = p_cell[use]
    gi = np.flatnonzero(good_x)
    cg = ci[gi]
    R0 = pts[p0]
    extra = np.take(R0, cg, axis=0) + cs[gi, None] * np.take(pts[p1] - R0, cg, axis=0)
    if (bad & ~bad0).any():  # cells found bad after their crossings were taken: theirs too
        ii = np.flatnonzero(inner & (bad & ~bad0)[rcell[i]])
        slab_x = (np.concatenate([slab_x[0], rcell[i[ii]]]), np.concatenate([slab_x[1], Y0[i[ii]] + s[ii] * dyi[ii]]))
    return tri, tcell, extra, bad[rcell], slab_x
