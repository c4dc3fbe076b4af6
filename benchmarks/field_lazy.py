"""A lazily opened netCDF file, the README's way, before and after the background read (issue 35).

    python benchmarks/field_lazy.py [--base REV] [--runs 3] [--steps 8] [--file PATH]

The file (written once if missing, default ``/tmp/rot4d-flame-80-60.nc``): an expanding wrinkled
flame, ``T`` in K on an 80^3 grid (x, y, z in m) at 60 uneven times from 1 to 4 ms (time in s),
float32, 123 MB, written by xarray with the scipy engine (netCDF3: what the package's own
install can write and read, no netCDF4 library).  For each version of the package (``--base``, a
git revision exported clean, and the working tree: `benchmarks/revisions.py`), in turns, a fresh
Python process does what the README says:

    field = Field4D.from_xarray(xarray.open_dataset(path)["T"], w="time")
    w = Rot4DWidget(field)

and measures: the widget's construction (its first picture included); the background read the
live widget starts, until it is over (``coarse_ready``; before, the coarse copy only); then
``--steps`` key steps at rest -- full-resolution slices after turning by the default step in the
x-w plane each time, what a press of ``4`` computes -- and as many held-key steps (the coarse
slices); the same steps on the same data loaded first (``ds["T"].load()``), the yardstick
"steps as fast as loaded data".  Medians per process; the table gives the median over ``--runs``
processes per version, with each run's figure.  No browser: the kernel's side of a step.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import statistics
import subprocess
import sys

from revisions import Revisions

NX, NT = 80, 60

CHILD = r"""
import json, resource, statistics, sys, time, warnings
import numpy as np
import xarray
import rot4d_widget
from rot4d_widget import Field4D, Rot4DWidget
from rot4d_widget.core.rotation import simple_rotation
path, steps = sys.argv[1], int(sys.argv[2])
out = {"file": rot4d_widget.__file__}

def stepping(field, c0):
    m = np.eye(4)
    full, held = [], []
    for k in range(steps):
        m = simple_rotation("xw", np.pi / 64) @ m
        t = time.perf_counter(); field.slice(m, c0); full.append(time.perf_counter() - t)
        t = time.perf_counter(); field.slice(m, c0, coarse=True); held.append(time.perf_counter() - t)
    return statistics.median(full), statistics.median(held)

t0 = time.perf_counter()
ds = xarray.open_dataset(path)
field = Field4D.from_xarray(ds["T"], w="time")
t1 = time.perf_counter()
w = Rot4DWidget(field)
t2 = time.perf_counter()
while not field.coarse_ready:
    time.sleep(0.01)
t3 = time.perf_counter()
c0 = w.c0
out.update(engine=str(ds["T"].encoding.get("source", "") and "netCDF4") or "scipy", open=t1 - t0,
           widget=t2 - t1, read=t3 - t2, triangles=len(w.slice.triangles))
out["full"], out["held"] = stepping(field, c0)
w.close()
loaded = Field4D.from_xarray(ds["T"].load(), w="time")
loaded.levels = field.levels
loaded.coarse()
out["loaded_full"], out["loaded_held"] = stepping(loaded, c0)
out["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print("RESULT" + json.dumps(out))
"""


def write_file(path: pathlib.Path) -> None:
    """The flame: T = 300 K unburnt to 2100 K burnt across a front 0.05 m thick, at radius R(t) =
    0.1 + 0.15 (t - 1 ms) / 3 ms m from the centre, wrinkled by 8 % with the angle; uneven times."""
    import numpy as np
    import xarray as xr

    x = np.linspace(-0.4, 0.4, NX)
    t = 1e-3 + 3e-3 * (np.arange(NT) / (NT - 1)) ** 1.5
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    r = np.sqrt(X * X + Y * Y + Z * Z)
    wrinkle = 1.0 + 0.08 * np.cos(5 * np.arctan2(Y, X)) * np.cos(4 * np.arccos(np.clip(Z / np.maximum(r, 1e-9),
                                                                                            -1, 1)))
    T = np.empty((NT, NX, NX, NX), dtype=np.float32)
    for k, tk in enumerate(t):
        R = 0.1 + 0.15 * (tk - 1e-3) / 3e-3
        T[k] = (300.0 + 1800.0 / (1.0 + np.exp((r - R * wrinkle) / 0.0125))).transpose(2, 1, 0)  # [z, y, x]
    ds = xr.Dataset({"T": (("time", "z", "y", "x"), T, {"units": "K", "long_name": "temperature"})},
                    coords={"time": ("time", t, {"units": "s"}), "z": ("z", x, {"units": "m"}),
                            "y": ("y", x, {"units": "m"}), "x": ("x", x, {"units": "m"})})
    tmp = path.with_suffix(".part")
    ds.to_netcdf(tmp, engine="scipy")
    tmp.replace(path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="main", help="the revision to compare with (default: main)")
    ap.add_argument("--runs", type=int, default=3, help="processes per version (default 3)")
    ap.add_argument("--steps", type=int, default=8, help="key steps per process (default 8)")
    ap.add_argument("--file", default=f"/tmp/rot4d-flame-{NX}-{NT}.nc")
    args = ap.parse_args()
    path = pathlib.Path(args.file)
    if not path.exists():
        print(f"writing {path} ...", file=sys.stderr)
        write_file(path)
    rows = {}
    with Revisions([args.base, None]) as revs:
        for k in range(args.runs):
            for rev in revs:
                proc = subprocess.run([sys.executable, "-c", CHILD, str(path), str(args.steps)], env=rev.env(),
                                      capture_output=True, text=True, timeout=1800)
                if proc.returncode or "RESULT" not in proc.stdout:
                    raise RuntimeError(f"{rev.label}: the child failed\n{proc.stderr[-3000:]}")
                r = json.loads(proc.stdout.split("RESULT", 1)[1].splitlines()[0])
                rev.check(r.pop("file"))
                rows.setdefault(rev.label, []).append(r)
                print(f"  {rev.label}, run {k + 1}: {r}", file=sys.stderr)
        size = path.stat().st_size / 1e6
        engine = rows[revs[0].label][0]["engine"]
        print(f"{path.name}: T[time, z, y, x] float32 {NT} x {NX}^3, {size:.0f} MB, opened by xarray's {engine} engine; "
              f"{args.steps} steps per process, {args.runs} processes per version, alternating\n")
        print("| version | widget made (first picture) s | background read s | key step at rest ms | "
              "held-key step ms | the same, data loaded first: at rest / held ms | key step / loaded | "
              "peak resident MB |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        for rev in revs:
            rs = rows[rev.label]

            def med(key, scale=1.0):
                return statistics.median(r[key] for r in rs) * scale

            def each(key, scale, fmt):
                return " (" + ", ".join(format(r[key] * scale, fmt) for r in rs) + ")"

            print(f"| {rev.label} | {med('widget'):.2f}{each('widget', 1, '.2f')} | {med('read'):.2f}"
                  f"{each('read', 1, '.2f')} | {med('full', 1e3):.0f}{each('full', 1e3, '.0f')} | "
                  f"{med('held', 1e3):.1f} | {med('loaded_full', 1e3):.0f} / {med('loaded_held', 1e3):.1f} | "
                  f"{med('full') / med('loaded_full'):.2f}x | {med('maxrss_mb'):.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
