"""Load and slice every 4OFF file of a library (issue 22): what a user loading another tool's
collection file by file with `Polytope.from_off` gets, and whether the slices are right.

For each ``*.off`` file in DIR or its sub-folders (sorted by the number its name starts with, then
by path):

* **load**: ``Polytope.from_off(path)``; if that is refused with an error that names a tolerance
  that would do (coordinates written with few digits), again with that tolerance, up to three
  times (`load`; the table says which were used).  A wrong edge count E is read with a warning
  (counted).
* **slice**: one fixed random rotation (``--seed``), cut at c0 = 0 and at ``--levels`` more
  levels spread over the rotated w range (``slice_polytope`` with a single c0 each; the time is
  the median over the levels, the slicing tables built by a first, untimed cut).  With
  ``--vertex-heights [K]`` (issue 33) instead: c0 exactly at every distinct vertex height unturned
  (the identity matrix), and at every vertex's height after the fixed rotation, or at K of them
  drawn with the seed where a file has more (the rows' problems start "unturned" or "turned").
* **check**, independently of the slicer (numpy on the file's vertices, faces and cells, read
  here from the file with its own few lines of parsing):
  - the slice's points are the edges' crossings of the hyperplane: every crossing (and every
    vertex lying in it) is within ``1e-7 * circumradius`` of a slice point and every slice point
    is within that of a crossing; every edge lying in the hyperplane (both ends within ``1e-9 *
    circumradius``) is an edge of the slice between those ends' points;
  - every slice point is finite (it lies in the hyperplane by construction: it is given in the
    hyperplane's own 3-D coordinates); the volume is finite (a negative one is counted, not a
    failure: the volume is weighted by the winding number, docs/design.md, and a self-intersecting
    polytope with reflex ridges, not detected as self-intersecting, can wind round negatively), or,
    for a polytope with no inside (``Polytope.volume_defined`` False: hemi cells or a boundary that
    is not orientable), None and nothing else (the table's ``novol`` column says why);
  - the slice's polygons close up: every edge of their cycles is in an even number of them (a
    non-convex section's fill corners, ``Slice.n_fill``, are not points: only checked to lie in
    the points' bounding box); whether each edge also runs one way in one polygon and the other
    way in the other, as the boundary's orientation induces, is reported apart (`unclosed`: with
    star faces the even-odd rule does not promise it);
  - for a polytope reported convex: the slice's volume equals the volume of
    ``scipy.spatial.ConvexHull`` of its points (relative ``1e-6``, plus 4 x the slice's area x the
    file's `flatness`: a file written with few digits leaves its faces and cells that far from flat).

    python benchmarks/off_library.py DIR [--numbers 1-132] [--levels 3 | --vertex-heights [K]] [--seed 0]
        [--max-bytes N] [--timeout S] [--json out.json] [--quiet]

``--numbers A-B`` takes only files whose name starts with a number in A..B (the Bowers numbers of
Pardesco/4d-polytope-viewer's ``public/data/polytopes``; docs/performance.md).  Prints one row
per file (file, V, E, F, C, convex, self-intersecting, tolerance, load ms, slice ms, result) and a
summary: how many loaded (with the default or a looser tolerance), sliced and checked, and the
refusals grouped by kind of error.
"""

from __future__ import annotations

import argparse
import collections
import json
import pathlib
import re
import signal
import statistics
import sys
import time
import warnings

import numpy as np
from scipy.spatial import ConvexHull, cKDTree

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.mesh import Polytope
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope

#: distance (relative to the circumradius) within which a slice point and an edge crossing agree
POINT_TOL = 1e-7
#: relative agreement of a convex slice's volume with its points' hull volume
VOLUME_RTOL = 1e-6
#: the error that says which looser tolerance would load the file
_HINT = re.compile(r"tolerance=([0-9.eE+-]+) \(Polytope")

#: refusals grouped by what they say (first match wins); the rest by their text without numbers
CATEGORIES = [
    ("hemi cell (a face through the cell's centre, or coplanar faces)",
     re.compile(r"centre lies in the plane of its face|lies in that face's plane|oriented areas cancel")),
    ("star face (not a convex polygon)", re.compile(r"not a convex polygon")),
    ("non-convex cell", re.compile(r"cell \d+ is not convex|is not convex: its vertex|not strictly convex")),
    ("face not planar", re.compile(r"not planar")),
    ("cell not flat", re.compile(r"does not lie in a hyperplane|not flat")),
    ("not orientable", re.compile(r"not orientable")),
    ("orientation", re.compile(r"orient")),
    ("a vertex in no face", re.compile(r"is in no face")),
    ("coinciding vertices", re.compile(r"vertices \d+ and \d+ coincide")),
    ("the suggested tolerance is refused", re.compile(r"Expected `tolerance`")),
    ("a line with the wrong count of numbers (the file is cut or damaged)", re.compile(r"has \d+ numbers; expected")),
    ("time limit", re.compile(r"time limit")),
]


# -- an independent reading of the file: vertices and the edges of its faces --------------------------
def read_file(path) -> tuple[np.ndarray, list, list]:
    """(V, 4) vertices, faces (vertex index arrays) and cells (face index lists) of a 4OFF file,
    parsed here with none of the package's code: the checks' own reading."""
    tokens = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            t = line.split("#", 1)[0].split()
            if t:
                tokens.append(t)
    k = next(i for i, t in enumerate(tokens) if t[0] == "4OFF")
    counts = tokens[k][1:] or tokens[k + 1]
    start = k + 1 if tokens[k][1:] else k + 2
    nv, nf, nc = int(counts[0]), int(counts[1]), int(counts[3])
    v = np.array([[float(x) for x in t] for t in tokens[start : start + nv]])
    faces = [np.array([int(x) for x in t[1 : int(t[0]) + 1]]) for t in tokens[start + nv : start + nv + nf]]
    cells = [[int(x) for x in t[1 : int(t[0]) + 1]] for t in tokens[start + nv + nf : start + nv + nf + nc]]
    return v, faces, cells


def edges_of(faces) -> np.ndarray:
    """(E, 2) sorted unique edges: consecutive corners of every face."""
    e = np.sort(np.concatenate([np.stack([f, np.roll(f, -1)], axis=1) for f in faces]), axis=1)
    return np.unique(e, axis=0)


def read_vertices_and_edges(path) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) vertices and (E, 2) sorted unique edges of the faces of a 4OFF file (`read_file`)."""
    v, faces, _ = read_file(path)
    return v, edges_of(faces)


def flatness(v: np.ndarray, faces: list, cells: list) -> float:
    """The largest distance of a corner from its face's best-fitting plane, or of a cell's vertex from
    its cell's best-fitting hyperplane: how far from flat the file's coordinates (rounded by the
    program that wrote them) leave its faces and cells."""
    worst = 0.0
    for f in faces:
        c = v[f] - v[f].mean(axis=0)
        off_plane = c @ np.linalg.svd(c)[2][2:].T  # each corner's offset from the best plane
        worst = max(worst, float(np.linalg.norm(off_plane, axis=1).max()))
    for cell in cells:
        idx = np.unique(np.concatenate([faces[i] for i in cell]))
        c = v[idx] - v[idx].mean(axis=0)
        n = np.linalg.svd(c)[2][3]
        worst = max(worst, float(np.abs(c @ n).max()))
    return worst


def crossings(v: np.ndarray, e: np.ndarray, m: np.ndarray, c0: float, on_tol: float) -> np.ndarray:
    """(k, 3) points where the edges ``e`` of vertices ``v`` (rotated: ``v @ m.T``) meet w = c0: the
    crossing of every edge with ends strictly on both sides, and every vertex within ``on_tol``."""
    x = v @ m.T
    h = x[:, 3] - c0
    on = np.abs(h) <= on_tol
    a, b = e[:, 0], e[:, 1]
    cross = ~on[a] & ~on[b] & (np.sign(h[a]) != np.sign(h[b]))
    a, b = a[cross], b[cross]
    t = (h[a] / (h[a] - h[b]))[:, None]
    return np.concatenate([x[a, :3] + t * (x[b, :3] - x[a, :3]), x[on, :3]])


def in_hyperplane(v: np.ndarray, e: np.ndarray, m: np.ndarray, c0: float, on_tol: float) -> np.ndarray:
    """(k, 2, 3) the ends of the edges ``e`` lying in w = c0 (both ends within ``on_tol``): edges of P ∩ H."""
    x = v @ m.T
    on = np.abs(x[:, 3] - c0) <= on_tol
    both = on[e[:, 0]] & on[e[:, 1]]
    return x[e[both]][..., :3]


def unclosed(s) -> tuple[str, str] | None:
    """What keeps the slice's polygons from closing up, as (kind, text), or None: every directed edge of their
    cycles must come as often as its reverse (each segment of a face's chord bounds the sections
    of the face's two cells, wound against each other, as the 4-D boundary's orientation induces).
    The polygons, not the triangles: a non-convex section's fill has extra corners on the segments
    (`Slice.n_fill`) that its neighbour's fill does not share.  kind "segments": an edge is in an
    odd number of polygons (a segment not shared); kind "winding": the segments are shared but
    some run the same way in both their polygons."""
    idx, off = np.asarray(s.polygon_indices), np.asarray(s.polygon_offsets)
    if len(off) < 2:
        return None
    nxt = np.arange(1, len(idx) + 1)
    nxt[off[1:] - 1] = off[:-1]  # each corner's successor in its own cycle
    d = np.stack([idx, idx[nxt]], axis=1)
    odd = sum(n % 2 for n in collections.Counter(map(tuple, np.sort(d, axis=1).tolist())).values())
    if odd:
        return "segments", f"{odd} polygon edges in an odd number of polygons (segments not shared)"
    fwd = collections.Counter(map(tuple, d.tolist()))
    wrong = sum(fwd[(j, i)] != n for (i, j), n in fwd.items())
    if wrong:
        return "winding", (f"{wrong} polygon edges run the same way in both their polygons (the sections' "
                           f"cycles are not wound as the boundary's orientation induces)")
    return None


def check_slice(p: Polytope, s, v: np.ndarray, e: np.ndarray, m: np.ndarray, c0: float,
                winding: bool = True, flat: float = 0.0) -> list[str]:
    """What is wrong with slice ``s`` of ``p`` (rotated by ``m``, cut at ``c0``), checked against the
    file's own vertices ``v`` and edges ``e``; an empty list when it is right.  ``winding=False``:
    the polygons' edges need only be shared, not wound against each other (see `unclosed`).
    ``flat``: the file's `flatness`; a convex slice's volume may then differ from its points' hull
    by up to 4 x flat x its surface area (the cells' sections are that far from the hull's facets)."""
    problems = []
    scale = float(np.max(np.linalg.norm(v, axis=1)))
    tol = POINT_TOL * scale
    allpts = np.asarray(s.vertices, dtype=float)
    nfill = int(s.n_fill)  # extra corners of a non-convex section's fill, after the points
    pts, fill = allpts[: len(allpts) - nfill], allpts[len(allpts) - nfill :]
    want = crossings(v, e, m, c0, 1e-9 * scale)
    if not np.all(np.isfinite(allpts)):
        problems.append(f"c0={c0:.4g}: slice points not finite")
        return problems
    if nfill and len(pts) and np.any((fill < pts.min(axis=0) - tol) | (fill > pts.max(axis=0) + tol)):
        problems.append(f"c0={c0:.4g}: a fill corner outside the slice points' box")
    # compared as sets: crossing points may coincide (two edges meeting the hyperplane at one point)
    if len(want) == 0 or len(pts) == 0:
        if len(want) != len(pts):
            problems.append(f"c0={c0:.4g}: {len(pts)} slice points but {len(want)} edge crossings")
        return problems
    tree = cKDTree(pts)
    d1 = tree.query(want)[0]
    d2 = cKDTree(want).query(pts)[0]
    if d1.max() > tol:
        problems.append(f"c0={c0:.4g}: {int(np.sum(d1 > tol))} of {len(want)} edge crossings (and vertices on H) "
                        f"are no slice point (worst {d1.max() / scale:.2g} x R)")
    if d2.max() > tol:
        problems.append(f"c0={c0:.4g}: {int(np.sum(d2 > tol))} of {len(pts)} slice points are no edge crossing "
                        f"(worst {d2.max() / scale:.2g} x R)")
    flat_edges = in_hyperplane(v, e, m, c0, 1e-9 * scale)
    if len(flat_edges):  # every edge lying in H is an edge of the slice, between its two ends' points
        ends = tree.query(flat_edges.reshape(-1, 3))[1].reshape(-1, 2)
        have = {frozenset(k) for k in np.asarray(s.edges).tolist()}
        lost = sum(frozenset(k) not in have for k in ends.tolist())
        if lost:
            problems.append(f"c0={c0:.4g}: {lost} of the {len(flat_edges)} edges lying in H are no slice edge")
    if p.volume_defined:
        if s.volume is None or not np.isfinite(s.volume):
            problems.append(f"c0={c0:.4g}: volume {s.volume}")
    elif s.volume is not None:  # a hemi or non-orientable polytope has no inside: no volume, never a number
        problems.append(f"c0={c0:.4g}: volume {s.volume!r} where the polytope has none ({p.why_no_volume})")
    why = unclosed(s)
    if why and (winding or why[0] != "winding"):
        problems.append(f"c0={c0:.4g}: the polygons do not close up: {why[1]}")
    if p.convex and s.dim == 3:
        hull = ConvexHull(pts).volume
        t = np.asarray(s.triangles)
        area = 0.5 * np.linalg.norm(np.cross(allpts[t[:, 1]] - allpts[t[:, 0]], allpts[t[:, 2]] - allpts[t[:, 0]]),
                                    axis=1).sum()
        allowed = VOLUME_RTOL * hull + 4 * flat * area
        if abs(s.volume - hull) > allowed:
            problems.append(f"c0={c0:.4g}: convex, volume {s.volume:.9g} but the points' hull has {hull:.9g} "
                            f"(allowed {allowed:.2g})")
    return problems


def levels(p: Polytope, m: np.ndarray, n: int) -> list[float]:
    """c0 = 0 and ``n`` levels spread over the rotated w range (never exactly at a vertex)."""
    w = p.vertices @ m.T[:, 3]
    lo, hi = float(w.min()), float(w.max())
    fr = 0.1 + 0.8 * (np.arange(n) + 0.37) / n  # off the middle: a centrally symmetric one has 0 there
    return [0.0] + [lo + f * (hi - lo) for f in fr]


def vertex_heights(p: Polytope, m: np.ndarray, k: int | None = None, seed: int = 0) -> list[float]:
    """The distinct heights w of ``p``'s vertices turned by ``m`` (one of each cluster within 1e-9 x the
    circumradius; c0 there puts those vertices exactly on H), or ``k`` of them drawn with ``seed``."""
    w = np.sort((p.vertices @ m.T)[:, 3])
    first = np.ones(len(w), dtype=bool)
    first[1:] = np.diff(w) > 1e-9 * float(np.max(np.linalg.norm(p.vertices, axis=1)))
    w = w[first]
    if k is not None and k < len(w):
        w = np.sort(np.random.default_rng(seed).choice(w, k, replace=False))
    return [float(c) for c in w]


def cuts(p: Polytope, m: np.ndarray, nlevels: int, at_vertices: int | None,
         seed: int) -> list[tuple[str, np.ndarray, float]]:
    """(label, matrix, c0) of every slice to check: `levels` after the rotation ``m``; or, with
    ``at_vertices`` (0: every one), c0 at every distinct vertex height unturned (the identity) and at
    every vertex's height after ``m``, or ``at_vertices`` of them drawn with ``seed`` when there are more."""
    if at_vertices is None:
        return [("", m, c0) for c0 in levels(p, m, nlevels)]
    eye = np.eye(4)
    return ([("unturned, ", eye, c0) for c0 in vertex_heights(p, eye)]
            + [("turned, ", m, c0) for c0 in vertex_heights(p, m, at_vertices or None, seed)])


class _TimeUp(Exception):
    pass


def _alarm(signum, frame):
    raise _TimeUp("time limit")


def category(message: str) -> str:
    for name, pattern in CATEGORIES:
        if pattern.search(message):
            return name
    text = re.sub(r"^('.*?', )?line \d+( \([a-z]+ \d+\))?: ", "", message)
    return re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", text)[:80]


def load(path, tries: int = 3) -> tuple[Polytope, str, int]:
    """(polytope, tolerance used: 'default' or the looser number, number of warnings).  A refusal
    that names a tolerance that would do is followed, as a user would, up to ``tries`` times (the
    hint is the first offending face's or cell's; a later one may need more: "t1>t2" in the table)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        used = []
        while True:
            try:
                p = Polytope.from_off(path, tolerance=used[-1] if used else None)
                return p, ">".join(f"{t:g}" for t in used) or "default", len(caught)
            except ValueError as exc:
                hint = _HINT.search(str(exc))
                if not hint or len(used) == tries:
                    raise
                used.append(float(hint.group(1)))


def run_file(path, m: np.ndarray, nlevels: int, timeout: float | None, name: str | None = None,
             at_vertices: int | None = None, seed: int = 0) -> dict:
    row = {"file": name or path.name, "bytes": path.stat().st_size}
    if timeout:
        signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        t0 = time.perf_counter()
        try:
            p, tol, nwarn = load(path)
        except (ValueError, _TimeUp) as exc:
            row.update(loaded=False, error=str(exc), category=category(str(exc)),
                       load_ms=(time.perf_counter() - t0) * 1e3)
            return row
        row.update(loaded=True, load_ms=(time.perf_counter() - t0) * 1e3, tolerance=tol, warnings=nwarn)
        row.update(zip("VEFC", p.counts))
        row.update(convex=bool(p.convex), self_intersecting=bool(p.self_intersecting), no_volume=p.why_no_volume)
        try:
            v, faces, cells = read_file(path)
            e = edges_of(faces)
            flat = flatness(v, faces, cells) if p.convex else 0.0
            problems = []
            if len(v) != len(p.vertices) or len(e) != len(p.edges):
                problems.append(f"counts: the file has {len(v)} vertices and {len(e)} face edges, the polytope "
                                f"{len(p.vertices)} and {len(p.edges)}")
            slice_polytope(p, m, 0.0)  # builds the slicing tables (not timed)
            times, negative, wound, failed = [], [], [], 0
            todo = cuts(p, m, nlevels, at_vertices, seed)
            for label, mm, c0 in todo:
                t1 = time.perf_counter()
                s = slice_polytope(p, mm, c0)
                times.append((time.perf_counter() - t1) * 1e3)
                found = [label + x for x in check_slice(p, s, v, e, mm, c0, flat=flat)]
                bad = [x for x in found if "not wound" not in x]
                problems += bad
                failed += bool(bad)
                wound += [x for x in found if "not wound" in x]
                if s.volume is not None and s.volume < 0:
                    negative.append(c0)
            row.update(slice_ms=statistics.median(times), problems=problems, ok=not problems, negative=negative,
                       wound=wound, levels=len(todo), failed_levels=failed)
        except Exception as exc:  # noqa: BLE001 -- a slicer failure is a finding, reported per file
            row.update(slice_ms=None, problems=[f"slice raised {type(exc).__name__}: {exc}"], ok=False, negative=[],
                       wound=[], levels=0, failed_levels=0)
        return row
    finally:
        if timeout:
            signal.setitimer(signal.ITIMER_REAL, 0)


def number(path) -> int | None:
    m = re.match(r"(\d+)-", path.name)  # "<Bowers number>-<acronym>.off"; "2gap.off" (a compound) has none
    return int(m.group(1)) if m else None


def select(directory, numbers: str | None, max_bytes: int | None) -> list[pathlib.Path]:
    files = sorted(pathlib.Path(directory).rglob("*.off"),  # sub-folders too (a library by family)
                   key=lambda f: (number(f) is None, number(f) or 0, str(f)))
    if numbers:
        a, _, b = numbers.partition("-")
        lo, hi = int(a), int(b or a)
        files = [f for f in files if number(f) is not None and lo <= number(f) <= hi]
    if max_bytes:
        files = [f for f in files if f.stat().st_size <= max_bytes]
    return files


def row_text(r: dict) -> str:
    if not r["loaded"]:
        return (f"{r['file'][-40:]:40} {'':>6} {'':>6} {'':>6} {'':>5} {'':>6} {'':>6} {'':>12} "
                f"{r['load_ms']:8.0f} {'':>8}  REFUSED: {r['error'][:150]}")
    res = "ok" if r["ok"] else (f"CHECK FAILED at {r['failed_levels']} of {r['levels']} levels: "
                                + "; ".join(r["problems"])[:200])
    if r["wound"]:
        res += f" (sections not wound as the boundary at {len(r['wound'])} of the levels)"
    if r["negative"]:
        res += f" (negative volume at c0 = {', '.join(f'{c:.3g}' for c in r['negative'])})"
    if r.get("no_volume"):
        res += f" (no volume: {r['no_volume']})"
    sl = f"{r['slice_ms']:8.2f}" if r["slice_ms"] is not None else f"{'-':>8}"
    return (f"{r['file'][-40:]:40} {r['V']:6d} {r['E']:6d} {r['F']:6d} {r['C']:5d} {str(r['convex']):>6} "
            f"{str(r['self_intersecting']):>6} {r['tolerance']:>12} {r['load_ms']:8.0f} {sl}  {res}")


HEADER = (f"{'file':40} {'V':>6} {'E':>6} {'F':>6} {'C':>5} {'convex':>6} {'selfx':>6} {'tol':>12} "
          f"{'load ms':>8} {'slice ms':>8}  result")


def summary(rows: list[dict]) -> str:
    n = len(rows)
    loaded = [r for r in rows if r["loaded"]]
    loose = [r for r in loaded if r["tolerance"] != "default"]
    ok = [r for r in loaded if r["ok"]]
    refused = [r for r in rows if not r["loaded"]]
    out = [f"{n} files: {len(loaded)} loaded ({len(loaded) - len(loose)} with the default tolerance, "
           f"{len(loose)} with a looser one), {len(ok)} of them sliced with every check right, "
           f"{len(loaded) - len(ok)} with a check failed; {len(refused)} refused",
           f"  convex {sum(r['convex'] for r in loaded)}, self-intersecting "
           f"{sum(r['self_intersecting'] for r in loaded)}, other non-convex "
           f"{sum(not r['convex'] and not r['self_intersecting'] for r in loaded)}; "
           f"{sum(r['warnings'] > 0 for r in loaded)} read with a warning (edge count); "
           f"{sum(bool(r['negative']) for r in loaded)} with a negative (winding-weighted) slice volume somewhere"]
    unturned = sum(any(x.startswith("unturned") for x in r["problems"]) for r in loaded)
    out.append(f"  {sum(r['levels'] for r in loaded)} levels cut, {sum(r['failed_levels'] for r in loaded)} with a "
               f"check failed" + (f" (files failing unturned: {unturned})" if unturned else ""))
    novol = collections.Counter(r["no_volume"] for r in loaded if r.get("no_volume"))
    for why, k in sorted(novol.items()):
        names = [r["file"] for r in loaded if r.get("no_volume") == why]
        out.append(f"  loaded with no volume ({why}; slice volume None): {k}  ({', '.join(names[:8])}"
                   f"{', ...' if k > 8 else ''})")
    for cat, k in collections.Counter(r["category"] for r in refused).most_common():
        names = [r["file"] for r in refused if r["category"] == cat]
        out.append(f"  refused, {cat}: {k}  ({', '.join(names[:8])}{', ...' if k > 8 else ''})")
    bad = [r for r in loaded if not r["ok"]]
    kinds = collections.Counter()
    for r in bad:
        kinds.update({re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", x.split(": ", 1)[-1])[:90] for x in r["problems"]})
    for kind, k in kinds.most_common():
        names = [r["file"] for r in bad if any(re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", x.split(": ", 1)[-1])[:90]
                                               == kind for x in r["problems"])]
        out.append(f"  check failed, {kind}: {k}  ({', '.join(names[:8])}{', ...' if k > 8 else ''})")
    wound = [r["file"] for r in loaded if r["wound"]]
    if wound:
        out.append(f"  sections not wound as the boundary's orientation induces (polygons' edges shared but running "
                   f"the same way; not counted as failed: even-odd sections of star faces close up only as a set, "
                   f"and a boundary with no orientation, hemi or not orientable, induces none): "
                   f"{len(wound)}  ({', '.join(wound[:8])}{', ...' if len(wound) > 8 else ''})")
    if loaded:
        out.append(f"  load ms median {statistics.median(r['load_ms'] for r in loaded):.0f}, "
                   f"max {max(r['load_ms'] for r in loaded):.0f}; slice ms median "
                   f"{statistics.median(r['slice_ms'] for r in loaded if r['slice_ms'] is not None):.2f}")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("directory")
    ap.add_argument("--numbers", help="only files whose name starts with a number in A-B")
    ap.add_argument("--levels", type=int, default=3, help="levels besides c0 = 0 (default 3)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the fixed rotation")
    ap.add_argument("--vertex-heights", type=int, nargs="?", const=0, default=None, metavar="K",
                    help="instead of --levels: c0 at every distinct vertex height unturned, and at every vertex's "
                         "height after the fixed rotation (or K of them, drawn with the seed, where there are more)")
    ap.add_argument("--max-bytes", type=int, help="skip files larger than this")
    ap.add_argument("--timeout", type=float, help="seconds per file (load and slices) before it counts as refused")
    ap.add_argument("--json", help="write the rows here")
    ap.add_argument("--quiet", action="store_true", help="the summary only")
    args = ap.parse_args(argv)
    files = select(args.directory, args.numbers, args.max_bytes)
    if not files:
        print("no .off files selected", file=sys.stderr)
        return 2
    m = random_rotation(args.seed)
    rows = []
    if not args.quiet:
        print(HEADER, flush=True)
    for f in files:
        r = run_file(f, m, args.levels, args.timeout, name=str(f.relative_to(args.directory)),
                     at_vertices=args.vertex_heights, seed=args.seed)
        rows.append(r)
        if not args.quiet:
            print(row_text(r), flush=True)
    print()
    print(summary(rows))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=1)
    return 0 if all(r["loaded"] and r["ok"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
