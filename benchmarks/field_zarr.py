"""A big field: a zarr store, the first picture, the background coarse copy, held keys and full steps.

    python benchmarks/field_zarr.py [--size 100 | --gb 4] [--chunk 32] [--store DIR] [--steps 30]
                                    [--open xarray,zarr]

The store (written once if missing, by a separate process slab by slab, so its memory does not
count; kept at ``--store``, default ``/tmp/rot4d-field-<size>-<chunk>.zarr``, for the next run --
delete it by hand): a zarr v3 group holding ``f``, a float32 array of ``size``^4 samples
(default 100^4 = 0.4 GB in 256 chunks; ``--gb 4``: 178^4 = 4.0 GB in 1296 chunks) in
``chunk``^4 chunks, dims x, y, z, w with coordinates -1 .. 1 each, f = a few travelling plane
waves; its attributes carry ``actual_range`` (the writer's min and max) and ``valid_min`` /
``valid_max`` (-2, 2), as CF-minded writers do.

Each opening in ``--open`` is measured in turn, as a user opens a store (lazily: nothing is read
but metadata and coordinates):

* ``xarray``: ``Field4D.from_xarray(xarray.open_zarr(store)["f"])`` -- dask over the store's
  chunks; the data range and default level from the metadata (``actual_range``);
* ``zarr``: ``Field4D(zarr.open_array(store, path="f"), axes="xyzw", extent=...)`` -- the
  zarr array itself; no metadata range, so the range and level come from the first cut.

The store is opened through a thin wrapper that counts the chunk objects zarr fetches from it
(``f/c/...`` keys: distinct and all), independent of the library's own count
(``field._reader.reads``).  Phases, at fixed orientations (seed 0):

1. open: time, chunks fetched (0 expected);
2. first picture: a full-resolution step of the fresh field (no levels given): time, chunks
   fetched of the store's total -- only those the hyperplane touches, never a full read;
3. background build alone: ``prepare(progress=False)`` (a daemon thread reading every
   chunk once, chunk by chunk) and nothing else until ``coarse_ready``: the build time, and the
   resident set's peak rise over the build's start, against the bound: the coarse copy (its
   float64 accumulator plus the float32 result) plus the chunks of one read batch plus 4 more;
4. held keys after the build: ``--steps`` coarse steps of R_xw by pi/64, as a held "4" does
   (the coarse copy only, no chunk read);
5. at rest: a full-resolution step at each of 3 orientations, chunk cache cleared first;
6. held keys during the build: a fresh field (opened again), its first picture, then
   ``prepare`` and held-key steps (``slice(..., coarse=True)``) back to back until the
   copy is ready -- from the full data meanwhile, at the resolution the readout names (quoted in
   the row) -- then ``--steps`` more.

Memory: the resident set (``/proc/self/statm``, sampled every 5 ms by a thread), its peak in
each phase; ``ru_maxrss`` at the end.  Target (issue 9): <= 1 GB while keys are held and at rest.
The store was just written or read, so its files are in the page cache (not in the resident set):
the times are decompression and slicing, not disk reads.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import threading
import time
import warnings

import numpy as np

PAGE = os.sysconf("SC_PAGE_SIZE")
MB = 2**20
LAYOUT = "rot4d field store v2"  # the first line of the COMPLETE marker
#: The fields' memory budget: 0, the store is never read whole (the big-store path this measures,
#: whatever --size; a store within the default budget would be read into memory by the background read)
BUDGET = 0


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

    def reset(self) -> int:
        self._peak = now = rss()
        return now

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
    """Write the store slab by slab (one chunk thick along x), then its range into the attributes."""
    import zarr

    root = zarr.open_group(str(store), mode="w", zarr_format=3)
    for d in "xyzw":
        c = root.create_array(d, shape=(n,), chunks=(n,), dtype="float64", dimension_names=(d,))
        c[:] = np.linspace(-1.0, 1.0, n)
    f = root.create_array("f", shape=(n,) * 4, chunks=(chunk,) * 4, dtype="float32",
                          dimension_names=tuple("xyzw"))
    lo, hi = math.inf, -math.inf
    for x0 in range(0, n, chunk):
        v = values(np.arange(x0, min(n, x0 + chunk)), n)
        lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
        f[x0:x0 + len(v)] = v
        del v
    f.attrs.update({"long_name": "travelling plane waves", "units": "1", "actual_range": [lo, hi],
                    "valid_min": -2.0, "valid_max": 2.0})
    with warnings.catch_warnings():  # "consolidated metadata is not part of the zarr v3 spec": xarray uses it
        warnings.simplefilter("ignore")
        zarr.consolidate_metadata(str(store))
    (store / "COMPLETE").write_text(f"{LAYOUT}\n{n} {chunk}\n")


def counting_store(path: pathlib.Path):
    """The store at ``path``, read-only, counting the chunk objects of ``f`` fetched from it."""
    import zarr.storage

    class CountingStore(zarr.storage.WrapperStore):
        def __init__(self, store, counts=None):
            super().__init__(store)
            self.counts = counts if counts is not None else {"all": 0, "keys": {}}

        def _with_store(self, store):
            return type(self)(store, self.counts)

        def _count(self, key, buf=None):
            if key.startswith("f/c/"):
                c = self.counts
                c["all"] += 1
                c["keys"][key] = 0 if buf is None else len(buf)

        async def get(self, key, prototype, byte_range=None):
            buf = await self._store.get(key, prototype, byte_range)
            self._count(key, buf)
            return buf

        async def get_partial_values(self, prototype, key_ranges):
            key_ranges = list(key_ranges)
            for key, _ in key_ranges:
                self._count(key)
            return await self._store.get_partial_values(prototype, key_ranges)

    return CountingStore(zarr.storage.LocalStore(str(path), read_only=True))


class Fetches:
    """Chunk objects fetched from the store since ``start()``: (distinct, all, MB of the distinct ones)."""

    def __init__(self, counts):
        self.c = counts
        self.start()

    def start(self):
        self.c["keys"] = {}  # the counting store adds to the dict it finds here: key -> bytes
        self.all0 = self.c["all"]

    def since(self):
        return len(self.c["keys"]), self.c["all"] - self.all0, sum(self.c["keys"].values()) / MB


def open_field(how: str, path: pathlib.Path, n: int):
    """(field, chunk counts) opened lazily as a user would, through the counting store."""
    from rot4d_widget import Field4D

    st = counting_store(path)
    if how == "xarray":
        import xarray

        ds = xarray.open_zarr(st)  # chunks: the store's own (dask); consolidated metadata
        field = Field4D.from_xarray(ds["f"], memory_budget=BUDGET)
    else:
        import zarr

        z = zarr.open_array(store=st, path="f", mode="r")
        field = Field4D(z, axes="xyzw", extent=[(-1.0, 1.0)] * 4, memory_budget=BUDGET)  # no levels: from the first cut
    return field, st.counts


def fetched_text(f, n_chunks):
    distinct, total, mb = f
    return f"{distinct}" + (f" ({total} fetches)" if total != distinct else "") + f" of {n_chunks}"


def measure(how: str, path: pathlib.Path, args, mem: PeakRSS, n_chunks: int, chunk_mb: float, disk: int):
    """The phases for one way of opening: (rows, notes)."""
    from rot4d_widget.sources.field import chunks
    from rot4d_widget.core.rotation import random_rotation, simple_rotation

    rows, notes = [], []
    gc.collect()
    before = mem.reset()

    # 1. open
    t0 = time.perf_counter()
    field, counts = open_field(how, path, args.size)
    t_open = time.perf_counter() - t0
    opened = (len(counts["keys"]), counts["all"], sum(counts["keys"].values()) / MB)
    fetch = Fetches(counts)
    rows.append((how, "open lazily", f"{1000 * t_open:.0f} ms", mem.peak(), None, fetched_text(opened, n_chunks)))
    notes.append(f"{how}: resident before opening {before / MB:.0f} MB; {field!r}")

    def reads() -> int:  # chunks the field's reader has read (full steps)
        return field._reader.reads if field._reader is not None else 0

    # 2. first picture
    mem.reset()
    fetch.start()
    m0 = random_rotation(np.random.default_rng(0))  # c0 = 0.05: the box is centred on w = 0, 1 w per unit
    t0 = time.perf_counter()
    first = field.slice(m0, 0.05)
    t_first = time.perf_counter() - t0
    f_first = fetch.since()
    assert not field.coarse_ready, "the first picture built the coarse copy"
    full_read = f_first[0] >= n_chunks
    rows.append((how, f"first picture: full step of the fresh field (range {field.data_range_source} "
                      f"{field.data_range[0]:.3g} … {field.data_range[1]:.3g}, level {field.levels[0]:.3g}; "
                      f"no coarse copy)",
                 f"{t_first:.2f} s, {len(first.triangles)} triangles", mem.peak(), None,
                 fetched_text(f_first, n_chunks) + (" FULL READ" if full_read else "")))
    notes.append(f"{how}: first picture fetched {f_first[0]} of {n_chunks} chunks, {f_first[2]:.0f} of the store's "
                 f"{disk / MB:.0f} MB on disk ({f_first[1]} fetches in all; the field's reader counts {reads()} "
                 f"reads) -> {'FULL READ' if full_read else 'no full read'}")

    # 3. the background build, alone
    gc.collect()
    start = mem.reset()
    fetch.start()
    t0 = time.perf_counter()
    field.prepare(progress=False)
    t_return = time.perf_counter() - t0
    while not field.coarse_ready:
        if field._coarse_error is not None:
            raise RuntimeError("the coarse build failed") from field._coarse_error
        time.sleep(0.01)
    t_build = time.perf_counter() - t0
    peak = mem.peak()
    f_build = fetch.since()
    coarse = field.coarse()
    copy_bytes = coarse.values.nbytes
    acc_bytes = coarse.values.size * 8  # the float64 accumulator the copy is summed in
    batch = max(1, min(chunks.CHUNK_BATCH, (64 * MB) // max(1, int(chunk_mb * MB))))
    bound = acc_bytes + copy_bytes + (batch + 4) * chunk_mb * MB
    rise = peak - start
    ok = rise <= bound
    rows.append((how, f"background build alone: prepare() returned in {1000 * t_return:.1f} ms; "
                      f"coarse copy {tuple(coarse.values.shape)} ready (every chunk once, chunk by chunk)",
                 f"{t_build:.1f} s", peak, rise, fetched_text(f_build, n_chunks)))
    notes.append(f"{how}: build rise {rise / MB:.0f} MB over its start ({start / MB:.0f} MB) vs the bound "
                 f"{bound / MB:.0f} MB = accumulator {acc_bytes / MB:.0f} + copy {copy_bytes / MB:.0f} + "
                 f"({batch} batch + 4) x {chunk_mb:.1f} MB chunks -> {'ok' if ok else 'OVER THE BOUND'}")

    # 4. held keys after the build
    mem.reset()
    fetch.start()
    step = simple_rotation("xw", np.pi / 64)
    m = m0
    times = []
    for _ in range(args.steps):
        m = step @ m
        t0 = time.perf_counter()
        field.slice(m, 0.05, coarse=True)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    rows.append((how, f"held '4' after the build: {args.steps} coarse steps",
                 f"{1 / med:.1f} steps/s ({1000 * med:.1f} ms each)", mem.peak(), None,
                 fetched_text(fetch.since(), n_chunks)))

    # 5. at rest
    rng = np.random.default_rng(1)
    for k in range(3):
        m = random_rotation(rng)
        if field._reader is not None:
            field._reader.clear_cache()
        mem.reset()
        fetch.start()
        t0 = time.perf_counter()
        s = field.slice(m, 0.05)
        dt = time.perf_counter() - t0
        rows.append((how, f"at rest: full step, orientation {k + 1}", f"{1000 * dt:.0f} ms, {len(s.triangles)} triangles",
                     mem.peak(), None, fetched_text(fetch.since(), n_chunks)))
    del field, coarse, first, s

    # 6. held keys during the build: a fresh field
    gc.collect()
    field, counts = open_field(how, path, args.size)
    fetch = Fetches(counts)
    field.slice(m0, 0.05)  # its first picture
    gc.collect()
    start = mem.reset()
    fetch.start()
    t0 = time.perf_counter()
    field.prepare(progress=False)
    m = m0
    during, said = [], set()
    while not field.coarse_ready:
        m = step @ m
        t1 = time.perf_counter()
        s = field.slice(m, 0.05, coarse=True)
        during.append(time.perf_counter() - t1)
        res = dict(s.readout).get("resolution", "")  # e.g. "32 (from the full data: the coarse copy is being built ..."
        said.add(res.split(" ")[0] + (" from the full data" if "being built" in res else " from the coarse copy"))
    t_build2 = time.perf_counter() - t0
    peak_during = mem.peak()
    f_during = fetch.since()
    after = []
    mem.reset()
    fetch.start()
    for _ in range(args.steps):
        m = step @ m
        t1 = time.perf_counter()
        field.slice(m, 0.05, coarse=True)
        after.append(time.perf_counter() - t1)
    steps_text = (f"{len(during)} steps, median {1000 * statistics.median(during):.0f} ms, max "
                  f"{1000 * max(during):.0f} ms" if during else "no step (built before the first)")
    rows.append((how, f"held '4' during the build (fresh field): steps back to back until the copy is ready "
                      f"(readout: resolution {', '.join(sorted(said)) or '-'}); build {t_build2:.1f} s with them",
                 steps_text, peak_during, peak_during - start, fetched_text(f_during, n_chunks)))
    rows.append((how, f"held '4' right after that build: {args.steps} coarse steps",
                 f"{1 / statistics.median(after):.1f} steps/s ({1000 * statistics.median(after):.1f} ms each)",
                 mem.peak(), None, fetched_text(fetch.since(), n_chunks)))
    del field, s
    gc.collect()
    return rows, notes


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=100, help="samples per axis (default 100: 0.4 GB)")
    ap.add_argument("--gb", type=float, default=None, help="the store's size in GB instead of --size (4: 178^4)")
    ap.add_argument("--chunk", type=int, default=32, help="chunk edge (default 32)")
    ap.add_argument("--store", default=None, help="where the store is kept")
    ap.add_argument("--steps", type=int, default=30, help="coarse steps of the held key (default 30)")
    ap.add_argument("--open", default="xarray,zarr", help="ways of opening, comma-separated: xarray, zarr")
    ap.add_argument("--create-only", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.gb is not None:
        args.size = int(round((args.gb * 1e9 / 4) ** 0.25))
    if args.size < 8 or args.chunk < 2:
        ap.error("--size >= 8 and --chunk >= 2")
    openings = [o.strip() for o in args.open.split(",") if o.strip()]
    if not openings or any(o not in ("xarray", "zarr") for o in openings):
        ap.error("--open takes xarray, zarr or both")
    store = pathlib.Path(args.store or f"/tmp/rot4d-field-{args.size}-{args.chunk}.zarr")
    if args.create_only:
        create(store, args.size, args.chunk)
        return 0
    marker = store / "COMPLETE"
    if not (marker.exists() and marker.read_text().splitlines()[:1] == [LAYOUT]):
        t0 = time.perf_counter()
        print(f"writing {store} ({args.size ** 4 * 4 / 1e9:.1f} GB) in a separate process ...", file=sys.stderr)
        subprocess.run([sys.executable, __file__, "--size", str(args.size), "--chunk", str(args.chunk),
                        "--store", str(store), "--create-only"], check=True)
        print(f"  written in {time.perf_counter() - t0:.0f} s", file=sys.stderr)

    n_chunks = math.prod(-(-args.size // args.chunk) for _ in range(4))
    chunk_mb = args.chunk ** 4 * 4 / MB
    disk = sum(p.stat().st_size for p in (store / "f" / "c").rglob("*") if p.is_file())

    mem = PeakRSS()
    start = rss()
    import dask.array  # noqa: F401 - imported before the first measurement (opening times exclude imports)
    import xarray  # noqa: F401
    import zarr  # noqa: F401

    import rot4d_widget  # noqa: F401

    rows, notes = [], []
    for how in openings:
        r, nt = measure(how, store, args, mem, n_chunks, chunk_mb, disk)
        rows += r
        notes += nt
    mem.stop()

    print(f"zarr store {store}: {args.size}^4 float32 = {args.size ** 4 * 4 / 1e9:.2f} GB "
          f"({disk / 1e9:.2f} GB on disk), chunks {args.chunk}^4 = {chunk_mb:.1f} MB ({n_chunks} chunks); "
          f"resident at the start {start / MB:.0f} MB\n")
    print("| opening | phase | time | peak resident MB | rise MB | chunks fetched from the store |")
    print("|---|---|---|---:|---:|---:|")
    for how, name, t, peak, rise, fetched in rows:
        print(f"| {how} | {name} | {t} | {peak / MB:.0f} | {'' if rise is None else f'{rise / MB:.0f}'} | {fetched} |")
    print()
    for n in notes:
        print(f"* {n}")
    maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    held_rest = max(r[3] for r in rows if r[1].startswith(("held", "at rest")))
    print(f"* ru_maxrss of the whole run: {maxrss / MB:.0f} MB; peak while keys are held and at rest: "
          f"{held_rest / MB:.0f} MB (target <= 1024 MB) -> {'ok' if held_rest <= 2**30 else 'MISSED'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
