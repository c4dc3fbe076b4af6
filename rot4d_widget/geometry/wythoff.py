"""The Wythoff construction of a linear Coxeter–Dynkin diagram: vertices, edges, 2-faces, cells.

A finite reflection group (its elements as matrices, `ReflectionGroup`) is enumerated once; the k-faces of
the polytope of a ring pattern are connected components of its Cayley graph restricted to a few
generators (see `rot4d_widget.geometry.uniform` for the whole story).  `Combinatorics` holds the
result before it becomes a `Polytope`; the cells are named by their sub-diagrams.

>>> wythoff((3, 3, 3), (1, 0, 0, 0)).counts  # the 5-cell
(5, 10, 10, 5)
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..core._arrays import sealed as _sealed

__all__ = ["Combinatorics", "wythoff"]


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


class ReflectionGroup:
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
def reflection_group(labels: tuple) -> ReflectionGroup:
    return ReflectionGroup(labels)


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


def _components_ok(group: ReflectionGroup, K, rings) -> bool:
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


def _stabiliser(group: ReflectionGroup, K, rings) -> list:
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
    g = reflection_group(labels)
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
    for i, j in itertools.combinations(range(n), 2):
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

POLYGON_WORDS = {3: "triangular", 4: "square", 5: "pentagonal", 6: "hexagonal", 7: "heptagonal",
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


def prism_cell_name(m: int) -> str:
    """The name of the uniform m-gonal prism (the 4-gonal one is the cube)."""
    return "cube" if m == 4 else f"{POLYGON_WORDS.get(m, f'{m}-gonal')} prism"


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
    return prism_cell_name(2 * m if both else m)
