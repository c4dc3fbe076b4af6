"""Keeping what the view shows (issue 12): time and file size of meshes, pictures, animations.

    python benchmarks/keep.py [--repeats 5]

Prints a table: `export.slice_mesh` (and each mesh format's file size) for a polytope, a stack of
parallel slices and a two-level field; `state_picture.render_state` at the widget's 600 x 500 for four
sources; `animation.paper_animation` for the paper's Figs. 3 and 4 as GIF and MP4.  Medians of
``--repeats`` runs (animations: one run each).  Files go to a temporary directory.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

import numpy as np

from rot4d_widget import Field4D, RotationState
from rot4d_widget.keep.meshes import slice_mesh
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.keep.animation import paper_animation
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.sources.tomography import StackSource


def median_ms(f, n):
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return 1e3 * statistics.median(ts)


def ball(x, y, z, w):
    return 1.0 - (x * x + y * y + z * z) - 0.3 * w


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    out = tempfile.mkdtemp(prefix="rot4d-keep-")
    m = random_rotation(np.random.default_rng(3))
    field = Field4D.from_function(ball, [(-1.2, 1.2)] * 3 + [(-1.0, 1.0)], levels=(0.3, 0.6))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; medians of {args.repeats}")
    print("| slice_mesh of | ms | vertices | faces | PLY KB | OBJ KB | STL KB | GLB KB |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    cases = {
        "600-cell": PolytopeSource("600-cell").slice(m, 0.1),
        "24-cell, 12 slices, oval": StackSource("24-cell", slices=12, spacing=0.3).slice(m, 0.0),
        "field, 64 samples, 2 levels": field.slice(m, 0.1),
    }
    for name, data in cases.items():
        ms = median_ms(lambda: slice_mesh(data), args.repeats)
        mesh = slice_mesh(data)
        sizes = []
        for ext in ("ply", "obj", "stl", "glb"):
            path = os.path.join(out, f"mesh.{ext}")
            mesh.export(path)
            sizes.append(os.path.getsize(path) / 1024)
        print(f"| {name} | {ms:.1f} | {len(mesh.vertices)} | {len(mesh.faces)} | "
              + " | ".join(f"{s:.0f}" for s in sizes) + " |")
    print()
    print("| render_state, 600 x 500 PNG | ms | KB |")
    print("|---|---:|---:|")
    st = RotationState(matrix=m, c0=0.1)
    png = os.path.join(out, "view.png")
    for name, src, kw in (("24-cell", "24-cell", {}), ("600-cell", "600-cell", {}), ("field, 2 levels", field, {}),
                          ("24-cell, 12 slices, oval", "24-cell", {"slices": 12, "spacing": 0.3})):
        ms = median_ms(lambda: render_state(st, src, png, **kw), max(1, min(3, args.repeats)))
        print(f"| {name} | {ms:.0f} | {os.path.getsize(png) / 1024:.0f} |")
    print()
    print("| paper_animation | frames | s | KB |")
    print("|---|---:|---:|---:|")
    for fig, ext in ((3, "gif"), (4, "gif"), (3, "mp4"), (4, "mp4")):
        path = os.path.join(out, f"fig{fig}.{ext}")
        t = time.perf_counter()
        n = paper_animation(fig, path)
        print(f"| Fig. {fig} .{ext} (400 x 400 + title) | {n} | {time.perf_counter() - t:.1f} | "
              f"{os.path.getsize(path) / 1024:.0f} |")
    print(f"\nfiles in {out}")


if __name__ == "__main__":
    main()
