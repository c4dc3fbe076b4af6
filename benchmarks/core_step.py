"""Median time of one key step in the numpy core: ``state.press`` + ``slice_polytope``.

For each regular polychoron: N random orientations (fixed seed), the slice
hyperplane through the centre (c0 = 0); each sample times one press of "4"
followed by a full `slice_polytope` (every `Slice` field is computed eagerly).

    python benchmarks/core_step.py [--steps N]

Targets on the project's 2-core machine (medians): 5-cell <= 0.15 ms,
120-cell <= 0.5 ms, 600-cell <= 0.6 ms.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from rot4d_widget import RotationState, polytope, slice_polytope

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]
TARGET_MS = {"5-cell": 0.15, "120-cell": 0.5, "600-cell": 0.6}


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def measure(name: str, steps: int, seed: int = 0) -> dict:
    p = polytope(name)
    rng = np.random.default_rng(seed)
    state = RotationState()
    slice_polytope(p, state.matrix, 0.0)  # build the incidence tables outside the timing
    times, sizes = [], []
    for _ in range(steps):
        state.matrix = random_rotation(rng)
        t0 = time.perf_counter()
        state.press("4")
        s = slice_polytope(p, state.matrix, state.c0)
        times.append(time.perf_counter() - t0)
        sizes.append((len(s.vertices), len(s.edges), len(s.cell_ids)))
    v, e, f = (statistics.median(x) for x in zip(*sizes))
    return {"name": name, "median_ms": 1e3 * statistics.median(times), "p90_ms": 1e3 * float(np.percentile(times, 90)),
            "V": v, "E": e, "F": f}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=3000)
    args = ap.parse_args()
    print(f"press + slice_polytope, random orientations, c0 = 0, {args.steps} steps each (medians)")
    print("| polytope | median (ms) | p90 (ms) | target (ms) | slice V / E / F (median) |")
    print("|---|---:|---:|---:|---|")
    for name in NAMES:
        r = measure(name, args.steps)
        target = TARGET_MS.get(name)
        mark = "" if target is None else (f"{target:.2f} {'ok' if r['median_ms'] <= target else 'MISSED'}")
        print(f"| {name} | {r['median_ms']:.3f} | {r['p90_ms']:.3f} | {mark} | {r['V']:.0f} / {r['E']:.0f} / {r['F']:.0f} |")


if __name__ == "__main__":
    main()
