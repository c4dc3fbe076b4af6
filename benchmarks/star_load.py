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

A star polychoron's levels are cut by the general slicer (`rot4d_widget.geometry.slicing.star`,
numpy), the 600-cell's and the other convex-celled ones' by the convex-cell slicer.

    python benchmarks/star_load.py [--steps 20] [--repeats 5] [--names all|three]

Target (issue 22): a star polychoron of 120 vertices loads and slices within 2x a convex one of
the same size.  A polychoron the `Polytope` class refuses is reported as such (its error).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rot4d_widget import Polytope, polytope
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
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
    return {"build": t1 - t0, "load": t2 - t0, "slice": statistics.median(times), "counts": p.counts,
            "points": len(s.vertices) - s.n_fill, "fill": fill}


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
    med = {n: {k: statistics.median(r[k] for r in rs) for k in ("build", "load", "slice")}
           for n, rs in runs.items() if rs}
    base = med["600-cell"]
    print(f"build (Polytope from arrays, validated), load (build + first slice: the slicing tables) and "
          f"slice_polytope at {args.steps} random orientations, c0 = 0.1 (median per slice); medians of "
          f"{args.repeats} interleaved runs")
    print("| polychoron | symbol | V, E, F, C | build (ms) | load (ms) | x 600-cell | slice (ms) | x 600-cell "
          "| slice points, fill corners |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|")
    for n in names:
        sym = SPECS[n].symbol if n in SPECS else "{3,3,5}"
        if n in refused:
            print(f"| {n} | {sym} | | refused: {refused[n]} | | | | | |")
            continue
        m, last = med[n], runs[n][-1]
        print(f"| {n} | {sym} | {', '.join(map(str, last['counts']))} | {1e3 * m['build']:.1f} "
              f"| {1e3 * m['load']:.1f} | {m['load'] / base['load']:.2f} | {1e3 * m['slice']:.2f} "
              f"| {m['slice'] / base['slice']:.2f} | {last['points']}, {last['fill']} |")
    print(f"(whole run {time.perf_counter() - t:.0f} s)")


if __name__ == "__main__":
    main()
