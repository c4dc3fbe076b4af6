"""Chunks a full-resolution slice of big chunked data reads, before and after (issue 35, item 2).

    python benchmarks/chunk_reads.py [--base REV] [--seeds 0,1]

The case of ``tests/sources/test_chunk_reads.py``: a 64^4 float32 dask array in 8^4 chunks (4096), read
through a wrapper counting the chunks dask fetches from it.  For each version of the package
(``--base``, a git revision exported clean, and the working tree: `benchmarks/revisions.py`) a
fresh process takes, at random orientations (``--seeds``) and c0 = 0.05, one full-resolution
slice of a fresh field each way -- ``Field4D.slice`` (what the widget asks), ``slice_field`` (the
documented way without a browser) and ``sample_field`` (the grid the volume renderings draw) --
and prints the chunks read, beside the chunks the hyperplane meets (each chunk's box grown by one
node: the most a slice may need) and whether the coarse copy (every chunk) was built.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

from revisions import Revisions

CHILD = r"""
import itertools, json, sys
import numpy as np
import dask.array as da
import rot4d_widget
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.field.container import Field4D, slice_field
from rot4d_widget.sources.field.grid import sample_field
N, C = 64, 8

class Counted:
    def __init__(self, a):
        self.a, self.shape, self.ndim, self.dtype, self.reads = a, a.shape, a.ndim, a.dtype, 0
    def __getitem__(self, key):
        out = self.a[key]
        self.reads += out.size > 0
        return out

g = np.linspace(-1.0, 1.0, N, dtype=np.float32)
x, y, z, w = np.meshgrid(g, g, g, g, indexing="ij", sparse=True)
values = (x * x + y * y + z * z + 0.5 * w * w).astype(np.float32)

def met(m, d):
    h = 2.0 / (N - 1)
    s = np.arange(0, N, C)
    lo, hi, row, n = -1.0 + s * h - h, -1.0 + (s + C - 1) * h + h, np.asarray(m)[3], 0
    for idx in itertools.product(range(N // C), repeat=4):
        a, b = np.array([lo[i] for i in idx]) * row, np.array([hi[i] for i in idx]) * row
        n += np.minimum(a, b).sum() <= d <= np.maximum(a, b).sum()
    return int(n)

out = {"file": rot4d_widget.__file__, "rows": []}
for seed in [int(v) for v in sys.argv[1].split(",")]:
    m = random_rotation(np.random.default_rng(seed))
    for how in ("Field4D.slice", "slice_field", "sample_field"):
        arr = Counted(values)
        f = Field4D(da.from_array(arr, chunks=(C,) * 4, asarray=False), axes="xyzw", extent=[(-1.0, 1.0)] * 4)
        if how == "Field4D.slice":
            f.slice(m, 0.05)
        elif how == "slice_field":
            slice_field(f, m, 0.05, 0.6)
        else:
            sample_field(f, m, 0.05, 64)
        out["rows"].append([seed, how, arr.reads, met(m, 0.05), bool(f.coarse_ready)])
print("RESULT" + json.dumps(out))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="main", help="the revision to compare with (default: main)")
    ap.add_argument("--seeds", default="0,1")
    args = ap.parse_args()
    print("64^4 float32 dask array in 8^4 chunks (4096); c0 = 0.05, random orientations\n")
    print("| version | orientation (seed) | slice by | chunks read | chunks the hyperplane meets | coarse copy built |")
    print("|---|---:|---|---:|---:|---|")
    with Revisions([args.base, None]) as revs:
        for rev in revs:
            proc = subprocess.run([sys.executable, "-c", CHILD, args.seeds], env=rev.env(), capture_output=True,
                                  text=True, timeout=1800)
            if proc.returncode or "RESULT" not in proc.stdout:
                raise RuntimeError(f"{rev.label}: the child failed\n{proc.stderr[-3000:]}")
            r = json.loads(proc.stdout.split("RESULT", 1)[1].splitlines()[0])
            rev.check(r["file"])
            for seed, how, reads, met, built in r["rows"]:
                print(f"| {rev.label} | {seed} | {how} | {reads} | {met} | {'yes' if built else 'no'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
