"""What a frame costs the page when it cuts the polytope itself (issue 34): ``page/slicer.js``
``slicePolytope`` and ``page/rows.js`` ``sliceRows`` under Node (the V8 engine of Chromium), next to
the kernel's `slice_polytope` and `slice_rows` on the same orientations and levels.

For each polytope, ``--slices`` random orientations, each at a random level within 0.8 of its
circumradius; the page's arrays are the kernel's (tests/page/test_page_slicer.py), so only time is
measured here.  Printed: milliseconds per slice, the median of ``--repeats`` passes over all the
slices (the first pass, before V8 optimises the code, in brackets), and the rows built from each
slice seen from an eye (the sort for blending included); the message's size sent once.

    python benchmarks/page_slice.py [--slices 50] [--repeats 5] [--seed 0]
"""

from __future__ import annotations

import argparse
import base64
import pathlib
import statistics
import sys
import time

import numpy as np

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.view.buffers import group_palette, pack_rgb, slice_rows
from rot4d_widget.view.pagegeometry import polytope_message, polytope_message_bytes

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from page_node import run_page  # noqa: E402  (runs the page's modules under Node)

NAMES = ["24-cell", "120-cell", "600-cell", "grand antiprism", "omnitruncated 120-cell"]
EYE = [0.0, 0.0, 5.0]

SCRIPT = """
import { decodePolytope, sliceData } from "page:slicer.js";
import { sliceRows } from "page:rows.js";
const out = INPUT.runs.map((c) => {
  const msg = { ...c.msg };
  for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
  const p = decodePolytope(msg);
  const slice = [], rows = [];
  for (let rep = 0; rep < INPUT.repeats; rep++) {
    let ts = 0, tr = 0;
    for (const [m, c0] of c.cases) {
      const t0 = performance.now();
      const d = sliceData(p, m, c0);
      const t1 = performance.now();
      sliceRows(d, { scale: c.scale, palette: c.palette, eye: INPUT.eye });
      ts += t1 - t0;
      tr += performance.now() - t1;
    }
    slice.push(ts / c.cases.length);
    rows.push(tr / c.cases.length);
  }
  return { slice, rows };
});
console.log(JSON.stringify(out));
"""


def _wire(p) -> dict:
    msg = polytope_message(p)
    binary = [k for k, v in msg.items() if isinstance(v, memoryview)]
    return {"msg": {k: base64.b64encode(bytes(v)).decode() if k in binary else v for k, v in msg.items()},
            "binary": binary}


def _python(p, cases, repeats, scale, palette):
    src = PolytopeSource(p)
    slice_ms, rows_ms = [], []
    for _ in range(repeats):
        ts = tr = 0.0
        for m, c0 in cases:
            t0 = time.perf_counter()
            slice_polytope(p, m, c0)
            t1 = time.perf_counter()
            d = src.slice(m, c0)
            t2 = time.perf_counter()
            slice_rows(d, scale=scale, group_rgb=palette, eye=EYE)
            ts += t1 - t0
            tr += time.perf_counter() - t2
        slice_ms.append(1e3 * ts / len(cases))
        rows_ms.append(1e3 * tr / len(cases))
    return slice_ms, rows_ms


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--slices", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    runs, table = [], []
    for name in NAMES:
        p = polytope(name)
        cases = [(random_rotation(rng), float(rng.uniform(-0.8, 0.8) * p.circumradius)) for _ in range(args.slices)]
        scale = 1.0 / p.circumradius
        palette = group_palette(max(1, len(p.cells)))
        runs.append({**_wire(p), "cases": [(m.reshape(-1).tolist(), c0) for m, c0 in cases], "scale": scale,
                     "palette": pack_rgb(palette).tolist()})
        table.append((p, _python(p, cases, args.repeats, scale, palette)))
    page = run_page(SCRIPT, {"runs": runs, "repeats": args.repeats, "eye": EYE})
    print(f"ms per slice, median of {args.repeats} passes over {args.slices} slices (first pass in brackets)")
    print(f"{'polytope':<24} {'message':>9} {'page slice':>16} {'page rows':>14} {'kernel slice':>13} "
          f"{'kernel rows':>12}")
    for (p, (py_slice, py_rows)), got in zip(table, page):
        mb = polytope_message_bytes(polytope_message(p)) / 1e6
        js_slice, js_rows = got["slice"], got["rows"]
        print(f"{p.name:<24} {mb:>7.2f}MB {statistics.median(js_slice):>7.2f} ({js_slice[0]:>6.2f}) "
              f"{statistics.median(js_rows):>6.2f} ({js_rows[0]:>5.2f}) {statistics.median(py_slice):>13.2f} "
              f"{statistics.median(py_rows):>12.2f}")


if __name__ == "__main__":
    main()
