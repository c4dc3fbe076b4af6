"""The ten regular star polychora (Schläfli–Hess), built from the 600-cell's and 120-cell's vertices.

Construction (nothing is read from a file or a table of faces): on the unit 3-sphere, nine of the
ten share the 600-cell's 120 vertices and the great grand stellated 120-cell has the 120-cell's
600.  Each cell lies in a hyperplane ``v . u = h``: ``u`` runs over the 600-cell's vertex
directions (120 cells; the 120-cell's 600 directions for the grand 600-cell's 600 cells), and
the vertices at that level form the cell's convex hull -- an icosahedron (12), a dodecahedron
(20) or a tetrahedron (4) of hull edge ``a``, so ``h = sqrt(1 - R(a)**2)``, R the hull's
circumradius.  Within a cell the faces are the regular polygons of the cell's symbol on its
vertices: triangles {3} and pentagons {5} of side ``edge``, pentagrams {5/2} of side ``edge``
(their hull pentagons have side ``edge / phi``) listed as 5-cycles in pentagram order.  A face
shared by two cells is one face.  The edges are the faces' sides.

=============================  ============  ============  ======  ===============  =====
name                           symbol        hull, a       cell    edge (unit)      dens.
=============================  ============  ============  ======  ===============  =====
icosahedral 120-cell           {3,5,5/2}     ico, 1/phi    {3,5}   1/phi            4
small stellated 120-cell       {5/2,5,3}     ico, 1/phi    {5/2,5} 1                4
great 120-cell                 {5,5/2,5}     ico, 1/phi    {5,5/2} 1/phi            6
grand 120-cell                 {5,3,5/2}     doe, 1/phi    {5,3}   1/phi            20
great stellated 120-cell       {5/2,3,5}     doe, 1/phi    {5/2,3} phi              20
grand stellated 120-cell       {5/2,5,5/2}   ico, 1        {5/2,5} phi              66
great grand 120-cell           {5,5/2,3}     ico, 1        {5,5/2} 1                76
great icosahedral 120-cell     {3,5/2,5}     ico, 1        {3,5/2} phi              76
grand 600-cell                 {3,3,5/2}     tet, phi      {3,3}   phi              191
great grand stellated 120-cell {5/2,3,3}     doe, 1/sqrt2  {5/2,3} phi**2/sqrt2     191
=============================  ============  ============  ======  ===============  =====

Scale: every one has **edge length 2** and is centred on the origin, like the regular six
(`rot4d_widget.geometry.regular`), so its circumradius is ``2 / edge(unit)``: 2*phi (the
600-cell's) for edge 1/phi, 2 for edge 1, 2/phi for edge phi.  Counts and densities are those
published (Wikipedia's "Schläfli–Hess polychoron", the Polytope Wiki); tests/geometry/test_star_regular.py
checks them, the density by the boundary's winding number round the centre.

>>> star_name("{5/2,3,3}"), star_name("Great Grand Stellated 120-cell"), star_name("600-cell")
('great grand stellated 120-cell', 'great grand stellated 120-cell', None)
"""

from __future__ import annotations

import functools
import itertools
import math
from typing import NamedTuple

import numpy as np

from .mesh import Polytope
from .regular import PHI, cell120_vertices, cell600_vertices

__all__ = ["STAR_NAMES", "STAR_FAMILY", "StarSpec", "SPECS", "star_name", "star_arrays", "star_polytope"]

#: the family label of the ten in `rot4d_widget.polytope_names`
STAR_FAMILY = "regular star (Schläfli–Hess) polychora"


class StarSpec(NamedTuple):
    """How one star polychoron is built: its Schläfli symbol, vertices ("600": the 600-cell's
    120, "120": the 120-cell's 600), cells' hull ("icosahedron" / "dodecahedron" / "tetrahedron")
    and its edge ``hull_edge`` on the unit sphere, the cell's symbol, the polychoron's edge on the
    unit sphere, its published (V, E, F, C) and density, and other names."""

    symbol: str
    vertices: str
    hull: str
    hull_edge: float
    cell: str
    edge: float
    counts: tuple
    density: int
    aliases: tuple


_IP = 1 / PHI
_S2 = 1 / math.sqrt(2.0)
#: canonical name -> StarSpec (Conway's names, in order of density)
SPECS = {
    "icosahedral 120-cell": StarSpec("{3,5,5/2}", "600", "icosahedron", _IP, "{3,5}", _IP,
                                     (120, 720, 1200, 120), 4, ("polyicosahedron", "faceted hexacosichoron")),
    "small stellated 120-cell": StarSpec("{5/2,5,3}", "600", "icosahedron", _IP, "{5/2,5}", 1.0,
                                         (120, 1200, 720, 120), 4,
                                         ("stellated polydodecahedron", "small stellated hecatonicosachoron")),
    "great 120-cell": StarSpec("{5,5/2,5}", "600", "icosahedron", _IP, "{5,5/2}", _IP,
                               (120, 720, 720, 120), 6, ("great polydodecahedron", "great hecatonicosachoron")),
    "grand 120-cell": StarSpec("{5,3,5/2}", "600", "dodecahedron", _IP, "{5,3}", _IP,
                               (120, 720, 720, 120), 20, ("grand polydodecahedron", "grand hecatonicosachoron")),
    "great stellated 120-cell": StarSpec("{5/2,3,5}", "600", "dodecahedron", _IP, "{5/2,3}", PHI,
                                         (120, 720, 720, 120), 20,
                                         ("great stellated polydodecahedron", "great stellated hecatonicosachoron")),
    "grand stellated 120-cell": StarSpec("{5/2,5,5/2}", "600", "icosahedron", 1.0, "{5/2,5}", PHI,
                                         (120, 720, 720, 120), 66,
                                         ("grand stellated polydodecahedron", "grand stellated hecatonicosachoron")),
    "great grand 120-cell": StarSpec("{5,5/2,3}", "600", "icosahedron", 1.0, "{5,5/2}", 1.0,
                                     (120, 1200, 720, 120), 76,
                                     ("great grand polydodecahedron", "great grand hecatonicosachoron")),
    "great icosahedral 120-cell": StarSpec("{3,5/2,5}", "600", "icosahedron", 1.0, "{3,5/2}", PHI,
                                           (120, 720, 1200, 120), 76,
                                           ("great polyicosahedron", "great faceted hexacosichoron")),
    "grand 600-cell": StarSpec("{3,3,5/2}", "600", "tetrahedron", PHI, "{3,3}", PHI,
                               (120, 720, 1200, 600), 191, ("grand polytetrahedron", "grand hexacosichoron")),
    "great grand stellated 120-cell": StarSpec("{5/2,3,3}", "120", "dodecahedron", _S2, "{5/2,3}", PHI**2 * _S2,
                                               (600, 1200, 720, 120), 191,
                                               ("great grand stellated polydodecahedron",
                                                "great grand stellated hecatonicosachoron")),
}
STAR_NAMES = tuple(SPECS)

#: circumradius / edge of each hull; the number of its vertices
_HULL = {"icosahedron": (math.sin(2 * math.pi / 5), 12), "dodecahedron": (math.sqrt(3.0) * PHI / 2, 20),
         "tetrahedron": (math.sqrt(3.0 / 8.0), 4)}
#: faces of a cell: (polygon, number of faces)
_CELL_FACES = {"{3,5}": ("{3}", 20), "{3,5/2}": ("{3}", 20), "{5,5/2}": ("{5}", 12), "{5/2,5}": ("{5/2}", 12),
               "{5,3}": ("{5}", 12), "{5/2,3}": ("{5/2}", 12), "{3,3}": ("{3}", 4)}


def _norm(name: str) -> str:
    return "".join(c for c in name.lower() if c not in " \t\n-_")


_NAME_OF = {_norm(a): canon for canon, s in SPECS.items() for a in (canon, s.symbol, *s.aliases)}


def star_name(name: str) -> str | None:
    """The canonical name of a regular star polychoron given by name, alias or Schläfli symbol
    (case, spaces, hyphens and underscores do not matter), else None."""
    return _NAME_OF.get(_norm(name))


def _unit(points: np.ndarray) -> np.ndarray:
    return points / np.linalg.norm(points, axis=1)[:, None]


@functools.lru_cache(maxsize=None)
def _unit_vertices(which: str, dual: bool = False) -> np.ndarray:
    """The 600-cell's ("600") or 120-cell's ("120") vertices on the unit sphere (read-only), as in
    `rot4d_widget.geometry.regular`; ``dual``: the directions of the other's cells instead (its
    dual's vertices: the even permutations of regular.py's coordinates made odd by swapping x, y)."""
    v = _unit(cell600_vertices() if which == "600" else cell120_vertices())
    if dual:
        v = np.ascontiguousarray(v[:, [1, 0, 2, 3]])
    v.setflags(write=False)
    return v


def _polygons(points: np.ndarray, side: float, sides: int, tol: float) -> list:
    """Every regular convex ``sides``-gon (3 or 5) of side ``side`` among ``points`` (k, d), as
    index cycles in convex order: cycles of the side-graph whose non-adjacent corners are
    ``side * phi`` apart (for 5; equal distances fix a regular pentagon up to isometry)."""
    d = np.linalg.norm(points[:, None] - points[None], axis=2)
    adj = np.abs(d - side) < tol
    if sides == 3:
        return [[i, j, k] for i, j, k in itertools.combinations(range(len(points)), 3)
                if adj[i, j] and adj[j, k] and adj[i, k]]
    diag = np.abs(d - side * PHI) < tol
    out = []
    for a in range(len(points)):  # a = the smallest index of the cycle
        nb = [b for b in np.flatnonzero(adj[a]) if b > a]
        for b, e in itertools.permutations(nb, 2):
            if b > e:  # each cycle once, not in both directions
                continue
            for c in np.flatnonzero(adj[b] & diag[a] & diag[e]):
                for dd in np.flatnonzero(adj[c] & adj[e] & diag[a] & diag[b]):
                    if c > a and dd > a and diag[c, e]:
                        out.append([a, int(b), int(c), int(dd), int(e)])
    return out


def _cell_faces(points: np.ndarray, cell: str, edge: float, tol: float) -> list:
    """The faces of one cell of symbol ``cell`` on its vertices ``points`` (local index cycles)."""
    poly, count = _CELL_FACES[cell]
    if poly == "{3}":
        faces = _polygons(points, edge, 3, tol)
    elif poly == "{5}":
        faces = _polygons(points, edge, 5, tol)
    else:  # a pentagram of side `edge` on a pentagon of side edge/phi, in pentagram order
        faces = [[f[0], f[2], f[4], f[1], f[3]] for f in _polygons(points, edge / PHI, 5, tol)]
    if len(faces) != count:
        raise AssertionError(f"a {cell} cell found {len(faces)} faces {poly} of side {edge:.6g}, not {count}")
    return faces


@functools.lru_cache(maxsize=None)
def star_arrays(name: str):
    """``(vertices, faces, cells)`` of a star polychoron (any accepted name): vertices (V, 4)
    float64 with edge 2, faces as lists of vertex indices (pentagrams in pentagram order), cells
    as lists of face indices.  Cached: treat as read-only."""
    canon = star_name(name)
    if canon is None:
        raise ValueError(f"Unknown regular star polychoron {name!r}; expected one of {', '.join(STAR_NAMES)} "
                         "or a Schläfli symbol such as '{5/2,3,3}'")
    s = SPECS[canon]
    v = _unit_vertices(s.vertices)
    # cell directions: the 600-cell's vertices (120 cells), the 120-cell's for the 600 tetrahedra;
    # the other polytope's directions must be its dual's, aligned with the vertices
    other = "120" if s.hull == "tetrahedron" else "600"
    dirs = _unit_vertices(other, dual=other != s.vertices)
    ratio, size = _HULL[s.hull]
    h = math.sqrt(1.0 - (ratio * s.hull_edge) ** 2)
    tol = 1e-9
    level = np.abs(v @ dirs.T - h) < tol  # (V, cells): vertex at the cell's level
    faces, index, cells = [], {}, []
    for c in range(dirs.shape[0]):
        members = np.flatnonzero(level[:, c])
        if len(members) != size:
            raise AssertionError(f"{canon}: {len(members)} vertices at level {h:.9g} of cell {c}, not {size}")
        row = []
        for f in _cell_faces(v[members], s.cell, s.edge, tol):
            cyc = [int(members[i]) for i in f]
            key = frozenset(cyc)
            if key not in index:
                index[key] = len(faces)
                faces.append(cyc)
            row.append(index[key])
        cells.append(row)
    return v * (2.0 / s.edge), faces, cells


def star_polytope(name: str) -> Polytope:
    """The regular star polychoron of a name, alias or Schläfli symbol as a `Polytope` (edge 2,
    centred), built once and cached: every name of one gives the same object."""
    canon = star_name(name)
    if canon is None:
        star_arrays(name)  # the ValueError naming the ten
    return _built(canon)


@functools.lru_cache(maxsize=None)
def _built(canon: str) -> Polytope:
    v, f, c = star_arrays(canon)
    return Polytope(v, f, c, name=canon)
