"""4-D meshes with explicit combinatorics for the tests: duoprisms, unions of unit tesseracts.

Built here by counting, independently of `Polytope`'s convex-hull path, so the
tests can compare the two.
"""

from __future__ import annotations

import itertools

import numpy as np

from rot4d_widget import Polytope


def duoprism_mesh(p: int, q: int, edge: float = 2.0):
    """The p-q duoprism, edge ``edge``: (vertices, faces, cells).

    Vertex i * q + j is (R_p cos 2πi/p, R_p sin 2πi/p, R_q cos 2πj/q, R_q sin 2πj/q).
    Faces: q p-gons (j fixed), p q-gons (i fixed), p q squares.  Cells: p q-gonal
    prisms (between q-gons i and i + 1), q p-gonal prisms.
    """
    rp, rq = edge / (2 * np.sin(np.pi / p)), edge / (2 * np.sin(np.pi / q))
    a, b = 2 * np.pi * np.arange(p) / p, 2 * np.pi * np.arange(q) / q
    i, j = np.meshgrid(np.arange(p), np.arange(q), indexing="ij")
    vertices = np.stack([rp * np.cos(a[i]), rp * np.sin(a[i]), rq * np.cos(b[j]), rq * np.sin(b[j])], -1).reshape(-1, 4)

    def vid(i, j):
        return (i % p) * q + (j % q)

    pgons = [[vid(i, j) for i in range(p)] for j in range(q)]  # faces 0 .. q-1
    qgons = [[vid(i, j) for j in range(q)] for i in range(p)]  # faces q .. q+p-1
    squares = [[vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)] for i in range(p) for j in range(q)]
    faces = pgons + qgons + squares

    def sq(i, j):
        return q + p + (i % p) * q + (j % q)

    qprisms = [[q + i, q + (i + 1) % p] + [sq(i, j) for j in range(q)] for i in range(p)]
    pprisms = [[j, (j + 1) % q] + [sq(i, j) for i in range(p)] for j in range(q)]
    return vertices, faces, qprisms + pprisms


def duoprism(p: int, q: int, **kw) -> Polytope:
    v, f, c = duoprism_mesh(p, q)
    return Polytope(v, f, c, name=f"{p}-{q} duoprism", **kw)


def prism_mesh(vertices3, faces3, height: float = 1.0):
    """The 4-D prism over a polyhedron (its vertices (n, 3) and faces): (vertices, faces, cells).

    Vertices: the polyhedron at w = 0, then at w = ``height``.  Faces: the polyhedron's
    faces below (0 .. k-1) and above (k .. 2k-1), then a square over each of its edges.
    Cells: the two caps, then a prism over each face.
    """
    v3 = np.asarray(vertices3, dtype=float)
    n, k = len(v3), len(faces3)
    vertices = np.concatenate([np.column_stack([v3, np.zeros(n)]), np.column_stack([v3, np.full(n, height)])])
    edges = sorted({tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in faces3 for i in range(len(f))})
    side = {e: 2 * k + i for i, e in enumerate(edges)}
    faces = [list(f) for f in faces3] + [[i + n for i in f] for f in faces3] + [[a, b, b + n, a + n] for a, b in edges]
    cells = [list(range(k)), list(range(k, 2 * k))]
    for j, f in enumerate(faces3):
        cells.append([j, k + j] + [side[tuple(sorted((f[i], f[(i + 1) % len(f)])))] for i in range(len(f))])
    return vertices, faces, cells


def tesseract_union_mesh(cubes, centre=True):
    """Boundary of a union of unit tesseracts [k, k+1]^4 at integer positions ``cubes``.

    Every facet of a tesseract whose neighbour across it is not in the union is a
    cell (a unit cube); faces are the unit squares of those cubes, each listed once.
    Cells stay separate cubes where two of them are coplanar and adjacent (a flat
    ridge).  Returns (vertices, faces, cells, pieces) where ``pieces`` are the
    tesseracts' corners, and the vertices are shifted by the union's centroid when
    ``centre``.
    """
    cubes = [tuple(int(x) for x in c) for c in cubes]
    occupied = set(cubes)
    eye = np.eye(4, dtype=int)
    vid, faces, fid, cells = {}, [], {}, []

    def vertex(pt):
        return vid.setdefault(tuple(int(x) for x in pt), len(vid))

    def face(base, a1, a2):
        key = (tuple(int(x) for x in base), a1, a2)
        if key not in fid:
            b = np.array(base)
            fid[key] = len(faces)
            faces.append([vertex(b), vertex(b + eye[a1]), vertex(b + eye[a1] + eye[a2]), vertex(b + eye[a2])])
        return fid[key]

    for c in cubes:
        for axis in range(4):
            for side in (0, 1):
                nb = tuple(np.array(c) + (1 if side else -1) * eye[axis])
                if nb in occupied:
                    continue
                base = np.array(c) + side * eye[axis]
                others = [a for a in range(4) if a != axis]
                cell = []
                for a1, a2 in itertools.combinations(others, 2):
                    (a3,) = [a for a in others if a not in (a1, a2)]
                    cell.append(face(base, a1, a2))
                    cell.append(face(base + eye[a3], a1, a2))
                cells.append(cell)
    vertices = np.array(sorted(vid, key=vid.get), dtype=float)
    shift = vertices.mean(axis=0) if centre else np.zeros(4)
    pieces = [np.array(list(itertools.product(*[(x, x + 1) for x in c])), dtype=float) - shift for c in cubes]
    return vertices - shift, faces, cells, pieces


def stellated_tesseract_mesh(height: float):
    """The tesseract [-1, 1]^4 with a 4-D pyramid of ``height`` on each of its 8 cubes.

    Cells: over each cube, a square pyramid on each of its 6 squares (48 in all); faces: the
    tesseract's 24 squares (each between the pyramids of its two cubes) and a triangle on each
    cube edge and apex (96).  Height 1 gives the 24-cell (the two pyramids on a square make an
    octahedron: flat ridges); above 1 the squares are reflex ridges.  Returns (vertices, faces,
    cells, pieces): the pieces are the tesseract and the 8 pyramids, as point arrays.
    """
    cube_pts = np.array(list(itertools.product((-1.0, 1.0), repeat=4)))
    apexes = [(k, s) for k in range(4) for s in (-1.0, 1.0)]
    vertices = np.concatenate([cube_pts, [s * (1.0 + height) * np.eye(4)[k] for k, s in apexes]])
    squares = {}  # frozenset of 4 vertex ids -> face id
    faces, triangles, cells = [], {}, []
    for a1, a2 in itertools.combinations(range(4), 2):
        rest = [k for k in range(4) if k not in (a1, a2)]
        for b1, b2 in itertools.product((-1.0, 1.0), repeat=2):
            def vid(u, v):
                x = np.zeros(4)
                x[a1], x[a2], x[rest[0]], x[rest[1]] = u, v, b1, b2
                return int(np.flatnonzero(np.all(cube_pts == x, axis=1))[0])
            cyc = [vid(-1, -1), vid(1, -1), vid(1, 1), vid(-1, 1)]
            squares[frozenset(cyc)] = len(faces)
            faces.append(cyc)
    pieces = [cube_pts]
    for j, (k, s) in enumerate(apexes):
        apex = 16 + j
        in_cube = [f for f, cyc in enumerate(faces[:24]) if np.all(cube_pts[cyc, k] == s)]
        for f in in_cube:
            cyc = faces[f]
            cell = [f]
            for a, b in zip(cyc, cyc[1:] + cyc[:1]):
                key = (frozenset((a, b)), apex)
                if key not in triangles:
                    triangles[key] = len(faces)
                    faces.append([a, b, apex])
                cell.append(triangles[key])
            cells.append(cell)
        pieces.append(np.concatenate([cube_pts[cube_pts[:, k] == s], vertices[apex : apex + 1]]))
    return vertices, faces, cells, pieces


#: unions of unit tesseracts, by their integer positions: in the xy-plane unless said
SHAPES = {
    "L": [(0, 0, 0, 0), (1, 0, 0, 0), (2, 0, 0, 0), (0, 1, 0, 0)],
    "plus": [(0, 0, 0, 0), (1, 0, 0, 0), (-1, 0, 0, 0), (0, 1, 0, 0), (0, -1, 0, 0)],
    "2x2 minus one": [(0, 0, 0, 0), (1, 0, 0, 0), (0, 1, 0, 0)],
    "U": [(0, 0, 0, 0), (1, 0, 0, 0), (2, 0, 0, 0), (0, 1, 0, 0), (2, 1, 0, 0)],
    "ring": [(x, y, 0, 0) for x in range(3) for y in range(3) if (x, y) != (1, 1)],
    # bends in every direction of 4-D: a corner with an arm along each axis
    "tripod": [(0, 0, 0, 0), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1)],
    # a step in the zw-plane on top of an L in the xy-plane
    "staircase": [(0, 0, 0, 0), (1, 0, 0, 0), (1, 1, 0, 0), (1, 1, 1, 0), (1, 1, 1, 1)],
}


def tesseract_union(name: str) -> tuple[Polytope, list]:
    v, f, c, pieces = tesseract_union_mesh(SHAPES[name])
    return Polytope(v, f, c, name=name), pieces
