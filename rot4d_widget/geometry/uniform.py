"""Convex uniform 4-polytopes (polychora): the Wythoff construction, its combinatorics, names.

What is here
------------
* the 45 distinct polychora of the 60 ring patterns of the linear Coxeter–Dynkin diagrams
  A4 ``[3,3,3]``, B4 ``[4,3,3]``, F4 ``[3,4,3]`` and H4 ``[5,3,3]``;
* the snub 24-cell and the grand antiprism (the two non-Wythoffian convex ones; both are
  600-cells with vertices cut away);
* prismatic families: prisms over the Platonic and Archimedean solids, the p-q duoprisms and
  the p-antiprismatic prisms for 3 <= p, q <= 32.

Every one has edge length 2 and is centred on the origin, like the regular six of
:mod:`rot4d_widget.geometry.polytopes` — and the regular six *are* those objects: ``build("x3o3o3o")``
returns ``polytope("5-cell")`` itself (its vertex array unchanged).

Combinatorics from the group, not from the geometry
---------------------------------------------------
A Wythoff polytope is the orbit ``W v0`` of a seed point ``v0`` under a finite reflection group
``W`` with simple reflections ``r0 .. r3`` (the diagram's nodes).  ``v0`` is at distance 1 from
the mirror of each ringed node and on the mirrors of the others, so each ringed reflection moves
it by 2 (the edge length).  The group is enumerated once (its elements as 4x4 matrices, at most
14400 for H4) together with the permutations ``g -> g r_i`` (right multiplication).  Then, by
Wythoff's rule, for every set K of nodes whose connected parts each contain a ringed node, the
k-faces of type K are the sets ``g W_K v0``; two elements give the same face exactly when they
lie in the same left coset of ``W_K x W_U'`` (U' the unringed nodes not joined to K, which fix the
face pointwise).  So vertices, edges, 2-faces and cells are *connected components* of the Cayley
graph restricted to a few generators (``scipy.sparse.csgraph.connected_components``), a 2-face's
vertex cycle is the walk ``g, g r_i, g r_i r_j, ...`` around its dihedral group, and a cell's
2-faces are the faces of the group elements in the cell's coset.  No distances are compared and
no hull is taken.  Only the two non-Wythoffian polychora (96 and 100 vertices) and the faces of
the two snub polyhedra (24 and 60 vertices) come from a convex hull.

Names
-----
``canonical_name`` accepts the common names ("rectified 5-cell", "omnitruncated 120-cell",
"snub 24-cell", "grand antiprism", "5-7 duoprism", "truncated cubic prism", "pentagonal prism
prism", "7-antiprismatic prism", ...), the linear Dynkin notation of the polytope community
("x3o3o3o", "o3x3o3o", "x4x3o3o", "x5x3x3x", "s3s4o3o"; a diagram read backwards is the same
polytope; prismatic ones "x5o x7o", "x4x3o x", "s2s14o x"), and the aliases of the regular six.
``polytope_names()`` lists the canonical names by family.
"""

from __future__ import annotations

import functools
import itertools
import math
import re

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull

from . import polytopes as _polytopes
from ..core._arrays import sealed as _sealed

__all__ = ["build", "canonical_name", "polytope_names", "dynkin_symbol", "Combinatorics", "combinatorics"]

PHI = (1.0 + math.sqrt(5.0)) / 2.0
MAX_P = 32  #: largest p, q of the duoprisms and antiprismatic prisms

# ---------------------------------------------------------------------------------------------
# Coxeter groups
# ---------------------------------------------------------------------------------------------

#: order of the finite linear Coxeter groups used here (branch labels -> |W|)
_GROUP_ORDER = {
    (3, 3, 3): 120, (4, 3, 3): 384, (3, 4, 3): 1152, (5, 3, 3): 14400,
    (3, 3): 24, (4, 3): 48, (5, 3): 120,
}


def _simple_roots(labels: tuple) -> np.ndarray:
    """Unit simple roots (rows) of the linear diagram with branch ``labels``: <a_i, a_j> = -cos(pi/m_ij)."""
    n = len(labels) + 1
    gram = np.eye(n)
    for i, m in enumerate(labels):
        gram[i, i + 1] = gram[i + 1, i] = -math.cos(math.pi / m)
    return np.linalg.cholesky(gram)  # rows a_i with a_i . a_j = gram_ij


class _Group:
    """A finite reflection group with a linear diagram: elements and right multiplication.

    ``mats`` (N, n, n) the elements as orthogonal matrices (``mats[0]`` the identity);
    ``right`` (n, N) intp: ``right[i, g]`` is the index of ``g r_i``.
    """

    def __init__(self, labels: tuple):
        self.labels = tuple(labels)
        n = len(labels) + 1
        self.n = n
        self.roots = _simple_roots(self.labels)
        refl = np.stack([np.eye(n) - 2.0 * np.outer(a, a) for a in self.roots])
        self.reflections = refl
        # a generic point: distances 1, 1.1, 1.2, ... from the mirrors, so distinct elements map
        # it at least 2 apart and a 1e-3 grid keys them without ambiguity
        generic = np.linalg.solve(self.roots, 1.0 + 0.1 * np.arange(n))
        order = _GROUP_ORDER[self.labels]
        mats = np.empty((order, n, n))
        mats[0] = np.eye(n)
        right = np.full((n, order), -1, dtype=np.intp)
        index = {self._key(generic): 0}
        count = 1
        frontier = np.array([0])
        while len(frontier):
            new = []
            for i in range(n):
                cand = mats[frontier] @ refl[i]
                pts = cand @ generic
                keys = np.floor(pts * 1e3 + 0.5).astype(np.int64)
                for row, (g, key) in enumerate(zip(frontier.tolist(), map(bytes, keys))):
                    j = index.get(key)
                    if j is None:
                        if count == order:
                            raise RuntimeError(f"group {self.labels}: more than {order} elements")
                        j = index[key] = count
                        mats[j] = cand[row]
                        count += 1
                        new.append(j)
                    right[i, g] = j
            frontier = np.array(new, dtype=np.intp)
        if count != order or (right < 0).any():
            raise RuntimeError(f"group {self.labels}: found {count} elements, expected {order}")
        self.mats = mats
        self.right = right
        self.order = order

    @staticmethod
    def _key(p):
        return bytes(np.floor(np.asarray(p) * 1e3 + 0.5).astype(np.int64))

    def adjacent(self, i: int, j: int) -> bool:
        return abs(i - j) == 1

    def label(self, i: int, j: int) -> int:
        return self.labels[min(i, j)] if abs(i - j) == 1 else 2

    def cosets(self, gens) -> np.ndarray:
        """(N,) labels of the left cosets g <gens>: connected components of the Cayley graph."""
        gens = sorted(gens)
        N = self.order
        if not gens:
            return np.arange(N, dtype=np.intp)
        src = np.tile(np.arange(N), len(gens))
        dst = self.right[gens].ravel()
        graph = coo_matrix((np.ones(len(src), dtype=np.int8), (src, dst)), shape=(N, N)).tocsr()
        _, labels = connected_components(graph, directed=False)
        # number the cosets in the order of their first element (deterministic, identity first)
        _, first, inv = np.unique(labels, return_index=True, return_inverse=True)
        rank = np.empty(len(first), dtype=np.intp)
        rank[np.argsort(first)] = np.arange(len(first))
        return rank[inv.ravel()]


@functools.lru_cache(maxsize=None)
def _group(labels: tuple) -> _Group:
    return _Group(labels)


# ---------------------------------------------------------------------------------------------
# Combinatorics container
# ---------------------------------------------------------------------------------------------


class Combinatorics:
    """Vertices and combinatorics of a polytope, before it becomes a `Polytope`.

    vertices : (V, d) float64
    edges : (E, 2) intp, each row ascending, rows sorted
    faces : tuple of F intp arrays, each a cycle of vertex indices (2-faces)
    cells : tuple of C intp arrays of face indices (4-D only; for a polyhedron, empty)
    face_types, cell_types : (F,), (C,) intp, the type (orbit) index of each face / cell
    cell_names : tuple of str, the name of each cell type (e.g. "truncated tetrahedron")

    Every array is read-only: `combinatorics` caches these objects and shares them.
    """

    def __init__(self, vertices, edges, faces, cells, face_types=None, cell_types=None, cell_names=None):
        self.vertices = _sealed(np.array(vertices, dtype=np.float64))
        e = np.sort(np.asarray(edges, dtype=np.intp).reshape(-1, 2), axis=1)
        self.edges = _sealed(e[np.lexsort((e[:, 1], e[:, 0]))])
        self.faces = _split_sealed(faces)
        self.cells = _split_sealed(cells)
        self.face_types = _sealed(np.zeros(len(self.faces), np.intp) if face_types is None
                                  else np.array(face_types, dtype=np.intp))
        self.cell_types = _sealed(np.zeros(len(self.cells), np.intp) if cell_types is None
                                  else np.array(cell_types, dtype=np.intp))
        self.cell_names = tuple(cell_names) if cell_names is not None else ()

    @property
    def counts(self) -> tuple:
        return len(self.vertices), len(self.edges), len(self.faces), len(self.cells)

    def cell_census(self) -> dict:
        """``{cell type name: how many}``."""
        out = {}
        for t, k in zip(*np.unique(self.cell_types, return_counts=True)):
            name = self.cell_names[t] if t < len(self.cell_names) else f"type {t}"
            out[name] = out.get(name, 0) + int(k)
        return out


def _split_sealed(rows) -> tuple:
    """Index rows as read-only views of one sealed flat array (fast for ~10^4 rows)."""
    rows = [np.asarray(r, dtype=np.intp) for r in rows]
    if not rows:
        return ()
    flat = _sealed(np.concatenate(rows))
    bounds = np.cumsum([0] + [len(r) for r in rows]).tolist()
    return tuple(flat[a:b] for a, b in zip(bounds[:-1], bounds[1:]))


# ---------------------------------------------------------------------------------------------
# Wythoff construction
# ---------------------------------------------------------------------------------------------


def _components_ok(group: _Group, K, rings) -> bool:
    """Wythoff's rule: every connected part of the sub-diagram K holds a ringed node."""
    K = sorted(K)
    parts, cur = [], [K[0]]
    for a, b in zip(K, K[1:]):
        if group.adjacent(a, b):
            cur.append(b)
        else:
            parts.append(cur)
            cur = [b]
    parts.append(cur)
    return all(any(rings[i] for i in part) for part in parts)


def _stabiliser(group: _Group, K, rings) -> list:
    """K plus the unringed nodes joined to no node of K (they fix the face g W_K v0 pointwise)."""
    K = set(K)
    extra = [u for u in range(group.n) if u not in K and not rings[u]
             and not any(group.adjacent(u, k) for k in K)]
    return sorted(K | set(extra))


def wythoff(labels, rings) -> Combinatorics:
    """Vertices, edges, 2-faces and (in 4-D) cells of the Wythoff polytope of a linear diagram.

    ``labels`` the branch labels (e.g. ``(5, 3, 3)``), ``rings`` one bool per node.
    """
    labels, rings = tuple(labels), tuple(bool(r) for r in rings)
    g = _group(labels)
    n = g.n
    if len(rings) != n or not any(rings):
        raise ValueError(f"Expected {n} ring flags with at least one ringed, got {rings}")
    v0 = np.linalg.solve(g.roots, np.array(rings, dtype=float))
    unringed = [i for i in range(n) if not rings[i]]
    vertex_of = g.cosets(unringed)
    V = int(vertex_of.max()) + 1
    first = np.zeros(V, dtype=np.intp)
    first[vertex_of[::-1]] = np.arange(g.order)[::-1]  # the first element of each coset
    vertices = g.mats[first] @ v0
    # edges: one orbit per ringed node
    edges = []
    for i in range(n):
        if rings[i]:
            lab = g.cosets(_stabiliser(g, [i], rings))
            _, rep = np.unique(lab, return_index=True)
            edges.append(np.stack([vertex_of[rep], vertex_of[g.right[i, rep]]], axis=1))
    edges = np.concatenate(edges)
    # 2-faces: one orbit per valid pair of nodes
    faces, face_types, face_label = [], [], {}
    n_faces = 0
    for t, (i, j) in enumerate(itertools.combinations(range(n), 2)):
        if not _components_ok(g, (i, j), rings):
            continue
        lab = g.cosets(_stabiliser(g, (i, j), rings))
        _, rep = np.unique(lab, return_index=True)
        m = g.label(i, j)
        a, b = (i, j) if not rings[i] else (j, i)  # walk starting with an unringed generator if any
        walk = np.empty((len(rep), 2 * m), dtype=np.intp)
        cur = rep
        for s in range(2 * m):
            walk[:, s] = vertex_of[cur]
            cur = g.right[a if s % 2 == 0 else b, cur]
        if not (rings[i] and rings[j]):
            walk = walk[:, ::2]  # the unringed step does not move the vertex
        faces.extend(walk)
        face_types.extend([len(face_label)] * len(rep))
        face_label[(i, j)] = lab + n_faces
        n_faces += len(rep)
    cells, cell_types, cell_names = [], [], []
    if n == 4:
        for K in itertools.combinations(range(n), 3):
            if not _components_ok(g, K, rings):
                continue
            lab = g.cosets(_stabiliser(g, K, rings))
            n_cells = int(lab.max()) + 1
            pairs = [lab * n_faces + face_label[J] for J in itertools.combinations(K, 2) if J in face_label]
            key = np.unique(np.concatenate(pairs))
            cell_of, face_of = np.divmod(key, n_faces)
            starts = np.searchsorted(cell_of, np.arange(n_cells + 1))
            cells.extend(np.split(face_of, starts[1:-1]))
            cell_types.extend([len(cell_names)] * n_cells)
            cell_names.append(_cell_name(labels, rings, K))
    return Combinatorics(vertices, edges, faces, cells, face_types, cell_types, cell_names)


# ---------------------------------------------------------------------------------------------
# Names of the cells (sub-diagrams)
# ---------------------------------------------------------------------------------------------

_POLYGON_WORDS = {3: "triangular", 4: "square", 5: "pentagonal", 6: "hexagonal", 7: "heptagonal",
                  8: "octagonal", 9: "enneagonal", 10: "decagonal", 11: "hendecagonal", 12: "dodecagonal"}

_POLYHEDRON_OF = {  # (labels, rings) of a 3-node linear diagram -> name
    ((3, 3), (1, 0, 0)): "tetrahedron", ((3, 3), (0, 0, 1)): "tetrahedron",
    ((3, 3), (0, 1, 0)): "octahedron", ((3, 3), (1, 1, 0)): "truncated tetrahedron",
    ((3, 3), (0, 1, 1)): "truncated tetrahedron", ((3, 3), (1, 0, 1)): "cuboctahedron",
    ((3, 3), (1, 1, 1)): "truncated octahedron",
    ((4, 3), (1, 0, 0)): "cube", ((4, 3), (0, 1, 0)): "cuboctahedron", ((4, 3), (0, 0, 1)): "octahedron",
    ((4, 3), (1, 1, 0)): "truncated cube", ((4, 3), (0, 1, 1)): "truncated octahedron",
    ((4, 3), (1, 0, 1)): "rhombicuboctahedron", ((4, 3), (1, 1, 1)): "truncated cuboctahedron",
    ((5, 3), (1, 0, 0)): "dodecahedron", ((5, 3), (0, 1, 0)): "icosidodecahedron",
    ((5, 3), (0, 0, 1)): "icosahedron", ((5, 3), (1, 1, 0)): "truncated dodecahedron",
    ((5, 3), (0, 1, 1)): "truncated icosahedron", ((5, 3), (1, 0, 1)): "rhombicosidodecahedron",
    ((5, 3), (1, 1, 1)): "truncated icosidodecahedron",
}


def _prism_cell(m: int) -> str:
    """The name of the uniform m-gonal prism (the 4-gonal one is the cube)."""
    return "cube" if m == 4 else f"{_POLYGON_WORDS.get(m, f'{m}-gonal')} prism"


def _cell_name(labels, rings, K) -> str:
    """Name of the cell of type K (three nodes of a 4-node linear diagram)."""
    K = sorted(K)
    r = tuple(int(rings[k]) for k in K)
    if K[1] - K[0] == 1 and K[2] - K[1] == 1:  # a connected 3-node diagram: a polyhedron
        labs = tuple(labels[K[0]:K[2]])
        key = (labs, r)
        if key not in _POLYHEDRON_OF:  # read backwards
            key = (labs[::-1], r[::-1])
        return _POLYHEDRON_OF[key]
    # two parts: a polygon (two joined nodes) times a segment (the lone node, ringed)
    pair = [k for k in K if any(abs(k - o) == 1 for o in K if o != k)]
    m = labels[min(pair)]
    both = all(rings[k] for k in pair)
    return _prism_cell(2 * m if both else m)


# ---------------------------------------------------------------------------------------------
# Non-Wythoffian polychora and polyhedra from small convex hulls
# ---------------------------------------------------------------------------------------------


def _hull_facets(points: np.ndarray):
    """Facets of the convex hull of ``points`` (every point a corner): (list of vertex-index arrays, normals, offsets).

    For small point sets only (at most a few hundred points): coplanar simplices of qhull are
    merged by their (rounded) hyperplanes.
    """
    hull = ConvexHull(points)
    eq = hull.equations
    key = np.round(eq, 7)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    d = points.shape[1]
    normals, offsets = eq[first, :d], -eq[first, d]
    inc = np.abs(points @ normals.T - offsets) <= 1e-8
    return [np.flatnonzero(inc[:, k]) for k in range(len(first))], inc


def _hull_combinatorics(points: np.ndarray, cell_namer=None) -> Combinatorics:
    """Combinatorics of a small convex 4-polytope from its hull (used for the 96- and 100-vertex ones)."""
    cells_v, inc = _hull_facets(points)
    incT = inc.T.astype(np.int32)
    shared = incT @ incT.T
    ci, cj = np.nonzero(np.triu(shared >= 3, k=1))
    faces = [_polytopes.order_cycle(points, np.flatnonzero(inc[:, a] & inc[:, b])) for a, b in zip(ci, cj)]
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


def _snub_24_cell() -> Combinatorics:
    """The 600-cell without the 24 vertices of an inscribed 24-cell: 96 vertices, 24 icosahedra, 120 tetrahedra."""
    v = _polytopes.polytope("600-cell").vertices
    # the inscribed 24-cell: the 24 vertices that are permutations of (±1,0,0,0), (±½,±½,±½,±½)
    # times the 600-cell's scale, i.e. those with every coordinate in {0, ±s/2, ±s}
    s = np.abs(v).max()
    frac = np.abs(v) / s
    in24 = np.all(np.isclose(frac, 0) | np.isclose(frac, 0.5) | np.isclose(frac, 1), axis=1)
    assert in24.sum() == 24
    return _hull_combinatorics(v[~in24], {4: "tetrahedron", 20: "icosahedron"}.get)


def _grand_antiprism() -> Combinatorics:
    """The 600-cell without two great decagons in completely orthogonal planes: 100 vertices,
    20 pentagonal antiprisms, 300 tetrahedra."""
    v = _polytopes.polytope("600-cell").vertices
    r = np.linalg.norm(v[0])
    d = np.linalg.norm(v - v[0], axis=1)
    b = int(np.argmin(np.where(d > 1e-9, d, np.inf)))  # a neighbour of vertex 0
    q, _ = np.linalg.qr(np.stack([v[0], v[b]], axis=1))  # orthonormal basis of their plane
    proj = np.linalg.norm(v @ q, axis=1)
    ring1 = np.isclose(proj, r)
    ring2 = np.isclose(proj, 0.0, atol=1e-9)
    assert ring1.sum() == 10 and ring2.sum() == 10
    return _hull_combinatorics(v[~(ring1 | ring2)], {4: "tetrahedron", 12: "pentagonal antiprism"}.get)


# ---------------------------------------------------------------------------------------------
# Polyhedra (3-D): Platonic and Archimedean solids, for the prisms
# ---------------------------------------------------------------------------------------------

#: polyhedron name -> (Dynkin symbol, labels, rings) or ("snub", labels)
_POLYHEDRA = {
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
_ADJECTIVE = {
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
    from scipy.optimize import fsolve

    g = _group(tuple(labels))
    r = g.reflections
    rot = [r[0] @ r[1], r[1] @ r[2], r[0] @ r[2]]

    def eqs(p):
        return [np.linalg.norm(p - m @ p) - 2.0 for m in rot]

    p = fsolve(eqs, np.linalg.solve(g.roots, np.ones(3)))
    even = np.linalg.det(g.mats) > 0
    pts = g.mats[even] @ p
    faces, _ = _hull_facets(pts)
    faces = [_polytopes.order_cycle(pts, f) for f in faces]
    return Combinatorics(pts, _edges_of(faces), faces, [])


@functools.lru_cache(maxsize=None)
def polyhedron(name: str) -> Combinatorics:
    """A Platonic or Archimedean solid with edge 2, centred: vertices, edges, faces (cycles)."""
    _, labels, rings = _POLYHEDRA[name]
    if rings is None:
        return _snub_polyhedron(labels)
    return wythoff(labels, rings)


# ---------------------------------------------------------------------------------------------
# Prismatic polychora
# ---------------------------------------------------------------------------------------------


def _prism(base: Combinatorics, base_name: str) -> Combinatorics:
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
        nm = _prism_cell(len(f))
        if nm not in names:
            names.append(nm)
        types.append(names.index(nm))
    edges = np.concatenate([base.edges, base.edges + n, np.stack([np.arange(n), np.arange(n) + n], axis=1)])
    ftypes = [len(f) for f in faces]
    fk = sorted(set(ftypes))
    return Combinatorics(vertices, edges, faces, cells, [fk.index(s) for s in ftypes], types, names)


def _antiprism(p: int) -> Combinatorics:
    """The uniform p-gonal antiprism with edge 2, centred (3-D)."""
    R = 1.0 / math.sin(math.pi / p)
    h = 0.5 * math.sqrt(4.0 - (2.0 * R * math.sin(math.pi / (2 * p))) ** 2)
    k = np.arange(2 * p)
    ang = math.pi * k / p
    vertices = np.stack([R * np.cos(ang), R * np.sin(ang), np.where(k % 2 == 0, h, -h)], axis=1)
    faces = [k[0::2], k[1::2][::-1]] + [np.array([i, (i + 1) % (2 * p), (i + 2) % (2 * p)]) for i in range(2 * p)]
    return Combinatorics(vertices, _edges_of(faces), faces, [])


def _duoprism(p: int, q: int) -> Combinatorics:
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
    names = list(dict.fromkeys([_prism_cell(p), _prism_cell(q)]))
    types = [names.index(_prism_cell(p))] * q + [names.index(_prism_cell(q))] * p
    ftypes = [0] * q + [1 if p != q else 0] * p + [2] * (p * q)
    return Combinatorics(vertices, _edges_of(faces), faces, cells, ftypes, types, names)


# ---------------------------------------------------------------------------------------------
# The table of names
# ---------------------------------------------------------------------------------------------

_GROUPS = {"A4": (3, 3, 3), "B4": (4, 3, 3), "F4": (3, 4, 3), "H4": (5, 3, 3)}
#: the regular polytope at each end of a diagram: (node 0 ringed, node 3 ringed)
_ENDS = {"A4": ("5-cell", "5-cell"), "B4": ("tesseract", "16-cell"), "F4": ("24-cell", "24-cell"),
         "H4": ("120-cell", "600-cell")}
#: ring pattern (node 0 .. node 3) -> operator on P (node 0 end) or Q (node 3 end)
_OPERATORS = {
    "xooo": ("", "P"), "oxoo": ("rectified", "P"), "ooxo": ("rectified", "Q"), "ooox": ("", "Q"),
    "xxoo": ("truncated", "P"), "xoxo": ("cantellated", "P"), "xoox": ("runcinated", "P"),
    "oxxo": ("bitruncated", "P"), "oxox": ("cantellated", "Q"), "ooxx": ("truncated", "Q"),
    "xxxo": ("cantitruncated", "P"), "xxox": ("runcitruncated", "P"), "xoxx": ("runcitruncated", "Q"),
    "oxxx": ("cantitruncated", "Q"), "xxxx": ("omnitruncated", "P"),
}
#: the same polytope under two names: B4 patterns that are F4 polytopes, regular names of the core
_SAME = {"rectified 16-cell": "24-cell", "cantellated 16-cell": "rectified 24-cell",
         "cantitruncated 16-cell": "truncated 24-cell", "tesseract": "8-cell"}
#: the family label of each group in `polytope_names`
_FAMILY = {"A4": "A4: 5-cell family [3,3,3]", "B4": "B4: tesseract / 16-cell family [4,3,3]",
           "F4": "F4: 24-cell family [3,4,3]", "H4": "H4: 120-cell / 600-cell family [5,3,3]"}
_REGULAR_DYNKIN = {"5-cell": "x3o3o3o", "8-cell": "x4o3o3o", "16-cell": "o4o3o3x", "24-cell": "x3o4o3o",
                   "120-cell": "x5o3o3o", "600-cell": "o5o3o3x"}
_POLYGON_PREFIX = _POLYGON_WORDS


def _symbol(labels, pattern: str) -> str:
    return "".join(c + (str(m) if k < len(labels) else "") for k, (c, m) in enumerate(zip(pattern, (*labels, 0))))


@functools.lru_cache(maxsize=None)
def _table():
    """(entries, alias, families): canonical name -> entry dict; normalised alias -> canonical
    name; family label -> canonical names in order."""
    entries, alias = {}, {}
    families = {_FAMILY[g]: [] for g in _GROUPS}

    def add(canon, family, kind, symbol=None, *aliases, **data):
        if canon not in entries:
            entries[canon] = dict(name=canon, family=family, kind=kind, symbol=symbol, **data)
            families.setdefault(family, []).append(canon)
        for a in (canon, symbol, *aliases):
            if a:
                alias.setdefault(_norm(a), canon)

    # F4 before B4: three B4 patterns are F4 polytopes and are named (and built) as those
    for gname in ("A4", "F4", "B4", "H4"):
        labels = _GROUPS[gname]
        P, Q = _ENDS[gname]
        for pattern, (op, end) in _OPERATORS.items():  # every "P" pattern precedes its reverse
            name = f"{op} {P if end == 'P' else Q}".strip()
            name = {"tesseract": "8-cell"}.get(name, name)
            canon = _SAME.get(name, name)
            sym = _symbol(labels, pattern)
            extra = [f"{op} {Q}"] if op in ("runcinated", "bitruncated", "omnitruncated") and P != Q else []
            if canon in entries:  # a reversed A4 / F4 diagram, or a B4 pattern of an F4 polytope
                for a in (sym, name, *extra):
                    alias.setdefault(_norm(a), canon)
                continue
            add(canon, _FAMILY[gname], "regular" if op == "" else "wythoff", sym, *extra,
                labels=labels, rings=tuple(c == "x" for c in pattern))
    fam = "non-Wythoffian: snub 24-cell and grand antiprism"
    add("snub 24-cell", fam, "snub24", "s3s4o3o", "o3o4s3s", "snub icositetrachoron")
    add("grand antiprism", fam, "grand", None, "gap", "pentagonal double antiprismoid")
    fam = "prisms over the Platonic and Archimedean solids"
    for poly, (psym, _, _) in _POLYHEDRA.items():
        canon = f"{_ADJECTIVE[poly]} prism"
        if poly == "cube":  # the cubic prism is the tesseract
            for a in (canon, f"{poly} prism", psym + " x"):
                alias.setdefault(_norm(a), "8-cell")
            continue
        add(canon, fam, "prism", psym + " x", f"{poly} prism", base=poly)
    fam = f"duoprisms p-q (3 <= p <= q <= {MAX_P})"
    for p in range(3, MAX_P + 1):
        for q in range(p, MAX_P + 1):
            names = [f"{p}-{q} duoprism", f"{q}-{p} duoprism", f"x{q}o x{p}o"]
            if p == 4 or q == 4:  # the prism over a q-gonal (p-gonal) prism
                names += [f"{w} prism prism" for w in _polygon_words(q if p == 4 else p)]
            if p == 4 and q == 4:  # the tesseract
                for a in names + [f"x{p}o x{q}o"]:
                    alias.setdefault(_norm(a), "8-cell")
                continue
            add(f"{p}-{q} duoprism", fam, "duoprism", f"x{p}o x{q}o", *names, p=p, q=q)
    fam = f"antiprismatic prisms (3 <= p <= {MAX_P})"
    for p in range(3, MAX_P + 1):
        words = [f"{p}-antiprismatic prism", f"{p}-gonal antiprismatic prism", f"{p}-gonal antiprism prism",
                 f"{p}-antiprism prism", f"s2s{2 * p}o x"]
        if p in _POLYGON_PREFIX:
            words += [f"{_POLYGON_PREFIX[p]} antiprismatic prism", f"{_POLYGON_PREFIX[p]} antiprism prism"]
        if p == 3:  # the triangular antiprism is the octahedron
            for a in words:
                alias.setdefault(_norm(a), "octahedral prism")
            continue
        add(f"{p}-antiprismatic prism", fam, "antiprism", f"s2s{2 * p}o x", *words, p=p)
    # the regular six under the core's own names and aliases
    for canon in _polytopes.POLYTOPE_NAMES:
        for a in (canon, *_polytopes._ALIASES[canon]):
            alias.setdefault(_norm(a), canon)
    return entries, alias, families


def _polygon_words(m: int) -> list:
    """How a regular m-gonal prism may be called: "pentagonal", "5-gonal", "5"."""
    out = [f"{m}-gonal", f"{m}"]
    if m in _POLYGON_PREFIX:
        out.append(_POLYGON_PREFIX[m])
    return out


def _norm(name: str) -> str:
    """Case, spaces, underscores and hyphens do not matter, except a hyphen between two numbers."""
    s = name.strip().lower().replace("_", " ")
    s = re.sub(r"(?<=\d)\s*-\s*(?=\d)", "~", s)  # keep "5-7"
    return re.sub(r"[\s\-]+", "", s)


# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


def canonical_name(name) -> str | None:
    """The canonical name of a polychoron given by any accepted name or Dynkin symbol, else None.

    >>> canonical_name("o3x3o3o"), canonical_name("Truncated Tesseract"), canonical_name("7-5 duoprism")
    ('rectified 5-cell', 'truncated tesseract', '5-7 duoprism')
    """
    if not isinstance(name, str):
        raise TypeError(f"Expected a polychoron name (str), got {type(name).__name__}")
    return _table()[1].get(_norm(name))


def _canonical_or_raise(name) -> str:
    canon = canonical_name(name)
    if canon is None:
        raise ValueError(
            f"Unknown polychoron {name!r}; rot4d_widget.geometry.uniform.polytope_names() lists the accepted names "
            "by family (e.g. 'rectified 5-cell', 'truncated tesseract', 'omnitruncated 120-cell', "
            "'snub 24-cell', 'grand antiprism', '5-7 duoprism', 'truncated cubic prism', "
            "'7-antiprismatic prism'), and linear Dynkin symbols such as 'o3x3o3o', 'x4x3o3o', 'x5x3x3x' "
            "are accepted too")
    return canon


def polytope_names() -> dict:
    """``{family: [canonical names]}``: the 47 non-prismatic polychora in four Coxeter families
    plus the two non-Wythoffian ones, then the prismatic families.  The regular six appear in
    their families under the core's names ("5-cell", "8-cell", ...)."""
    return {fam: list(names) for fam, names in _table()[2].items()}


def dynkin_symbol(name) -> str | None:
    """The linear Coxeter–Dynkin symbol of a polychoron ("x5x3x3x"), or None for the grand antiprism.

    Prismatic ones are written as products: "x5o x7o" (5-7 duoprism), "x4x3o x" (truncated
    cubic prism), "s2s14o x" (7-antiprismatic prism); "s" marks a snub (alternated) node.
    """
    canon = _canonical_or_raise(name)
    if canon in _REGULAR_DYNKIN:
        return _REGULAR_DYNKIN[canon]
    return _table()[0][canon]["symbol"]


def family(name) -> str:
    """The family label (a key of `polytope_names`) of a polychoron."""
    return _table()[0][_canonical_or_raise(name)]["family"]


def combinatorics(name) -> Combinatorics:
    """Vertices, edges, 2-faces (vertex cycles) and cells (face indices) of a polychoron.

    For the regular six this is the Wythoff construction (vertices in the group's order and
    orientation, not the core's arrays): `build` returns the core's objects instead.  Cached:
    treat the arrays as read-only.
    """
    return _combinatorics(_canonical_or_raise(name))


@functools.lru_cache(maxsize=64)
def _combinatorics(canon: str) -> Combinatorics:
    if canon in _REGULAR_DYNKIN:
        sym = _REGULAR_DYNKIN[canon]
        labels = tuple(int(c) for c in sym[1::2])
        return wythoff(labels, tuple(c == "x" for c in sym[0::2]))
    e = _table()[0][canon]
    kind = e["kind"]
    if kind == "wythoff":
        return wythoff(e["labels"], e["rings"])
    if kind == "snub24":
        return _snub_24_cell()
    if kind == "grand":
        return _grand_antiprism()
    if kind == "prism":
        return _prism(polyhedron(e["base"]), e["base"])
    if kind == "duoprism":
        return _duoprism(e["p"], e["q"])
    if kind == "antiprism":
        return _prism(_antiprism(e["p"]), f"{_POLYGON_PREFIX.get(e['p'], str(e['p']) + '-gonal')} antiprism")
    raise AssertionError(kind)


def _as_polytope(comb: Combinatorics, name: str):
    """A core `Polytope` from explicit combinatorics (``Polytope(vertices, faces, cells)``).

    Validated even though the construction is exact: the constructor's checks (planar convex
    faces, closed convex cells, orientable boundary) are part of the build times in
    docs/uniform.md (`benchmarks/uniform_build.py`).
    """
    return _polytopes.Polytope(comb.vertices, comb.faces, comb.cells, name=name)


@functools.lru_cache(maxsize=None)
def _built(canon: str):
    if canon in _REGULAR_DYNKIN:
        return _polytopes.polytope(canon)
    return _as_polytope(combinatorics(canon), canon)


def build(name):
    """The polychoron called ``name`` as a `rot4d_widget.geometry.polytopes.Polytope` (edge 2, centred).

    ``name``: a canonical or common name, an alias or a linear Dynkin symbol (see the module
    docstring; `polytope_names` lists the canonical names).  The regular six are the core's own
    objects (``build("x3o3o3o") is polytope("5-cell")``).  Built once and cached.

    Raises TypeError for a non-str and ValueError, saying where the names are listed, for an
    unknown name.
    """
    return _built(_canonical_or_raise(name))
