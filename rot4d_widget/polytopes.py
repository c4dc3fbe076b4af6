"""Convex 4-polytopes: vertices plus combinatorics built from the geometry.

`Polytope(vertices)` finds everything else once: the cells are the facets of
scipy's 4-D convex hull (coplanar simplices merged), the 2-faces are the
intersections of pairs of cells that share three or more vertices, each
ordered as a cycle, and the edges are consecutive vertices of those cycles.
So any convex 4-polytope can be given, and the six regular polychora are
built with the same code.

`polytope(name)` gives the six regular polychora, all with edge length 2 and
centred on the origin, from the textbook coordinates (scaled to edge 2):

========  ==========  ===================================================
name      Schläfli    vertices before scaling
========  ==========  ===================================================
5-cell    {3,3,3}     the paper's eqs. (8)-(12) with a = 2
8-cell    {4,3,3}     (±1, ±1, ±1, ±1)
16-cell   {3,3,4}     permutations of (±1, 0, 0, 0)
24-cell   {3,4,3}     permutations of (±1, ±1, 0, 0)
600-cell  {3,3,5}     permutations of (±1,0,0,0), (±½,±½,±½,±½), even
                      permutations of ½(±φ, ±1, ±1/φ, 0)
120-cell  {5,3,3}     the 600 points of circumradius √8 (see `_cell120`)
========  ==========  ===================================================
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ._arrays import sealed as _sealed
from scipy.spatial import ConvexHull

__all__ = ["Polytope", "polytope", "pentachoron", "POLYTOPE_NAMES"]

PHI = (1.0 + math.sqrt(5.0)) / 2.0

#: Canonical names, in order of vertex count.
POLYTOPE_NAMES = ("5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell")

_ALIASES = {
    "5-cell": ("5cell", "pentachoron", "simplex", "4-simplex", "pentatope", "hypertetrahedron", "{3,3,3}"),
    "8-cell": ("8cell", "tesseract", "hypercube", "octachoron", "4-cube", "{4,3,3}"),
    "16-cell": ("16cell", "hexadecachoron", "orthoplex", "cross-polytope", "4-orthoplex", "{3,3,4}"),
    "24-cell": ("24cell", "icositetrachoron", "octaplex", "{3,4,3}"),
    "120-cell": ("120cell", "hecatonicosachoron", "dodecaplex", "{5,3,3}"),
    "600-cell": ("600cell", "hexacosichoron", "tetraplex", "{3,3,5}"),
}
_NAME_OF = {}
for _canon, _aliases in _ALIASES.items():
    for _alias in (_canon, *_aliases):
        _NAME_OF[_alias] = _canon


def _normalise_name(name: str) -> str:
    return "".join(name.lower().split()).replace("_", "-")


def pentachoron(a: float = 2.0) -> "Polytope":
    """The regular pentachoron of the paper's eqs. (8)-(12), edge ``a``, centroid at the origin."""
    if isinstance(a, bool) or not isinstance(a, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected edge length `a` to be a positive number, got {type(a).__name__}")
    a = float(a)
    if not (math.isfinite(a) and a > 0):
        raise ValueError(f"Expected edge length `a` to be a positive finite number, got {a}")
    s3, s6, s10 = math.sqrt(3.0), math.sqrt(6.0), math.sqrt(10.0)
    w = -a / (2 * s10)
    vertices = np.array(
        [
            [-a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [0.0, a / s3, -a / (2 * s6), w],
            [0.0, 0.0, a * s3 / (2 * math.sqrt(2.0)), w],
            [0.0, 0.0, 0.0, 2 * a / s10],
        ]
    )
    return Polytope(vertices, name="5-cell" if a == 2.0 else f"5-cell (a={a:g})")


def _even_permutations():
    out = []
    for p in itertools.permutations(range(4)):
        inversions = sum(p[i] > p[j] for i in range(4) for j in range(i + 1, 4))
        if inversions % 2 == 0:
            out.append(p)
    return out


def _orbit(base, even_only: bool = False) -> np.ndarray:
    """All sign changes of the non-zero entries of ``base`` under (even) permutations."""
    perms = _even_permutations() if even_only else list(itertools.permutations(range(4)))
    base = np.asarray(base, dtype=float)
    signs = np.array(list(itertools.product((1.0, -1.0), repeat=4)))
    pts = np.concatenate([signs * base[list(p)] for p in perms])
    return pts


def _unique_rows(points: np.ndarray) -> np.ndarray:
    _, idx = np.unique(np.round(points, 9), axis=0, return_index=True)
    return points[np.sort(idx)]


def _cell8() -> np.ndarray:
    return np.array(list(itertools.product((-1.0, 1.0), repeat=4)))


def _cell16() -> np.ndarray:
    return _unique_rows(_orbit((1, 0, 0, 0))) * math.sqrt(2.0)


def _cell24() -> np.ndarray:
    return _unique_rows(_orbit((1, 1, 0, 0))) * math.sqrt(2.0)


def _cell600() -> np.ndarray:
    pts = np.concatenate(
        [
            _orbit((1, 0, 0, 0)),
            _orbit((0.5, 0.5, 0.5, 0.5)),
            _orbit((PHI / 2, 0.5, 1 / (2 * PHI), 0.0), even_only=True),
        ]
    )
    return _unique_rows(pts) * (2.0 * PHI)  # edge 1/phi -> 2


def _cell120() -> np.ndarray:
    """The 600 vertices of circumradius sqrt(8): permutations of (0,0,±2,±2),
    (±1,±1,±1,±√5), (±φ⁻²,±φ,±φ,±φ), (±φ⁻¹,±φ⁻¹,±φ⁻¹,±φ²) and even permutations
    of (0,±φ⁻²,±1,±φ²), (0,±φ⁻¹,±φ,±√5), (±φ⁻¹,±1,±φ,±2); edge 2/φ² scaled to 2."""
    s5 = math.sqrt(5.0)
    ip, ip2 = 1 / PHI, 1 / PHI**2
    pts = np.concatenate(
        [
            _orbit((0, 0, 2, 2)),
            _orbit((1, 1, 1, s5)),
            _orbit((ip2, PHI, PHI, PHI)),
            _orbit((ip, ip, ip, PHI**2)),
            _orbit((0, ip2, 1, PHI**2), even_only=True),
            _orbit((0, ip, PHI, s5), even_only=True),
            _orbit((ip, 1, PHI, 2), even_only=True),
        ]
    )
    return _unique_rows(pts) * PHI**2


_BUILDERS = {
    "5-cell": lambda: pentachoron(2.0).vertices,
    "8-cell": _cell8,
    "16-cell": _cell16,
    "24-cell": _cell24,
    "600-cell": _cell600,
    "120-cell": _cell120,
}


class Polytope:
    """A convex 4-polytope.

    Attributes
    ----------
    vertices : (V, 4) float64
    edges : (E, 2) intp, each row sorted
    faces : tuple of F intp arrays, each an ordered cycle of vertex indices
    cells : tuple of C tuples of face indices
    face_cells : (F, 2) intp, the two cells of each face, ascending
    circumradius : float, max distance of a vertex from the origin
    cell_normals : (C, 4) float64 outward unit normals; ``cell_offsets`` (C,)
        so that cell c lies in ``vertices @ cell_normals[c] == cell_offsets[c]``

    Every array is read-only and the sequences are tuples: a polytope is
    shared (``polytope(name)`` is cached, slicing tables are built from it
    once), so an edit anywhere would corrupt every later slice.
    """

    def __init__(self, vertices, name: str = "polytope"):
        try:
            v = np.array(vertices, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError("Expected `vertices` to be a (V, 4) array of real numbers") from None
        if v.ndim != 2 or v.shape[1] != 4 or v.shape[0] < 5:
            raise ValueError(f"Expected `vertices` to have shape (V, 4) with V >= 5, got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("Expected `vertices` to be finite")
        self.name = str(name)
        self.vertices = _sealed(v)
        self.circumradius = float(np.sqrt((v * v).sum(axis=1)).max())
        self._build()

    # -- construction ------------------------------------------------------
    def _build(self) -> None:
        v = self.vertices
        scale = float(np.abs(v).max())
        tol = 1e-9 * scale
        try:
            hull = ConvexHull(v)
        except Exception as exc:  # qhull: flat or degenerate input
            raise ValueError(f"`vertices` do not span a 4-D convex polytope: {exc}") from None
        if len(hull.vertices) != len(v):
            raise ValueError("Every vertex must be a corner of the convex hull (found interior or repeated points)")
        # cells: distinct facet hyperplanes of the hull
        eq = hull.equations
        key = np.round(eq / scale * np.array([1, 1, 1, 1, scale]), 7)
        _, first = np.unique(key, axis=0, return_index=True)
        first = np.sort(first)
        normals, offsets = eq[first, :4], -eq[first, 4]
        inc = np.abs(v @ normals.T - offsets) <= tol * 10  # (V, C) vertex-in-cell
        cell_vertices = inc.T
        # 2-faces: pairs of cells sharing >= 3 vertices
        shared = cell_vertices.astype(np.int32) @ cell_vertices.T.astype(np.int32)
        ci, cj = np.nonzero(np.triu(shared >= 3, k=1))
        face_sets = cell_vertices[ci] & cell_vertices[cj]  # (F, V)
        faces = [self._order_cycle(np.flatnonzero(row)) for row in face_sets]
        cells = [[] for _ in range(len(first))]
        for f, (a, b) in enumerate(zip(ci, cj)):
            cells[a].append(f)
            cells[b].append(f)
        edges = set()
        for cyc in faces:
            for a, b in zip(cyc, np.roll(cyc, -1)):
                edges.add((min(a, b), max(a, b)))
        self.edges = _sealed(np.array(sorted(edges), dtype=np.intp).reshape(-1, 2))
        self.faces = tuple(_sealed(f) for f in faces)
        self.cells = tuple(tuple(int(f) for f in c) for c in cells)
        self.cell_normals = _sealed(np.ascontiguousarray(normals))
        self.cell_offsets = _sealed(np.ascontiguousarray(offsets))
        self.face_cells = _sealed(np.stack([ci, cj], axis=1).astype(np.intp))  # (F, 2), ascending
        self._cell_vertex_mask = _sealed(cell_vertices)

    def _order_cycle(self, idx: np.ndarray) -> np.ndarray:
        """Order the vertices of a planar convex polygon in 4-D as a cycle."""
        p = self.vertices[idx]
        c = p.mean(axis=0)
        _, _, vt = np.linalg.svd(p - c)
        xy = (p - c) @ vt[:2].T
        return idx[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))].astype(np.intp)

    # -- conveniences ------------------------------------------------------
    @property
    def counts(self) -> tuple[int, int, int, int]:
        """(V, E, F, C)."""
        return len(self.vertices), len(self.edges), len(self.faces), len(self.cells)

    def cell_vertices(self, c: int) -> np.ndarray:
        """Vertex indices of cell ``c``."""
        return np.flatnonzero(self._cell_vertex_mask[c])

    def __repr__(self) -> str:
        v, e, f, c = self.counts
        return f"Polytope({self.name!r}, V={v}, E={e}, F={f}, C={c}, circumradius={self.circumradius:.4g})"


@functools.lru_cache(maxsize=None)
def _named(canon: str) -> Polytope:
    if canon == "5-cell":
        return pentachoron(2.0)
    return Polytope(_BUILDERS[canon](), name=canon)


def polytope(name) -> Polytope:
    """One of the six regular polychora with edge 2, by name, alias or Schläfli symbol.

    ``"5-cell"`` (pentachoron, ``"{3,3,3}"``), ``"8-cell"`` (tesseract),
    ``"16-cell"``, ``"24-cell"``, ``"120-cell"``, ``"600-cell"``.  A `Polytope`
    is returned as is.  The result is built once and cached.
    """
    if isinstance(name, Polytope):
        return name
    if not isinstance(name, str):
        raise TypeError(f"Expected a polytope name (str) or a Polytope, got {type(name).__name__}")
    canon = _NAME_OF.get(_normalise_name(name))
    if canon is None:
        allowed = ", ".join(f"{n!r} ({', '.join(_ALIASES[n][1:3])}, {_ALIASES[n][-1]})" for n in POLYTOPE_NAMES)
        raise ValueError(f"Unknown polytope {name!r}; expected one of {allowed}")
    return _named(canon)
