"""Chunk fetches of full-resolution steps of a zarr-backed field: points in grid order vs ordered by chunk.

    python benchmarks/chunk_fetches.py [--size 100] [--chunk 32] [--cache-mb 32,128] [--seeds 0,1,2]

A step reads the values at its sample points in passes of ``fields.CHUNKED_POINTS`` points, each
pass fetching the chunks its points' cells touch, through the field's chunk cache
(``chunk_cache_bytes``).  When a step touches more chunks than the cache holds, a chunk needed by
two passes far apart is fetched twice.  ``fields._SORT_PASSES`` orders the points by the chunk
their cell starts in first.  This prints, for each cache size and orientation (random rotations,
seeds), the chunks fetched with and without that order, the distinct chunks the step needs (the
floor) and the step's time, both orders in the same run on the same store.  The store (float32,
``size``^4, ``chunk``^4 chunks, a smooth sum of waves) is written to /tmp once if missing.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

from rot4d_widget import Field4D  # noqa: E402
from rot4d_widget.sources.field import chunks, container  # noqa: E402
from rot4d_widget.core.rotation import random_rotation  # noqa: E402


def store(size: int, chunk: int) -> str:
    import zarr

    path = f"/tmp/rot4d-fetches-{size}-{chunk}.zarr"
    if not os.path.exists(os.path.join(path, "f", "zarr.json")):
        g = zarr.open_group(path, mode="w")
        z = g.create_array("f", shape=(size,) * 4, chunks=(chunk,) * 4, dtype="f4")
        x = np.linspace(-1.0, 1.0, size)
        Y, Z, W = np.meshgrid(x, x, x, indexing="ij")
        for i in range(size):
            z[i] = (np.sin(3 * x[i] + 2 * W) + np.cos(2 * Y - W) + np.sin(2.5 * Z + W)).astype("f4")
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=int, default=100)
    ap.add_argument("--chunk", type=int, default=32)
    ap.add_argument("--cache-mb", default="32,128")
    ap.add_argument("--seeds", default="0,1,2")
    args = ap.parse_args()
    import zarr

    warnings.simplefilter("ignore")
    z = zarr.open_group(store(args.size, args.chunk), mode="r")["f"]
    fetched: list = []
    original = chunks.ChunkReader.read

    def counting_read(self, wanted):
        with self._lock:
            fetched.extend(i for i in wanted if i not in self._cache)
        return original(self, wanted)

    chunks.ChunkReader.read = counting_read
    print(f"store {args.size}^4 float32, {args.chunk}^4 chunks ({args.chunk ** 4 * 4 / 2**20:.0f} MiB each)")
    print(f"{'cache MiB':>9} {'seed':>4} {'distinct':>8} {'grid order':>10} {'by chunk':>8} {'time grid s':>11} {'time chunk s':>12}")
    for mb in (int(v) for v in args.cache_mb.split(",")):
        ratios = []
        for seed in (int(v) for v in args.seeds.split(",")):
            row = {}
            for order in (False, True):
                container._SORT_PASSES = order
                fetched.clear()
                f = Field4D(z, axes="xyzw", extent=[(-1.0, 1.0)] * 4, levels=[0.0], chunk_cache_bytes=mb * 2**20)
                t = time.perf_counter()
                f.slice(random_rotation(seed), 0.0)
                row[order] = (len(fetched), len(set(fetched)), time.perf_counter() - t)
            ratios.append(row[True][0] / row[False][0])
            print(f"{mb:>9} {seed:>4} {row[True][1]:>8} {row[False][0]:>10} {row[True][0]:>8} "
                  f"{row[False][2]:>11.2f} {row[True][2]:>12.2f}")
        print(f"{mb:>9} median fetches by chunk / grid order: {statistics.median(ratios):.2f}")
    container._SORT_PASSES = True


if __name__ == "__main__":
    main()
