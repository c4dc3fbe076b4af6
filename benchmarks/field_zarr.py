"""A big field: a zarr store, the first picture, the background coarse copy, held keys and full steps.

    python benchmarks/field_zarr.py [--size 100 | --gb 4] [--chunk 32] [--store DIR] [--steps 30]

Builds (once; kept at ``--store``, default ``/tmp/rot4d-zarr-<size>-<chunk>.zarr``) a
float32 zarr array of ``size``^4 samples (default 100^4 = 0.4 GB, 256 chunks; ``--gb 4``:
the size of about 4 GB, 178^4) in ``chunk``^4 chunks, written
by a separate process slab by slab, so its memory does not count: f = a smooth field
(a few travelling plane waves) on [-1, 1]^4.  Then, in this process, a `Field4D` over
the store and, at fixed orientations (seed 0):

* first picture: a full-resolution step of the fresh field (no levels given: the range and the
  default level come from the chunks it reads, "first cut"): time, chunks read (only those the
  hyperplane touches; the coarse copy is not built);
* background build: ``prepare_coarse()`` reads every chunk once on a daemon thread, chunk by
  chunk; time until ``coarse_ready``, and the peak resident set meanwhile (the copy plus a few
  chunks), and a held key's step during the build (full resolution meanwhile);
* held keys: ``--steps`` coarse steps of R_xw by theta0, as a held "4" does (the coarse copy
  only; no chunk read): steps per second;
* at rest: a full-resolution step at each of 3 orientations (reads only the chunks the
  hyperplane touches): time, chunks read, and how many the store has.

Memory: the process's resident set (``/proc/self/statm``, sampled every 5 ms by a thread)
-- its peak in each phase -- and ``ru_maxrss`` at the end.  The target (issue 9): the peak
stays <= 1 GB while keys are held and at rest.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import threading
import time

import numpy as np

PAGE = os.sysconf("SC_PAGE_SIZE")


def rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * PAGE


class PeakRSS:
    """Samples the resident set every 5 ms; ``peak()`` since the last ``reset()``."""

    def __init__(self):
        self._peak = rss()
        self._run = True
        self._t = threading.Thread(target=self._loop, daemon=True)
        self._t.start()

    def _loop(self):
        while self._run:
            self._peak = max(self._peak, rss())
            time.sleep(0.005)

    def reset(self):
        self._peak = rss()

    def peak(self) -> int:
        self._peak = max(self._peak, rss())
        return self._peak

    def stop(self):
        self._run = False


def values(block_x, n):
    """The field on the nodes of x-indices ``block_x`` (all y, z, w): float32 (len(block_x), n, n, n)."""
    g = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    x = g[block_x][:, None, None, None]
    y, z, w = g[None, :, None, None], g[None, None, :, None], g[None, None, None, :]
    return (np.cos(4 * x + 2 * w) * np.cos(3 * y - w) + np.cos(5 * z + 3 * w) * np.cos(2 * x)).astype(np.float32)


def create(store: pathlib.Path, n: int, chunk: int) -> None:
    """Write the store slab by slab (one chunk thick along x)."""
    import zarr

    z = zarr.create_array(store=str(store), shape=(n,) * 4, chunks=(chunk,) * 4, dtype="float32",
                          overwrite=True)
    for x0 in range(0, n, chunk):
        idx = np.arange(x0, min(n, x0 + chunk))
        z[x0:x0 + len(idx)] = values(idx, n)
    (store / "COMPLETE").write_text(f"{n} {chunk}\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=100, help="samples per axis (default 100: 0.4 GB)")
    ap.add_argument("--gb", type=float, default=None, help="the store's size in GB instead of --size (4: 178^4)")
    ap.add_argument("--chunk", type=int, default=32, help="chunk edge (default 32)")
    ap.add_argument("--store", default=None, help="where the store is kept")
    ap.add_argument("--steps", type=int, default=30, help="coarse steps of the held key (default 30)")
    ap.add_argument("--create-only", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.gb is not None:
        args.size = int(round((args.gb * 1e9 / 4) ** 0.25))
    if args.size < 8 or args.chunk < 2:
        ap.error("--size >= 8 and --chunk >= 2")
    store = pathlib.Path(args.store or f"/tmp/rot4d-zarr-{args.size}-{args.chunk}.zarr")
    if args.create_only:
        create(store, args.size, args.chunk)
        return 0
    if not (store / "COMPLETE").exists():
        t0 = time.perf_counter()
        print(f"writing {store} ({args.size ** 4 * 4 / 1e9:.1f} GB) in a separate process ...", file=sys.stderr)
        subprocess.run([sys.executable, __file__, "--size", str(args.size), "--chunk", str(args.chunk),
                        "--store", str(store), "--create-only"], check=True)
        print(f"  written in {time.perf_counter() - t0:.0f} s", file=sys.stderr)

    import zarr

    from rot4d_widget import Field4D
    from rot4d_widget.rotation import random_rotation, simple_rotation

    mem = PeakRSS()
    start = rss()
    z = zarr.open_array(str(store), mode="r")
    field = Field4D(z, axes="xyzw", extent=[(-1.0, 1.0)] * 4)  # no levels: the default one from the first cut
    n_chunks = int(np.prod([-(-n // c) for n, c in zip(z.shape, z.chunks)]))

    def reads() -> int:  # chunks the field's reader has read from the store (full steps)
        return field._reader.reads if field._reader is not None else 0
    rows = []

    mem.reset()
    t0 = time.perf_counter()
    m = random_rotation(np.random.default_rng(0))
    first = field.slice(m, 0.05)
    t_first = time.perf_counter() - t0
    assert not field.coarse_ready
    rows.append((f"first picture: full step of the fresh field (range {field.data_range_source}, "
                 f"level {field.levels[0]:.3g}; no coarse copy)",
                 f"{t_first:.2f} s, {len(first.triangles)} triangles", mem.peak(), reads()))

    mem.reset()
    t0 = time.perf_counter()
    field.prepare_coarse(progress=False)
    t_return = time.perf_counter() - t0
    t1 = time.perf_counter()
    held = field.slice(m, 0.05, coarse=True)
    t_held = time.perf_counter() - t1
    meanwhile = "full resolution" if "being built" in dict(held.readout)["resolution"] else "coarse (build done)"
    while not field.coarse_ready:
        time.sleep(0.01)
    t_build = time.perf_counter() - t0
    rows.append((f"background build: prepare_coarse() returned in {1000 * t_return:.1f} ms; coarse copy ready "
                 f"(every chunk once, chunk by chunk); a held key's step meanwhile: {1000 * t_held:.0f} ms "
                 f"({meanwhile})", f"{t_build:.1f} s", mem.peak(), n_chunks))

    mem.reset()
    step = simple_rotation("xw", np.pi / 64)
    reads0 = reads()
    times = []
    for _ in range(args.steps):
        m = step @ m
        t0 = time.perf_counter()
        field.slice(m, 0.05, coarse=True)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    rows.append((f"held '4': {args.steps} coarse steps", f"{1 / med:.1f} steps/s ({1000 * med:.1f} ms each)",
                 mem.peak(), reads() - reads0))

    rng = np.random.default_rng(1)
    for k in range(3):
        m = random_rotation(rng)
        if field._reader is not None:
            field._reader.clear_cache()
        mem.reset()
        reads0 = reads()
        t0 = time.perf_counter()
        s = field.slice(m, 0.05)
        dt = time.perf_counter() - t0
        rows.append((f"at rest: full step, orientation {k + 1}", f"{1000 * dt:.0f} ms, {len(s.triangles)} triangles",
                     mem.peak(), reads() - reads0))
    mem.stop()

    print(f"zarr store {store}: {args.size}^4 float32 = {args.size ** 4 * 4 / 1e9:.2f} GB, chunks {args.chunk}^4 "
          f"({n_chunks} chunks); resolution {field.resolution}, coarse {field.coarse_resolution}; "
          f"resident before opening {start / 2**20:.0f} MB\n")
    print("| phase | time | peak resident MB | chunks read |")
    print("|---|---|---:|---:|")
    for name, t, peak, reads in rows:
        print(f"| {name} | {t} | {peak / 2**20:.0f} | {reads} |")
    maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(f"\nru_maxrss of the whole run: {maxrss / 2**20:.0f} MB (target: <= 1024 MB while keys are held and at rest)")
    held_rest = max(r[2] for r in rows[1:])
    print(f"peak while held and at rest: {held_rest / 2**20:.0f} MB -> {'ok' if held_rest <= 2**30 else 'MISSED'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
