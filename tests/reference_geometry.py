"""Independent reference computations for the slicing tests (scipy only).

Nothing here uses rot4d_widget's slicing: volumes come from the polytope's
facet inequalities (scipy ConvexHull in 4-D) restricted to H and intersected
by scipy's HalfspaceIntersection; combinatorics from scipy's ConvexHull of the
slice's points with coplanar facets merged.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection


def random_rotation(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q, r = np.linalg.qr(rng.normal(size=(4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def rotation_with_w_row(direction) -> np.ndarray:
    """A rotation whose last row (the new w axis) is ``direction`` normalised."""
    u = np.asarray(direction, dtype=float)
    u = u / np.linalg.norm(u)
    basis = np.linalg.qr(np.column_stack([u, np.eye(4)[:, :3]]))[0]
    basis = basis * np.sign(basis[:, :1].T @ u)[0]  # first column = +u
    m = np.roll(basis, -1, axis=1).T  # rows: three complements, then u
    if np.linalg.det(m) < 0:
        m[0] = -m[0]
    assert np.allclose(m[3], u)
    return m


def slice_volume_by_halfspaces(vertices4: np.ndarray, c0: float) -> tuple[float, np.ndarray | None]:
    """Volume of {p in R^3 : (p, c0) in conv(vertices4)}, and the corner points.

    Returns (0.0, None) when the slice is lower-dimensional or empty.  The
    volume is computed about the slice's own centre (Chebyshev centre).
    """
    hull = ConvexHull(vertices4)
    A4, b4 = hull.equations[:, :4], hull.equations[:, 4]
    A = A4[:, :3]
    b = b4 + A4[:, 3] * c0  # A p + b <= 0
    norms = np.linalg.norm(A, axis=1)
    keep = norms > 1e-12
    if not np.all(b[~keep] <= 1e-12):
        return 0.0, None  # a facet parallel to H excludes the whole hyperplane
    A, b, norms = A[keep], b[keep], norms[keep]
    # Chebyshev centre: max r s.t. A p + r |A| <= -b
    res = linprog(
        c=[0, 0, 0, -1], A_ub=np.column_stack([A, norms]), b_ub=-b, bounds=[(None, None)] * 3 + [(0, None)],
        method="highs",
    )
    if res.status != 0 or res.x[3] < 1e-9 * np.abs(vertices4).max():
        return 0.0, None
    centre = res.x[:3]
    b_c = b + A @ centre  # about the centre
    hs = HalfspaceIntersection(np.column_stack([A, b_c]), np.zeros(3))
    pts = hs.intersections
    return float(ConvexHull(pts - pts.mean(axis=0)).volume), pts + centre


def merged_hull_faces(points: np.ndarray, tol: float = 1e-7):
    """Faces of conv(points) with coplanar triangles merged: list of vertex-index sets, and the edges."""
    pts = points - points.mean(axis=0)
    hull = ConvexHull(pts)
    scale = np.abs(pts).max()
    faces = []
    for eq in hull.equations:
        on = np.flatnonzero(np.abs(pts @ eq[:3] + eq[3]) <= tol * scale)
        faces.append(frozenset(on.tolist()))
    faces = set(faces)
    edges = set()
    for f in faces:
        # order the face's points by angle about their mean, in the face's own plane
        idx = np.array(sorted(f))
        fp = pts[idx] - pts[idx].mean(axis=0)
        _, _, vt = np.linalg.svd(fp)
        ang = np.arctan2(fp @ vt[1], fp @ vt[0])
        cyc = idx[np.argsort(ang)].tolist()
        edges.update(frozenset((a, b)) for a, b in zip(cyc, cyc[1:] + cyc[:1]))
    return faces, edges, set(hull.vertices.tolist())
