"""What a compiled (numba) kernel costs a fresh process before its first answer (issue 22's question:
would a numba star slicer keep "loads within 2x the 600-cell"?).

The project's own numba kernel, `rot4d_widget.sources.field.kernels` (``cache=True``: compiled once,
loaded from numba's on-disk cache afterwards), is called on a tiny array in ``--runs`` fresh Python
processes; each reports ``import rot4d_widget`` (which imports numba), the first call (the cached
kernel loaded) and the second call.  The first run may compile (no cache yet): its row says so.
Against it, the same processes build the 600-cell from its arrays and slice it once (what
benchmarks/star_load.py calls its load).

    python benchmarks/numba_first_call.py [--runs 5]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

CHILD = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import rot4d_widget
t1 = time.perf_counter()
from rot4d_widget import Polytope, polytope
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
p0 = polytope("600-cell")
v, f, c = p0.vertices.copy(), [x.tolist() for x in p0.faces], [list(x) for x in p0.cells]
t2 = time.perf_counter()
p = Polytope(v, f, c)
slice_polytope(p, np.eye(4), 0.1)
t3 = time.perf_counter()
from rot4d_widget.sources.field import kernels as fk
a, idx, inside = np.zeros((3, 3, 3, 3)), np.zeros((4, 4)), np.ones(4, bool)
t4 = time.perf_counter()
fk.resample_points(a, idx, inside)
t5 = time.perf_counter()
fk.resample_points(a, idx, inside)
t6 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "load600": t3 - t2, "first": t5 - t4, "second": t6 - t5}))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    rows = []
    for _ in range(args.runs):
        out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True)
        rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
    print("| run | import rot4d_widget (ms) | 600-cell load (ms) | numba kernel, first call (ms) | second call (ms) |")
    print("|---|---:|---:|---:|---:|")
    for i, r in enumerate(rows, 1):
        print(f"| {i} | {1e3 * r['import']:.0f} | {1e3 * r['load600']:.1f} | {1e3 * r['first']:.0f} | "
              f"{1e3 * r['second']:.3f} |")
    med = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
    print(f"| median | {1e3 * med['import']:.0f} | {1e3 * med['load600']:.1f} | {1e3 * med['first']:.0f} | "
          f"{1e3 * med['second']:.3f} |")
    print(f"\nfirst call / 600-cell load, median: {med['first'] / med['load600']:.0f}x "
          "(run 1 may include compiling, if numba's cache was empty)")


if __name__ == "__main__":
    main()
