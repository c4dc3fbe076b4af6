"""The even-odd fill of the regular star polychora's sections (issue 22), checked against an
independent computation that never calls the slicer's steps.

For random cells of a slice at random rotations and levels: random points of the cell's section
plane are inside a drawn triangle of that cell exactly when they are inside the 4-D cell by ray
parity (a ray in the cell's hyperplane, its hits on the cell's faces counted even-odd in each
face's own plane), and no point is inside two of its triangles (the view draws the fill
translucent: an overlap would show as a darker patch).  Then, per cell, the triangles' area is
the sampled even-odd area (within the sampling error), and every triangle is wound the way the
cell's outward normal says (the fill's vector area is the section's, not its mirror).

The great icosahedral and great grand 120-cells have cells whose sections are several cycles
crossing each other (dozens of crossings a cell); the great 120-cell fewer; the small stellated
120-cell's are mostly star-shaped (fanned from a centroid).
"""

from __future__ import annotations

import numpy as np
import pytest

from reference_geometry import random_rotation
from rot4d_widget import polytope, slice_polytope

NAMES = ["great icosahedral 120-cell", "great grand 120-cell", "great 120-cell", "small stellated 120-cell",
         "great stellated 120-cell"]


def _frame(points):
    """(origin, (k, d) orthonormal rows spanning the affine hull's first k principal axes)."""
    c = points.mean(axis=0)
    return c, np.linalg.svd(points - c)[2]


def _inside_faces(q, faces, direction):
    """(n,) ray parity of points ``q`` (n, 3) against planar polygons ``faces`` (list of (k, 3)),
    the ray ``q + s direction`` (s > 0); each face hit counts when the hit is inside the face by
    the even-odd rule in the face's plane."""
    hits = np.zeros(len(q), dtype=int)
    for poly in faces:
        c, ax = _frame(poly)
        n = np.cross(ax[0], ax[1])
        den = direction @ n
        if abs(den) < 1e-12:
            continue
        s = ((c - q) @ n) / den
        h = q + s[:, None] * direction - c
        x, y = h @ ax[0], h @ ax[1]
        p2 = (poly - c) @ ax[:2].T
        odd = np.zeros(len(q), dtype=bool)
        for (x1, y1), (x2, y2) in zip(p2, np.roll(p2, -1, axis=0)):
            if y1 == y2:
                continue
            odd ^= ((y1 > y) != (y2 > y)) & (x < x1 + (y - y1) * (x2 - x1) / (y2 - y1))
        hits += odd & (s > 0)
    return hits % 2


def _drawn(sample, tri2):
    """(n,) how many of the triangles ``tri2`` (k, 3, 2) contain each point of ``sample`` (n, 2)."""
    A, B, C = tri2[:, None, 0], tri2[:, None, 1], tri2[:, None, 2]
    s = sample[None]

    def side(P, Q):
        return (Q[..., 0] - P[..., 0]) * (s[..., 1] - P[..., 1]) - (Q[..., 1] - P[..., 1]) * (s[..., 0] - P[..., 0])

    d1, d2, d3 = side(A, B), side(B, C), side(C, A)
    return (((d1 > 0) & (d2 > 0) & (d3 > 0)) | ((d1 < 0) & (d2 < 0) & (d3 < 0))).sum(axis=0)


def _check_cells(p, m, c0, rng, n_cells=12, n_pts=400):
    s = slice_polytope(p, m, c0)
    x = np.asarray(p.vertices) @ m.T
    v = np.asarray(s.vertices)
    tri_cells = np.asarray(s.triangle_cells)
    cells = np.unique(tri_cells)
    assert len(cells)
    checked = 0
    for cell in rng.permutation(cells)[:n_cells]:
        faces4 = [x[p.faces[f]] for f in p.cells[cell]]
        allv = np.concatenate(faces4)
        c4, ax4 = _frame(allv)
        ax4 = ax4[:3]  # the cell's hyperplane
        faces3 = [(f - c4) @ ax4.T for f in faces4]
        tri = v[np.asarray(s.triangles)[tri_cells == cell]]  # (k, 3, 3)
        flat = tri.reshape(-1, 3)
        c, ax = _frame(flat)
        assert np.abs((flat - c) @ ax[2]).max() < 1e-9  # the fill is flat
        T2 = (tri - c) @ ax[:2].T
        # the section's extent: the cell's vertices' hull cut by the level, bounded by the
        # triangles' box grown by a margin (points outside every triangle count too)
        lo, hi = T2.reshape(-1, 2).min(axis=0), T2.reshape(-1, 2).max(axis=0)
        pad = 0.25 * (hi - lo).max()
        sample = rng.uniform(lo - pad, hi + pad, size=(n_pts, 2))
        q4 = np.concatenate([c + sample @ ax[:2], np.full((n_pts, 1), c0)], axis=1)
        q3 = (q4 - c4) @ ax4.T
        assert np.abs((q4 - c4) - q3 @ ax4).max() < 1e-9  # the section plane lies in the cell's hyperplane
        direction = rng.normal(size=3)
        inside = _inside_faces(q3, faces3, direction / np.linalg.norm(direction))
        drawn = _drawn(sample, T2)
        assert drawn.max() <= 1, f"cell {cell}: overlapping fill triangles"
        assert (drawn == inside).all(), f"cell {cell}: {int((drawn != inside).sum())} of {n_pts} points differ"
        # area: the triangles' against the sampled even-odd area (binomial error, 5 sigma)
        e1, e2 = T2[:, 1] - T2[:, 0], T2[:, 2] - T2[:, 0]
        area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
        box = float(np.prod(hi - lo + 2 * pad))
        f = inside.mean()
        assert abs(area - f * box) <= 5 * box * np.sqrt(max(f * (1 - f), 1 / n_pts) / n_pts) + 1e-12
        # orientation: every triangle wound the same way about the plane normal as the cell's
        # outward normal restricted to the level (a triangle's normal . cell normal > 0)
        n3 = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        cn = (np.asarray(p.cell_normals)[cell] @ m.T)[:3]
        assert (n3 @ cn > -1e-12).all()  # (a sliver of no area may come out either way)
        checked += 1
    return checked


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("seed, level", [(1, 0.05), (7, -0.4), (23, 0.75)])
def test_fill_is_each_cells_even_odd_region_without_overlap(name, seed, level):
    """At ``level`` times the circumradius."""
    p = polytope(name)
    rng = np.random.default_rng(seed)
    assert _check_cells(p, random_rotation(seed), level * p.circumradius, rng) > 0


def test_a_level_through_vertices_fills_alike():
    """A level at a vertex's height (vertices on H: crossings merged into them)."""
    p = polytope("great icosahedral 120-cell")
    m = random_rotation(5)
    w = (np.asarray(p.vertices) @ m.T)[:, 3]
    c0 = float(np.sort(w)[len(w) // 3])
    assert _check_cells(p, m, c0, np.random.default_rng(5), n_cells=20) > 0
