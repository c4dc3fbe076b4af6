"""Whole slices through vertices (issue 33): a hyperplane exactly at a vertex's height keeps every
point of P ∩ H, for every non-convex and star polytope the package builds or ships.

The polytopes: the ten regular star polychora (`rot4d_widget.polytope_names()`'s star family;
every other polytope the catalogue builds is convex: the Wythoff families, the snub 24-cell, the
grand antiprism, prisms, duoprisms and antiprismatic prisms) and every non-convex 4OFF file in
tests/data/off_library (star faces, non-convex, star and hemi cells, self-intersecting ones, a
one-sided boundary).  Each is cut with c0 equal to a rotated vertex's w, the level a user reaches
first (unturned) and by ``h``/``l``:

* **unturned** (the identity matrix): at every distinct vertex height;
* in **three random orientations** (fixed seeds): at every vertex's height for a polytope of up
  to 120 vertices in the first, at 24 of them (seeded) in the others; at 40 a turn for the three
  with 600 and more vertices (they take 3-14 ms a level).

The slice's points, less its fill corners (the last `Slice.n_fill` vertices: extra corners of an
even-odd fill, not points of P ∩ H), must be P ∩ H's points as computed here in plain numpy from
the polytope's vertices and its faces' sides alone, none of the slicer's tables: the crossing of
every edge whose ends lie strictly on both sides of H, and every vertex on H (``|w - c0| <=
1e-9`` x the circumradius, the slicer's documented tolerance).  Both are compared as point sets
(either way, within 1e-7 x the circumradius, as benchmarks/off_library.py does): several edges
may cross H at one point.  And every edge of P lying in H (both ends on H) is an edge of the
slice, between those two points.  The whole public libraries are checked the same way by
``python benchmarks/off_library.py DIR --vertex-heights`` (docs/performance.md).
"""

from __future__ import annotations

import functools
import pathlib
import sys

import numpy as np
import pytest
from scipy.spatial import cKDTree

from rot4d_widget import polytope, polytope_names
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.geometry.star_regular import STAR_FAMILY

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "benchmarks"))
from off_library import load  # noqa: E402  (the default tolerance, else the one the refusal names)

DATA = pathlib.Path(__file__).resolve().parents[1] / "data" / "off_library"
ON = 1e-9  #: a vertex is on H within this times the circumradius
SAME = 1e-7  #: a slice point and a point of P ∩ H agree within this times the circumradius
SEEDS = (1, 2, 3)  #: the random orientations
BIG = 600  #: from this many vertices, 40 vertex heights a turn
EVERY = 120  #: up to this many vertices, every vertex height in the first turn


def _names():
    stars = [("star", n) for n in polytope_names()[STAR_FAMILY]]
    files = [("off", f"{f.parent.name}/{f.name}") for f in sorted(DATA.rglob("*.off"))]
    return stars + files


@functools.lru_cache(maxsize=None)
def _polytope(kind, name):
    return polytope(name) if kind == "star" else load(DATA / name)[0]


def _cases():
    """The star ten and the library's non-convex files (whether a file is convex is its loading's)."""
    return [pytest.param(kind, name, id=name.removesuffix(".off"))
            for kind, name in _names() if kind == "star" or not _polytope(kind, name).convex]


def edges_in_h(p, m, c0) -> np.ndarray:
    """(k, 2, 3) the ends of P's edges lying in H (both ends on H): edges of P ∩ H."""
    x = np.asarray(p.vertices, dtype=float) @ np.asarray(m).T
    on = np.abs(x[:, 3] - c0) <= ON * _radius(p)
    a, b = _edges(p)
    both = on[a] & on[b]
    return np.stack([x[a[both], :3], x[b[both], :3]], axis=1)


def points_of_p_cap_h(p, m, c0) -> np.ndarray:
    """(k, 3) the points of P ∩ H (H: w = c0 after ``vertices @ m.T``): each edge's crossing where its ends
    are strictly on both sides, and each vertex on H.  The edges are the faces' sides."""
    x = np.asarray(p.vertices, dtype=float) @ np.asarray(m).T
    h = x[:, 3] - c0
    on = np.abs(h) <= ON * _radius(p)
    a, b = _edges(p)
    cross = ~on[a] & ~on[b] & ((h[a] > 0) != (h[b] > 0))
    a, b = a[cross], b[cross]
    s = (h[a] / (h[a] - h[b]))[:, None]
    return np.concatenate([x[a, :3] + s * (x[b, :3] - x[a, :3]), x[on, :3]])


@functools.lru_cache(maxsize=None)
def _edges(p) -> np.ndarray:
    """(2, E) the polytope's edges as its faces' sides (consecutive corners), each once."""
    sides = np.concatenate([np.stack([f, np.roll(f, -1)], axis=1) for f in p.faces])
    return np.unique(np.sort(sides, axis=1), axis=0).T


def _radius(p) -> float:
    return float(np.linalg.norm(np.asarray(p.vertices, dtype=float), axis=1).max())


def vertex_heights(p, m, rng=None, k=None) -> list[float]:
    """The distinct heights w of ``p``'s vertices turned by ``m`` (the first vertex of each cluster within
    `ON`), or ``k`` of them drawn by ``rng``."""
    w = (np.asarray(p.vertices, dtype=float) @ np.asarray(m).T)[:, 3]
    w = np.sort(w)
    first = np.ones(len(w), dtype=bool)
    first[1:] = np.diff(w) > ON * _radius(p)
    w = w[first]
    if k is not None and k < len(w):
        w = np.sort(rng.choice(w, k, replace=False))
    return [float(c) for c in w]


def mismatch(p, m, c0) -> str | None:
    """What differs between the slice's points and P ∩ H's at ``c0``, or None."""
    s = slice_polytope(p, m, c0)
    return points_mismatch(p, m, c0, np.asarray(s.vertices)[: len(s.vertices) - s.n_fill], s.edges)


def points_mismatch(p, m, c0, got, edges) -> str | None:
    """What differs between a slice's points ``got`` (its fill corners left out) and edges and P ∩ H
    at ``c0``, or None: the kernel's slices here, the page's in tests/page/test_page_star.py."""
    got = np.asarray(got, dtype=float).reshape(-1, 3)
    want = points_of_p_cap_h(p, m, c0)
    tol = SAME * _radius(p)
    if not len(got) or not len(want):
        return None if len(got) == len(want) else f"c0={c0:.6g}: {len(got)} slice points, {len(want)} of P ∩ H"
    tree = cKDTree(got)
    missing = int((tree.query(want)[0] > tol).sum())
    extra = int((cKDTree(want).query(got)[0] > tol).sum())
    if missing or extra:
        return (f"c0={c0:.6g}: {missing} of P ∩ H's {len(want)} points missing from the slice, "
                f"{extra} of its {len(got)} points not in P ∩ H")
    flat = edges_in_h(p, m, c0)
    if len(flat):  # and each edge lying in H joins two of them in the slice
        ends = tree.query(flat.reshape(-1, 3))[1].reshape(-1, 2)
        have = {frozenset(e) for e in np.asarray(edges).reshape(-1, 2).tolist()}
        lost = sum(frozenset(e) not in have for e in ends.tolist())
        if lost:
            return f"c0={c0:.6g}: {lost} of P's {len(flat)} edges lying in H are no edge of the slice"
    return None


def _turns(p):
    """(label, matrix, levels): unturned at every vertex height, then the random orientations."""
    n = len(p.vertices)
    out = [("unturned", np.eye(4), vertex_heights(p, np.eye(4)))]
    for i, seed in enumerate(SEEDS):
        m = random_rotation(seed)
        rng = np.random.default_rng(seed)
        k = 40 if n >= BIG else (None if i == 0 and n <= EVERY else 24)
        out.append((f"seed {seed}", m, vertex_heights(p, m, rng, k)))
    return out


@pytest.mark.parametrize("kind, name", _cases())
def test_a_slice_at_a_vertex_height_has_every_point_of_p_cap_h(kind, name):
    p = _polytope(kind, name)
    assert not p.convex
    problems = []
    for label, m, levels in _turns(p):
        problems += [f"{label}, {why}" for c0 in levels if (why := mismatch(p, m, c0))]
    assert not problems, f"{len(problems)} levels:\n" + "\n".join(problems[:12])


def test_the_oracle_sees_a_vertex_on_h_and_an_edge_crossing():
    """The oracle itself, on the tesseract unturned: at w = 1 its 8 top vertices (a cube) and
    nothing else; at w = 0.5 the 8 crossings of its vertical edges, halfway up; above it, nothing."""
    p = polytope("tesseract")
    top = points_of_p_cap_h(p, np.eye(4), 1.0)
    assert len(top) == 8 and np.allclose(np.abs(top), 1.0)
    mid = points_of_p_cap_h(p, np.eye(4), 0.5)
    assert len(mid) == 8 and np.allclose(np.abs(mid), 1.0)
    assert len(points_of_p_cap_h(p, np.eye(4), 1.5)) == 0
    assert vertex_heights(p, np.eye(4)) == [-1.0, 1.0]
    assert mismatch(p, np.eye(4), 1.0) is None and mismatch(p, np.eye(4), -1.0) is None

