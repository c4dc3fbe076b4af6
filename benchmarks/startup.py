"""Start-up in a new Jupyter kernel: the import, then the first widget on a 64^4 field (issue 35).

    python benchmarks/startup.py [--base REV] [--runs 3]

For each version of the package (``--base``, a git revision exported clean, and the working tree:
`benchmarks/revisions.py`), in turns, a new IPython kernel (ipykernel, started by jupyter_client as
a notebook starts one) runs one cell that times, inside the kernel:

* ``from rot4d_widget import Rot4DWidget, Field4D``;
* ``Rot4DWidget(field)`` on a 64^4 float32 array in memory (a smooth field, made before the clock
  starts): the construction, which includes the first picture the kernel slices and sends.

Each version has its own numba cache folder (``NUMBA_CACHE_DIR``, emptied at the start), so its
first kernel is "the first run ever" (numba compiles and writes its cache) and the next ``--runs``
kernels are what a user sees afterwards.  Targets (issue 35), after the first run ever: the
import <= 1 s, the first widget <= 3 s.  Medians over the runs; the machine is shared, so the
versions alternate kernel by kernel.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
import time

from revisions import Revisions

CELL = r"""
import json as _json, time as _time
import numpy as _np
_g = _np.linspace(-1.0, 1.0, 64, dtype=_np.float32)
_a = (_g[:, None, None, None] ** 2 + _g[None, :, None, None] ** 2 + _g[None, None, :, None] ** 2
      + 0.5 * _g[None, None, None, :] ** 2).astype(_np.float32)
_t0 = _time.perf_counter()
from rot4d_widget import Rot4DWidget, Field4D
_t1 = _time.perf_counter()
_field = Field4D(_a, axes="xyzw")
_w = Rot4DWidget(_field)
_t2 = _time.perf_counter()
import rot4d_widget as _r
print("RESULT" + _json.dumps({"import": _t1 - _t0, "widget": _t2 - _t1, "file": _r.__file__,
                              "triangles": int(len(_w.slice.triangles))}))
_w.close()
"""


def run_kernel(env: dict, timeout: float = 300.0) -> dict:
    """One new kernel: the cell's timings (the kernel is shut down after)."""
    from jupyter_client.manager import start_new_kernel

    km, kc = start_new_kernel(kernel_name="python3", env=env)
    try:
        out = []

        def hook(msg):
            if msg["msg_type"] == "stream":
                out.append(msg["content"]["text"])
            elif msg["msg_type"] == "error":
                out.append("\n".join(msg["content"]["traceback"]))

        reply = kc.execute_interactive(CELL, timeout=timeout, output_hook=hook)
        text = "".join(out)
        if reply["content"]["status"] != "ok" or "RESULT" not in text:
            raise RuntimeError(f"the kernel's cell failed:\n{text[-3000:]}")
        return json.loads(text.split("RESULT", 1)[1].splitlines()[0])
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="main", help="the revision to compare with (default: main)")
    ap.add_argument("--runs", type=int, default=3, help="kernels per version after the first (default 3)")
    args = ap.parse_args()
    caches = tempfile.mkdtemp(prefix="rot4d-numba-")
    try:
        with Revisions([args.base, None]) as revs:
            first, warm = {}, {r.label: [] for r in revs}
            for k in range(args.runs + 1):
                for i, rev in enumerate(revs):
                    env = rev.env(NUMBA_CACHE_DIR=f"{caches}/{i}")
                    t0 = time.perf_counter()
                    r = run_kernel(env)
                    rev.check(r["file"])
                    r["kernel"] = time.perf_counter() - t0
                    (warm[rev.label].append(r) if k else first.__setitem__(rev.label, r))
                    print(f"  {rev.label}, kernel {k}: import {r['import']:.2f} s, widget {r['widget']:.2f} s",
                          file=sys.stderr)
            print(f"Python {sys.version.split()[0]}; {args.runs} kernels per version after the first, alternating\n")
            print("| version | first run ever: import s | first run ever: first widget s | import s (median) | "
                  "first widget s (median) | import + widget s (median) | per kernel |")
            print("|---|---:|---:|---:|---:|---:|---|")
            for rev in revs:
                f, w = first[rev.label], warm[rev.label]
                med = {k: statistics.median(r[k] for r in w) for k in ("import", "widget")}
                runs = ", ".join(f"{r['import']:.2f} + {r['widget']:.2f}" for r in w)
                print(f"| {rev.label} | {f['import']:.2f} | {f['widget']:.2f} | {med['import']:.2f} | "
                      f"{med['widget']:.2f} | {med['import'] + med['widget']:.2f} | {runs} |")
    finally:
        shutil.rmtree(caches, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
