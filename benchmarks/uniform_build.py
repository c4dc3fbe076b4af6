"""Cold build time and slice time of the uniform polychora (rot4d_widget.geometry.uniform).

For each polychoron, a fresh Python process (``subprocess``) imports the package, then times

* **build**: ``uniform.build(name)`` (group, Wythoff cosets, faces, cells, the validated
  `Polytope`) plus the first ``slice_polytope`` call, which builds the slicing tables — so
  everything the first slice needs; the median of ``--repeats`` fresh processes;
* **slice**: ``slice_polytope(p, matrix, 0.0)`` at ``--steps`` random orientations (fixed
  seed), hyperplane through the centre; the median.

    python benchmarks/uniform_build.py [--steps N] [--repeats R] [--names all|non-prismatic|big]

The regular six are the core's objects (``polytope(name)``, built from their hull as before);
their row is what ``build`` costs for them.  Target (issue 11): the 14400-vertex omnitruncated
120-cell builds in <= 2 s on the developers' machine (~3x faster than the project's 2-core one)
and slices in <= 5 ms.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from rot4d_widget.geometry import uniform
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
t1 = time.perf_counter()
name, steps = sys.argv[1], int(sys.argv[2])
p = uniform.build(name)
t2 = time.perf_counter()
slice_polytope(p, np.eye(4), 0.0)
t3 = time.perf_counter()
rng = np.random.default_rng(0)
times = []
for _ in range(steps):
    q, r = np.linalg.qr(rng.normal(size=(4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    a = time.perf_counter()
    s = slice_polytope(p, q, 0.0)
    times.append(time.perf_counter() - a)
print(json.dumps({"import": t1 - t0, "build": t2 - t1, "first_slice": t3 - t2,
                  "slice_ms": 1e3 * float(np.median(times)), "counts": list(p.counts),
                  "slice_F": len(s.cell_ids)}))
"""


def names(which: str) -> list:
    from rot4d_widget.geometry import uniform

    fams = uniform.polytope_names()
    non_prismatic = [n for f, ns in fams.items() if not f.startswith(("prisms", "duoprisms", "antiprismatic"))
                     for n in ns]
    if which == "non-prismatic":
        return non_prismatic
    if which == "big":
        return ["omnitruncated 120-cell", "runcitruncated 600-cell", "cantitruncated 120-cell", "120-cell"]
    prismatic = fams["prisms over the Platonic and Archimedean solids"]
    prismatic += ["3-3 duoprism", "5-7 duoprism", "32-32 duoprism", "4-antiprismatic prism", "32-antiprismatic prism"]
    return non_prismatic + prismatic


def measure(name: str, steps: int, repeats: int) -> dict:
    runs = []
    for _ in range(repeats):
        out = subprocess.run([sys.executable, "-c", CHILD, name, str(steps)], capture_output=True, text=True,
                             check=True)
        runs.append(json.loads(out.stdout))
    med = {k: statistics.median(r[k] for r in runs) for k in ("import", "build", "first_slice", "slice_ms")}
    return {"name": name, **med, "counts": runs[0]["counts"], "slice_F": runs[0]["slice_F"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--names", default="all", choices=["all", "non-prismatic", "big"])
    args = ap.parse_args()
    t = time.perf_counter()
    print(f"cold build in a fresh process (median of {args.repeats}) and slice_polytope at {args.steps} random "
          "orientations, c0 = 0 (median)")
    print("| polychoron | Dynkin | V, E, F, C | build (s) | + first slice, tables (s) | cold total (s) "
          "| slice (ms) | slice polygons |")
    print("|---|---|---|---:|---:|---:|---:|---:|")
    from rot4d_widget.geometry import uniform

    for name in names(args.names):
        r = measure(name, args.steps, args.repeats)
        sym = uniform.dynkin_symbol(name) or "–"
        print(f"| {name} | {sym} | {', '.join(map(str, r['counts']))} | {r['build']:.3f} | {r['first_slice']:.3f} "
              f"| {r['build'] + r['first_slice']:.3f} | {r['slice_ms']:.2f} | {r['slice_F']} |", flush=True)
    print(f"(import of numpy, scipy and rot4d_widget.geometry.uniform + slicing, not in the figures: "
          f"~{r['import']:.2f} s; whole run {time.perf_counter() - t:.0f} s)")


if __name__ == "__main__":
    main()
