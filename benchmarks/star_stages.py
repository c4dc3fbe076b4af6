"""Where the compiled star level's time goes, stage by stage (issue 22's great icosahedral 120-cell).

Compiles ``rot4d_widget/geometry/_starcut.c`` once more with ``-DSTARCUT_TIMING`` (clock marks
between its stages, summed in ``starcut_times``) into a temporary folder, loads that build in
place of the package's, and cuts each polychoron at ``--steps`` random orientations (the
orientations of benchmarks/star_load.py, c0 = 0.1), ``--repeats`` times over.  Prints, per
slice, the ms of each stage and the whole call (timed from Python, the clock marks included),
and how many cells a slice fills by arrangement and how many the arrangement leaves to the slabs.

Stages: the edges' crossing points; the faces' pairing and the volume; the cycles; the fans from
centroids of star-shaped sections; the arrangement fill, split into its pair tests, the crossings
ordered along each segment, the parity (a ray per cycle), the next-piece pointers, the output of
the crossings as fill corners ("arr: output") and the faces' walk with their fans ("arr: faces");
the slab fill.  The timing build runs on one thread (the package's may split a level's fills
between two: see _cstar.THREADS), with the package's memory pool.  The marks cost a few percent:
compare stages, not the total with star_load.py's.

    python benchmarks/star_stages.py [--names "great icosahedral 120-cell,..."] [--steps 20] [--repeats 10]
"""

from __future__ import annotations

import argparse
import ctypes
import hashlib
import pathlib
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time

import numpy as np

from rot4d_widget import polytope
from rot4d_widget.geometry import _cstar, starslice
from rot4d_widget.geometry.slicetables import tables

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from star_load import rotations  # noqa: E402

SOURCE = pathlib.Path(_cstar.__file__).with_name("_starcut.c")
STAGES = ["edges", "faces", "cycles", "fans", "arr: pairs", "arr: order", "arr: parity", "arr: next",
          "arr: faces", "arr: output", "slabs"]
DEFAULT = ("small stellated 120-cell,great 120-cell,great stellated 120-cell,grand stellated 120-cell,"
           "great grand 120-cell,great icosahedral 120-cell")


def timing_build(folder: pathlib.Path):
    """The timing build of _starcut.c in ``folder`` (beside a copy of its source), loaded."""
    shutil.copy(SOURCE, folder / SOURCE.name)
    sha = hashlib.sha256(SOURCE.read_bytes()).hexdigest()
    cc = shlex.split(sysconfig.get_config_var("CC") or "cc")
    subprocess.run([*cc, "-O3", "-ffp-contract=off", "-shared", "-fPIC", "-DSTARCUT_TIMING", f'-DSTARCUT_SOURCE="{sha}"',
                    "-o", str(folder / _cstar.LIBRARY), str(SOURCE), "-lm"], check=True)
    lib = _cstar._load(folder)
    if lib is None:
        raise SystemExit("the timing build did not load")
    return lib


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--names", default=DEFAULT)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=10)
    args = ap.parse_args()
    if not _cstar.available:
        raise SystemExit("the compiled level is not built here (no C compiler at install)")
    mats = rotations(args.steps)
    with tempfile.TemporaryDirectory() as tmp:
        lib = timing_build(pathlib.Path(tmp))
        times = (ctypes.c_double * 16).in_dll(lib, "starcut_times")
        counts = (ctypes.c_long * 4).in_dll(lib, "starcut_counts")
        keep, _cstar._lib = _cstar._lib, lib
        try:
            rows = []
            for name in args.names.split(","):
                p = polytope(name.strip())
                t = tables(p)
                st = starslice.star_tables(p, t)
                xs = [t.vertices @ m.T for m in mats]
                _cstar.cut(st.c, xs[0], mats[0], 0.1, t.tol)  # warm
                for k in range(16):
                    times[k] = 0.0
                for k in range(4):
                    counts[k] = 0
                n, whole = 0, 0.0
                for _ in range(args.repeats):
                    for x, m in zip(xs, mats):
                        a = time.perf_counter()
                        _cstar.cut(st.c, x, m, 0.1, t.tol)
                        whole += time.perf_counter() - a
                        n += 1
                rows.append((name.strip(), [1e3 * times[k] / n for k in range(len(STAGES))], 1e3 * whole / n,
                             counts[1] / n, (counts[0] - counts[1]) / n))
        finally:
            _cstar._lib = keep
    print(f"ms per slice, {args.steps} orientations x {args.repeats}, c0 = 0.1, timing build of _starcut.c")
    print("| polychoron | " + " | ".join(STAGES) + " | whole call | cells by arrangement, by slabs |")
    print("|---|" + "---:|" * (len(STAGES) + 2))
    for name, st_ms, whole, arr, slab in rows:
        print(f"| {name} | " + " | ".join(f"{v:.3f}" for v in st_ms) + f" | {whole:.3f} | {arr:.1f}, {slab:.1f} |")


if __name__ == "__main__":
    main()
