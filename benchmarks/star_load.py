"""Load and slice time of the regular star polychora of 120 vertices against the convex 600-cell (issue 22).

For each polychoron, in one process and interleaved run by run (so that drift in the machine's
speed hits all alike):

* **build**: ``Polytope(vertices, faces, cells)`` from its arrays, validated (the star ones from
  `rot4d_widget.geometry.star_regular.star_arrays`, the 600-cell from ``polytope("600-cell")``'s
  own vertices, faces and cells, so both go through the same mesh path); **load**: that plus the
  first ``slice_polytope``, which builds the slicing tables;
* **slice**: ``slice_polytope(p, matrix, 0.1)`` at ``--steps`` random orientations (fixed seed,
  the same for every polychoron), off the centre so the cut is generic; the median per slice, and
  the slice's size: its points (the edges' crossings) and the most fill corners of a slice (the
  extra corners of the triangles that fill a star section even-odd, `Slice.n_fill`).

Medians over ``--repeats`` runs; the ratio is each one's over the 600-cell's of the same runs.

A star polychoron's level is cut by the compiled level (`rot4d_widget.geometry._cstar`, built from
``_starcut.c`` at install) when no vertex lies on H; the **numpy slicer** column times the same
slices with the compiled tables switched off (the pure-numpy slicer the C code stands in for, and
what an install without a C compiler runs), in the same runs; ``C levels`` says how many of the
``--steps`` slices the C code did (the rest it declined to numpy: a vertex on H, a tie) and, in
brackets, how many of them a second thread helped fill (`_cstar.THREADS` on a machine with two or
more cores, for a level with many crossing sections); **C on one thread** times the same slices
with the compiled level kept to one thread.

    python benchmarks/star_load.py [--steps 20] [--repeats 5] [--names all|three]

Target (issue 22): a star polychoron of 120 vertices loads and slices within 2x a convex one of
the same size.  A polychoron the `Polytope` class refuses is reported as such (its error).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from rot4d_widget import Polytope, polytope
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry import _cstar, starslice
from rot4d_widget.geometry.slicetables import tables
from rot4d_widget.geometry.slicing import slice_polytope
from rot4d_widget.geometry.star_regular import SPECS, star_arrays

THREE = ["great 120-cell", "icosahedral 120-cell", "small stellated 120-cell"]


def rotations(steps: int, seed: int = 0) -> list:
    rng = np.random.default_rng(seed)
    return [random_rotation(rng) for _ in range(steps)]


def arrays(name: str):
    if name == "600-cell":
        p = polytope("600-cell")
        return p.vertices.copy(), [f.tolist() for f in p.faces], [list(c) for c in p.cells]
    return star_arrays(name)


def one_run(name: str, mats: list) -> dict:
    v, f, c = arrays(name)
    t0 = time.perf_counter()
    p = Polytope(v, f, c, name=name)
    t1 = time.perf_counter()
    slice_polytope(p, np.eye(4), 0.1)  # the slicing tables
    t2 = time.perf_counter()
    times, fill = [], 0
    for m in mats:
        a = time.perf_counter()
        s = slice_polytope(p, m, 0.1)
        times.append(time.perf_counter() - a)
        fill = max(fill, s.n_fill)
    out = {"build": t1 - t0, "load": t2 - t0, "slice": statistics.median(times), "counts": p.counts,
           "points": len(s.vertices) - s.n_fill, "fill": fill, "numpy": float("nan"), "one": float("nan"),
           "c_levels": None, "two": 0}
    st = starslice.star_tables(p, tables(p)) if p.star is not None else None
    if st is not None and st.c is not None:
        t = tables(p)
        levels = [_cstar.cut(st.c, t.vertices @ m.T, m, 0.1 / t.unit, t.tol) is not None and st.c.threads_used
                  for m in mats]
        out["c_levels"], out["two"] = sum(lv is not False for lv in levels), sum(lv == 2 for lv in levels)
        keep_threads, _cstar.THREADS = _cstar.THREADS, 1  # the compiled level on one thread
        try:
            out["one"] = statistics.median(_timed(p, mats))
        finally:
            _cstar.THREADS = keep_threads
        keep, st.c = st.c, None  # the numpy slicer alone, on the same slices
        try:
            out["numpy"] = statistics.median(_timed(p, mats))
        finally:
            st.c = keep
    return out


def _timed(p, mats: list) -> list:
    out = []
    for m in mats:
        a = time.perf_counter()
        slice_polytope(p, m, 0.1)
        out.append(time.perf_counter() - a)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--names", default="all", choices=["all", "three"])
    args = ap.parse_args()
    stars = THREE if args.names == "three" else [n for n, s in SPECS.items() if s.counts[0] == 120]
    names = ["600-cell", *stars]
    mats = rotations(args.steps)
    for n in names:  # the arrays, and numpy / scipy warmed up: not timed
        arrays(n)
    runs = {n: [] for n in names}
    refused = {}
    t = time.perf_counter()
    for _ in range(args.repeats):
        for n in names:
            if n in refused:
                continue
            try:
                runs[n].append(one_run(n, mats))
            except ValueError as exc:
                refused[n] = str(exc).splitlines()[0][:90]
    med = {n: {k: statistics.median(r[k] for r in rs) for k in ("build", "load", "slice", "numpy", "one")}
           for n, rs in runs.items() if rs}
    base = med["600-cell"]
    print(f"build (Polytope from arrays, validated), load (build + first slice: the slicing tables) and "
          f"slice_polytope at {args.steps} random orientations, c0 = 0.1 (median per slice); medians of "
          f"{args.repeats} interleaved runs; compiled level {'built' if _cstar.available else 'NOT built'}, "
          f"up to {_cstar.THREADS} thread(s) a level ({os.cpu_count()} cores)")
    print("| polychoron | symbol | V, E, F, C | build (ms) | load (ms) | x 600-cell | slice (ms) | x 600-cell "
          "| C levels (on two threads) | C on one thread (ms) | x 600-cell | numpy slicer (ms) | x 600-cell "
          "| slice points, fill corners |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in names:
        sym = SPECS[n].symbol if n in SPECS else "{3,3,5}"
        if n in refused:
            print(f"| {n} | {sym} | | refused: {refused[n]} | | | | | | | | | | |")
            continue
        m, last = med[n], runs[n][-1]
        print(f"| {n} | {sym} | {', '.join(map(str, last['counts']))} | {1e3 * m['build']:.1f} "
              f"| {1e3 * m['load']:.1f} | {m['load'] / base['load']:.2f} | {1e3 * m['slice']:.2f} "
              f"| {m['slice'] / base['slice']:.2f} "
              + (f"| {last['c_levels']}/{args.steps} ({last['two']}) | {1e3 * m['one']:.2f} "
                 f"| {m['one'] / base['slice']:.2f} | {1e3 * m['numpy']:.2f} | {m['numpy'] / base['slice']:.2f} "
                 if last["c_levels"] is not None else "| | | | | ")
              + f"| {last['points']}, {last['fill']} |")
    print(f"(whole run {time.perf_counter() - t:.0f} s)")


if __name__ == "__main__":
    main()
