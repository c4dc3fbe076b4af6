"""The single slicer: one hyperplane w = c0, with the explicit on-H case table.

See `rot4d_widget.geometry.slicing` for the case table and what replaced convexity;
`slice_level` is the entry (with its fallbacks for near-degenerate classifications), `_slice` the
vectorised steps, `_faces_in_h` the rule for 2-faces lying in H.
"""

from __future__ import annotations

import numpy as np

from ...core import tolerances as tol_
from .tables import Inconsistent, Slice, SliceTables, fan, inplane_axes, scaled, scaled_volume

__all__: list = []

_TWO_PI_PLUS = 8.0  # > 2*pi: spacing of per-polygon sort keys


def slice_level(t: SliceTables, x: np.ndarray, m: np.ndarray, c0: float, radius: float) -> Slice:
    """One level, with the fallbacks for near-degenerate classifications."""
    try:
        return _slice(t, x, m, c0, t.tol)
    except Inconsistent:
        pass
    # A face almost parallel to H but not within the tolerance: classify by exact
    # sign instead, then (never seen) nudge the hyperplane by a hair.
    try:
        return _slice(t, x, m, c0, 0.0)
    except Inconsistent:
        return _slice(t, x, m, c0 + tol_.NUDGE * radius, t.tol)


def _slice(t: SliceTables, x: np.ndarray, m: np.ndarray, c0: float, tol: float) -> Slice:
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
            raise Inconsistent
        edges = np.concatenate([seg_sv[order].reshape(-1, 2), in_h_edges])
    else:
        edges = in_h_edges

    f_on = np.logical_and.reduceat(fv_on, t.f_starts) if len(on_idx) else None  # faces lying in H
    if not solid:
        return touching(t, vertices, edges, on_idx, f_on)

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
        return touching(t, vertices, edges, on_idx, f_on)
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
    uv = inplane_axes(normals[ids])
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

    triangles, poly_of = fan(flat, rank[order], offsets, counts)
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
    return Slice(scaled(t, vertices), edges, flat, offsets, cell_ids, triangles, triangle_cells,
                 scaled_volume(t, volume), 3)


def touching(t: SliceTables, vertices, edges, on_idx, f_on) -> Slice:
    """A slice with no polygons: H touches P in faces (dim 2), edges (1) or vertices (0), or misses it."""
    if not len(on_idx):
        dim = -1
    else:
        dim = 2 if f_on.any() else (1 if len(edges) else 0)
    return Slice(scaled(t, vertices), edges, t.empty_i, t.offsets0, t.empty_i, t.empty_i3, t.empty_i, 0.0, dim)


def _faces_in_h(t: SliceTables, x: np.ndarray, m: np.ndarray, face_ids: np.ndarray, fn: np.ndarray, c_on: np.ndarray):
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

