"""Uniform polychora and polyhedra that are not one linear diagram's Wythoff construction.

* the snub 24-cell and the grand antiprism: 600-cells with vertices cut away, their faces and
  cells from small convex hulls;
* the Platonic and Archimedean solids (`polyhedron`; the two snubs from the rotation group and a
  hull), for the prisms;
* prismatic polychora: prisms over a polyhedron, p-q duoprisms, antiprismatic prisms.

Everything has edge 2 and is centred on the origin.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.spatial import ConvexHull

from ..core import tolerances as tol_
from .mesh import order_cycle
from .regular import named
from .wythoff import Combinatorics, prism_cell_name, reflection_group, wythoff

__all__ = ["polyhedron"]



def _hull_facets(points: np.ndarray):
    """Facets of the convex hull of ``points`` (every point a corner): (list of vertex-index arrays, normals, offsets).

    For small point sets only (at most a few hundred points): coplanar simplices of qhull are
    merged by their (rounded) hyperplanes.
    """
    hull = ConvexHull(points)
    eq = hull.equations
    key = np.round(eq, tol_.HULL_DECIMALS)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    d = points.shape[1]
    normals, offsets = eq[first, :d], -eq[first, d]
    inc = np.abs(points @ normals.T - offsets) <= tol_.HULL_INCIDENCE
    return [np.flatnonzero(inc[:, k]) for k in range(len(first))], inc


def _hull_combinatorics(points: np.ndarray, cell_namer=None) -> Combinatorics:
    """Combinatorics of a small convex 4-polytope from its hull (used for the 96- and 100-vertex ones)."""
    cells_v, inc = _hull_facets(points)
    incT = inc.T.astype(np.int32)
    shared = incT @ incT.T
    ci, cj = np.nonzero(np.triu(shared >= 3, k=1))
    faces = [order_cycle(points, np.flatnonzero(inc[:, a] & inc[:, b])) for a, b in zip(ci, cj)]
    cells = [[] for _ in cells_v]
    for f, (a, b) in enumerate(zip(ci, cj)):
        cells[a].append(f)
        cells[b].append(f)
    edges = _edges_of(faces)
    sizes = [len(c) for c in cells]
    kinds = sorted(set(sizes))
    names = [cell_namer(k) if cell_namer else f"{k}-faced" for k in kinds]
    types = [kinds.index(s) for s in sizes]
    ftypes = [len(f) for f in faces]
    fk = sorted(set(ftypes))
    return Combinatorics(points, edges, faces, cells, [fk.index(s) for s in ftypes], types, names)


def _edges_of(faces) -> np.ndarray:
    e = np.concatenate([np.stack([f, np.roll(f, -1)], axis=1) for f in faces])
    e.sort(axis=1)
    return np.unique(e, axis=0)


def snub_24_cell() -> Combinatorics:
    """The 600-cell without the 24 vertices of an inscribed 24-cell: 96 vertices, 24 icosahedra, 120 tetrahedra."""
    v = named("600-cell").vertices
    # the inscribed 24-cell: the 24 vertices that are permutations of (±1,0,0,0), (±½,±½,±½,±½)
    # times the 600-cell's scale, i.e. those with every coordinate in {0, ±s/2, ±s}
    s = np.abs(v).max()
    frac = np.abs(v) / s
    in24 = np.all(np.isclose(frac, 0) | np.isclose(frac, 0.5) | np.isclose(frac, 1), axis=1)
    assert in24.sum() == 24
    return _hull_combinatorics(v[~in24], {4: "tetrahedron", 20: "icosahedron"}.get)


def grand_antiprism() -> Combinatorics:
    """The 600-cell without two great decagons in completely orthogonal planes: 100 vertices,
    20 pentagonal antiprisms, 300 tetrahedra."""
    v = named("600-cell").vertices
    r = np.linalg.norm(v[0])
    d = np.linalg.norm(v - v[0], axis=1)
    b = int(np.argmin(np.where(d > tol_.COINCIDENT, d, np.inf)))  # a neighbour of vertex 0
    q, _ = np.linalg.qr(np.stack([v[0], v[b]], axis=1))  # orthonormal basis of their plane
    proj = np.linalg.norm(v @ q, axis=1)
    ring1 = np.isclose(proj, r)
    ring2 = np.isclose(proj, 0.0, atol=tol_.COINCIDENT)
    assert ring1.sum() == 10 and ring2.sum() == 10
    return _hull_combinatorics(v[~(ring1 | ring2)], {4: "tetrahedron", 12: "pentagonal antiprism"}.get)


# ---------------------------------------------------------------------------------------------
# Polyhedra (3-D): Platonic and Archimedean solids, for the prisms
# ---------------------------------------------------------------------------------------------

#: polyhedron name -> (Dynkin symbol, labels, rings) or ("snub", labels)
POLYHEDRA = {
    "tetrahedron": ("x3o3o", (3, 3), (1, 0, 0)),
    "cube": ("x4o3o", (4, 3), (1, 0, 0)),
    "octahedron": ("o4o3x", (4, 3), (0, 0, 1)),
    "dodecahedron": ("x5o3o", (5, 3), (1, 0, 0)),
    "icosahedron": ("o5o3x", (5, 3), (0, 0, 1)),
    "truncated tetrahedron": ("x3x3o", (3, 3), (1, 1, 0)),
    "cuboctahedron": ("o4x3o", (4, 3), (0, 1, 0)),
    "truncated cube": ("x4x3o", (4, 3), (1, 1, 0)),
    "truncated octahedron": ("o4x3x", (4, 3), (0, 1, 1)),
    "rhombicuboctahedron": ("x4o3x", (4, 3), (1, 0, 1)),
    "truncated cuboctahedron": ("x4x3x", (4, 3), (1, 1, 1)),
    "snub cube": ("s4s3s", (4, 3), None),
    "icosidodecahedron": ("o5x3o", (5, 3), (0, 1, 0)),
    "truncated dodecahedron": ("x5x3o", (5, 3), (1, 1, 0)),
    "truncated icosahedron": ("o5x3x", (5, 3), (0, 1, 1)),
    "rhombicosidodecahedron": ("x5o3x", (5, 3), (1, 0, 1)),
    "truncated icosidodecahedron": ("x5x3x", (5, 3), (1, 1, 1)),
    "snub dodecahedron": ("s5s3s", (5, 3), None),
}
#: adjective of each polyhedron, for the prism's name ("truncated cubic prism")
ADJECTIVE = {
    "tetrahedron": "tetrahedral", "cube": "cubic", "octahedron": "octahedral", "dodecahedron": "dodecahedral",
    "icosahedron": "icosahedral", "truncated tetrahedron": "truncated tetrahedral",
    "cuboctahedron": "cuboctahedral", "truncated cube": "truncated cubic",
    "truncated octahedron": "truncated octahedral", "rhombicuboctahedron": "rhombicuboctahedral",
    "truncated cuboctahedron": "truncated cuboctahedral", "snub cube": "snub cubic",
    "icosidodecahedron": "icosidodecahedral", "truncated dodecahedron": "truncated dodecahedral",
    "truncated icosahedron": "truncated icosahedral", "rhombicosidodecahedron": "rhombicosidodecahedral",
    "truncated icosidodecahedron": "truncated icosidodecahedral", "snub dodecahedron": "snub dodecahedral",
}


def _snub_polyhedron(labels) -> Combinatorics:
    """Snub cube / snub dodecahedron: the orbit of a point under the rotation group, the point
    chosen so that its images by the three generating rotations are all at distance 2."""
    # scipy.optimize (~0.1 s more than scipy.spatial): only the two snub solids solve for a point
    from scipy.optimize import fsolve

    g = reflection_group(tuple(labels))
    r = g.reflections
    rot = [r[0] @ r[1], r[1] @ r[2], r[0] @ r[2]]

    def eqs(p):
        return [np.linalg.norm(p - m @ p) - 2.0 for m in rot]

    p = fsolve(eqs, np.linalg.solve(g.roots, np.ones(3)))
    even = np.linalg.det(g.mats) > 0
    pts = g.mats[even] @ p
    faces, _ = _hull_facets(pts)
    faces = [order_cycle(pts, f) for f in faces]
    return Combinatorics(pts, _edges_of(faces), faces, [])


@functools.lru_cache(maxsize=None)
def polyhedron(name: str) -> Combinatorics:
    """A Platonic or Archimedean solid with edge 2, centred: vertices, edges, faces (cycles)."""
    _, labels, rings = POLYHEDRA[name]
    if rings is None:
        return _snub_polyhedron(labels)
    return wythoff(labels, rings)


# ---------------------------------------------------------------------------------------------
# Prismatic polychora
# ---------------------------------------------------------------------------------------------


def prism(base: Combinatorics, base_name: str) -> Combinatorics:
    """The prism over a polyhedron with edge 2: two copies at w = -1 and w = +1 joined by squares."""
    n = len(base.vertices)
    vertices = np.concatenate([np.c_[base.vertices, -np.ones(n)], np.c_[base.vertices, np.ones(n)]])
    bf = base.faces
    edge_index = {(int(a), int(b)): k for k, (a, b) in enumerate(base.edges)}
    faces = list(bf) + [f + n for f in bf] + [np.array([a, b, b + n, a + n]) for a, b in base.edges]
    nf = len(bf)
    cells = [np.arange(nf), np.arange(nf, 2 * nf)]
    names = [base_name]
    types = [0, 0]
    for k, f in enumerate(bf):
        sq = [2 * nf + edge_index[(min(a, b), max(a, b))] for a, b in zip(f.tolist(), np.roll(f, -1).tolist())]
        cells.append(np.array([k, k + nf] + sq))
        nm = prism_cell_name(len(f))
        if nm not in names:
            names.append(nm)
        types.append(names.index(nm))
    edges = np.concatenate([base.edges, base.edges + n, np.stack([np.arange(n), np.arange(n) + n], axis=1)])
    ftypes = [len(f) for f in faces]
    fk = sorted(set(ftypes))
    return Combinatorics(vertices, edges, faces, cells, [fk.index(s) for s in ftypes], types, names)


def antiprism(p: int) -> Combinatorics:
    """The uniform p-gonal antiprism with edge 2, centred (3-D)."""
    R = 1.0 / math.sin(math.pi / p)
    h = 0.5 * math.sqrt(4.0 - (2.0 * R * math.sin(math.pi / (2 * p))) ** 2)
    k = np.arange(2 * p)
    ang = math.pi * k / p
    vertices = np.stack([R * np.cos(ang), R * np.sin(ang), np.where(k % 2 == 0, h, -h)], axis=1)
    faces = [k[0::2], k[1::2][::-1]] + [np.array([i, (i + 1) % (2 * p), (i + 2) % (2 * p)]) for i in range(2 * p)]
    return Combinatorics(vertices, _edges_of(faces), faces, [])


def duoprism(p: int, q: int) -> Combinatorics:
    """The p-q duoprism with edge 2: a regular p-gon times a regular q-gon."""
    Rp, Rq = 1.0 / math.sin(math.pi / p), 1.0 / math.sin(math.pi / q)
    i, j = np.meshgrid(np.arange(p), np.arange(q), indexing="ij")
    a, b = 2 * math.pi * i.ravel() / p, 2 * math.pi * j.ravel() / q
    vertices = np.stack([Rp * np.cos(a), Rp * np.sin(a), Rq * np.cos(b), Rq * np.sin(b)], axis=1)
    idx = np.arange(p * q).reshape(p, q)  # vertex (i, j)
    faces = [idx[:, jj] for jj in range(q)]  # q p-gons
    faces += [idx[ii, :] for ii in range(p)]  # p q-gons
    sq0 = p + q
    faces += [np.array([idx[ii, jj], idx[(ii + 1) % p, jj], idx[(ii + 1) % p, (jj + 1) % q], idx[ii, (jj + 1) % q]])
              for ii in range(p) for jj in range(q)]  # square (ii, jj) at sq0 + ii*q + jj
    cells = []
    for jj in range(q):  # the p-gonal prism between p-gons jj and jj+1
        cells.append(np.array([jj, (jj + 1) % q] + [sq0 + ii * q + jj for ii in range(p)]))
    for ii in range(p):  # the q-gonal prism between q-gons ii and ii+1
        cells.append(np.array([q + ii, q + (ii + 1) % p] + [sq0 + ii * q + jj for jj in range(q)]))
    names = list(dict.fromkeys([prism_cell_name(p), prism_cell_name(q)]))
    types = [names.index(prism_cell_name(p))] * q + [names.index(prism_cell_name(q))] * p
    ftypes = [0] * q + [1 if p != q else 0] * p + [2] * (p * q)
    return Combinatorics(vertices, _edges_of(faces), faces, cells, ftypes, types, names)
