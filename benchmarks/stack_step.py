"""Issue 10: one batched slice_polytope call of 16 levels against 16 single calls, and StackSource.slice.

For each regular polychoron and each of ``--orientations`` fixed random orientations (seed 0),
16 levels evenly spread over 90 % of the circumradius either side of 0 are cut (a) by 16 calls
``slice_polytope(p, m, c)`` and (b) by one ``slice_polytope(p, m, levels)``; the two are timed
alternately ``--repeats`` times and each takes its fastest run (the least disturbed on a shared
machine), then the median over orientations.  The ratio is batched / ONE single slice (the
issue's target: <= 4 for the 600-cell and the 120-cell).  Last column: one
``StackSource(name, slices=12).slice(m, 0)`` (oval, colour by w), median over orientations.

    python benchmarks/stack_step.py [--orientations 7] [--repeats 15]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from rot4d_widget import polytope, slice_polytope
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.tomography import StackSource

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell"]
TARGET = {"600-cell": 4.0, "120-cell": 4.0}
LEVELS = 16


def measure(name: str, orientations: int, repeats: int) -> dict:
    p = polytope(name)
    levels = np.linspace(-0.9, 0.9, LEVELS) * p.circumradius
    rng = np.random.default_rng(0)
    stack = StackSource(name, slices=12)
    singles, batched, stacks = [], [], []
    for _ in range(orientations):
        m = random_rotation(rng)
        slice_polytope(p, m, levels)  # tables built, caches warm
        stack.slice(m, 0.0)
        a, b, c = [], [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            for w in levels:
                slice_polytope(p, m, float(w))
            a.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            slice_polytope(p, m, levels)
            b.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            stack.slice(m, 0.0)
            c.append(time.perf_counter() - t0)
        singles.append(min(a))
        batched.append(min(b))
        stacks.append(min(c))
    s16, b16, st = (statistics.median(x) for x in (singles, batched, stacks))
    return {"name": name, "single16_ms": 1e3 * s16, "one_ms": 1e3 * s16 / LEVELS, "batched_ms": 1e3 * b16,
            "ratio": b16 / (s16 / LEVELS), "stack12_ms": 1e3 * st}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orientations", type=int, default=7)
    ap.add_argument("--repeats", type=int, default=15)
    args = ap.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{LEVELS} levels, {args.orientations} orientations x {args.repeats} repeats (fastest per orientation, "
          f"median over orientations); load average {load:.1f} on {os.cpu_count()} cores")
    print("| polytope | 16 single calls (ms) | one single (ms) | batched 16 (ms) | batched / one single | target | "
          "StackSource N=12 (ms) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in NAMES:
        r = measure(name, args.orientations, args.repeats)
        target = f"\u2264 {TARGET[name]:g}" if name in TARGET else ""
        print(f"| {name} | {r['single16_ms']:.2f} | {r['one_ms']:.3f} | {r['batched_ms']:.2f} | {r['ratio']:.2f} | "
              f"{target} | {r['stack12_ms']:.2f} |")


if __name__ == "__main__":
    main()
