"""A big zarr store's first picture: from ``Rot4DWidget(field)`` to the first picture sent (issue 35).

    python benchmarks/field_first_picture.py [--base REV] [--gb 2] [--runs 3] [--chunk 32]

The store is `benchmarks/field_zarr.py`'s (written once if missing: ``--gb 2`` is 150^4 float32,
2.0 GB in 625 chunks of 32^4, dims x, y, z, w with coordinates and ``actual_range``), bigger than
a field's memory budget, so it is never read whole.  For each version of the package (``--base``,
a git revision exported clean, and the working tree: `benchmarks/revisions.py`), in turns, a fresh
Python process opens the store lazily the two ways a user would -- ``xarray``:
``Field4D.from_xarray(xarray.open_zarr(store)["f"])`` (dask over the store's chunks, the range
from ``actual_range``) and ``zarr``: ``Field4D(zarr.open_array(store, path="f"), axes="xyzw",
extent=...)`` (no metadata: the range and default level from the first cut) -- and times
``Rot4DWidget(field)``, a live widget (its ticker running): everything up to and including the
first picture the kernel slices and hands to the page, which is what "shown" waits for.  It
counts the chunks the field's reader read for it (of the store's total: the first cut's only,
never a full read), then, for the working tree, how long the background read (the coarse copy)
takes after it with the widget's bar following it.  Medians over ``--runs`` processes per version.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import statistics
import subprocess
import sys

from revisions import Revisions

CHILD = r"""
import json, sys, time, warnings
import numpy as np
warnings.simplefilter("ignore")  # zarr 3: consolidated metadata is not in the spec
import xarray, zarr
import rot4d_widget
from rot4d_widget import Field4D, Rot4DWidget
store, how = sys.argv[1], sys.argv[2]
if how == "xarray":
    field = Field4D.from_xarray(xarray.open_zarr(store)["f"])
else:
    field = Field4D(zarr.open_array(store=store, path="f", mode="r"), axes="xyzw", extent=[(-1.0, 1.0)] * 4)
t0 = time.perf_counter()
w = Rot4DWidget(field)
t1 = time.perf_counter()
out = {"file": rot4d_widget.__file__, "first": t1 - t0, "reads": field._reader.reads if field._reader else 0,
       "triangles": int(len(w.slice.triangles)), "ready_at_first": bool(field.coarse_ready)}
deadline = time.perf_counter() + 600
while not field.coarse_ready and time.perf_counter() < deadline:
    time.sleep(0.05)
out["read"] = time.perf_counter() - t1
bar = getattr(w, "progress_bar", None)
out["bar"] = None if bar is None else bar.visible
w.close()
print("RESULT" + json.dumps(out))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="main", help="the revision to compare with (default: main)")
    ap.add_argument("--gb", type=float, default=2.0, help="the store's size in GB (default 2: 150^4)")
    ap.add_argument("--chunk", type=int, default=32)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--open", default="xarray,zarr")
    args = ap.parse_args()
    size = int(round((args.gb * 1e9 / 4) ** 0.25))
    store = pathlib.Path(f"/tmp/rot4d-field-{size}-{args.chunk}.zarr")
    here = pathlib.Path(__file__).resolve().parent
    if not (store / "COMPLETE").exists():
        print(f"writing {store} ...", file=sys.stderr)
        subprocess.run([sys.executable, str(here / "field_zarr.py"), "--size", str(size), "--chunk", str(args.chunk),
                        "--store", str(store), "--create-only"], check=True)
    n_chunks = math.prod(-(-size // args.chunk) for _ in range(4))
    openings = [o.strip() for o in args.open.split(",") if o.strip()]
    rows = {}
    with Revisions([args.base, None]) as revs:
        for k in range(args.runs):
            for how in openings:
                for rev in revs:
                    proc = subprocess.run([sys.executable, "-c", CHILD, str(store), how], env=rev.env(),
                                          capture_output=True, text=True, timeout=1800)
                    if proc.returncode or "RESULT" not in proc.stdout:
                        raise RuntimeError(f"{rev.label} {how}: the child failed\n{proc.stderr[-3000:]}")
                    r = json.loads(proc.stdout.split("RESULT", 1)[1].splitlines()[0])
                    rev.check(r.pop("file"))
                    rows.setdefault((rev.label, how), []).append(r)
                    print(f"  run {k + 1}, {rev.label}, {how}: {r}", file=sys.stderr)
        print(f"store {store}: {size}^4 float32 = {size ** 4 * 4 / 1e9:.2f} GB in {n_chunks} chunks of "
              f"{args.chunk}^4; {args.runs} fresh processes per version and opening, alternating\n")
        print("| version | opening | Rot4DWidget(field) to the first picture sent, s (per run) | chunks read for it "
              "| the background read after it (coarse copy), s |")
        print("|---|---|---:|---:|---:|")
        for rev in revs:
            for how in openings:
                rs = rows[(rev.label, how)]
                first = statistics.median(r["first"] for r in rs)
                each = ", ".join(f"{r['first']:.2f}" for r in rs)
                reads = statistics.median(r["reads"] for r in rs)
                full = " (more reads than the store has chunks)" if reads >= n_chunks else ""
                read = statistics.median(r["read"] for r in rs)
                print(f"| {rev.label} | {how} | {first:.2f} ({each}) | {reads:.0f} of {n_chunks}{full} | {read:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
