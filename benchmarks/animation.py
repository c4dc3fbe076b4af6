"""render_animation, before and after "Keeping it": the same 33-frame recordings, old and new code, one run.

A held "4" (32 steps of R_xw, 33 frames, 600 x 500) on the 24-cell and on the moving sphere
(`rot4d_widget.sources.datasets.moving_sphere()`, a Field4D), each to GIF and MP4.  The old code is
the package at commit 7ba6e62, checked out with ``git worktree add /tmp/old-anim 7ba6e62``
(``--old`` elsewhere); the new is this checkout.  Each side runs in its own Python process
(PYTHONPATH set to its tree), imports and draws one small warm-up animation first, then times
``--repeats`` renders of every case; old and new alternate case by case so that the load of the
machine falls on both alike.  Prints a table of medians (seconds) and the speed-up.

``--parts`` adds, for the new code, where each render's time went (medians, seconds): slicing
(the framing pass's ``state_picture.prepare_render``, every frame's slice), building the frame's artists
(``render_state``), Agg drawing them (``FrameCanvas.rgba``), the encoder's work after the last
frame (``_Encoder.finish``: x264's lookahead, the GIF's last frames) and the rest.

    python benchmarks/animation.py [--repeats 3] [--old /tmp/old-anim] [--parts]

``--rev REV`` (issue 37) instead times a field's ray-cast animations on the code of git revision REV
(a clean ``git archive``, `benchmarks/revisions.py`) and on the working tree, in one run: a
flame-like T(x, y, z, t) in K, 80^3 x 60 steps over 1-4 ms on 0.01-0.05 m (float32, made once and
handed to every child as an .npy file), 8 taps of "4" (9 frames, a turn into time) drawn as a
600 x 500 GIF in each rendering.  "Same resolution": one ray through every pixel, REV's own
``render_grid`` given ``pixels_per_ray=1`` by the benchmark (its default cast a ray every few
pixels and interpolated between them); REV's default is timed too.

    python benchmarks/animation.py --rev 2a6f126 --repeats 2 [--new 349e157]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

CASES = [("24-cell", ".gif"), ("24-cell", ".mp4"), ("field", ".gif"), ("field", ".mp4")]


def _recording():
    from rot4d_widget.keep.recorder import Recorder
    from rot4d_widget.core.state import RotationState

    st = RotationState()
    rec = Recorder(st, clock=lambda: 0.0)
    action, inverted = st.keymap.resolve("4")
    for k in range(1, 33):  # a held key: 32 repeats at 30 Hz
        rec.record("4", False, action, inverted, t=k / 30)
    return rec.recording()


PARTS = ("slicing", "building", "drawing", "encoder tail")


def _timed(owner, name, part, spent, when=lambda args, kwargs: True):
    """Wrap ``owner.name`` so that its seconds add up in ``spent[part]`` (when ``when`` says so)."""
    real = getattr(owner, name)

    def timed(*args, **kwargs):
        if not when(args, kwargs):
            return real(*args, **kwargs)
        t = time.perf_counter()
        try:
            return real(*args, **kwargs)
        finally:
            spent[part] += time.perf_counter() - t

    setattr(owner, name, timed)


def _time_parts(spent: dict) -> None:
    """Time the parts of the new code's render_animation (see --parts)."""
    from rot4d_widget.keep import animation
    from rot4d_widget.keep.pictures import canvas, state_picture

    _timed(state_picture, "prepare_render", "slicing", spent, lambda args, kwargs: kwargs.get("data") is None)
    _timed(state_picture, "render_state", "building", spent)
    _timed(canvas.FrameCanvas, "rgba", "drawing", spent)
    _timed(animation._Encoder, "finish", "encoder tail", spent)


def worker(case: str, ext: str, repeats: int, new: bool, parts: bool = False) -> list:
    """Seconds of each of ``repeats`` renders of one case, in this process (with ``parts``: a dict
    per render, its total and `PARTS`)."""
    import inspect

    from rot4d_widget.sources import datasets
    from rot4d_widget.keep.animation import render_animation

    quiet = {"progress": False} if "progress" in inspect.signature(render_animation).parameters else {}
    rec = _recording()
    source = datasets.moving_sphere() if case == "field" else case
    spent = dict.fromkeys(PARTS, 0.0)
    if parts:
        _time_parts(spent)
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        render_animation(rec, None, "5-cell", os.path.join(tmp, "warm" + ext), size=(80, 60), max_frames=40,
                         **quiet)
        for r in range(repeats):
            spent.update(dict.fromkeys(PARTS, 0.0))
            t = time.perf_counter()
            n = render_animation(rec, None, source, os.path.join(tmp, f"a{r}{ext}"), fps=10, **quiet)
            total = time.perf_counter() - t
            times.append({"total": total, **spent} if parts else total)
            assert n == 33, n
    return times


FLAME_RENDERINGS = ("surface", "volume", "mip", "sections")


def _flame(path: str) -> None:
    """The flame-like field's values, T[t, z, y, x] float32 in K, saved to ``path`` (.npy)."""
    import numpy as np

    n, nt = 80, 60
    x = np.linspace(0.01, 0.05, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    out = np.empty((nt, n, n, n), np.float32)
    for k, tk in enumerate(np.linspace(0.001, 0.004, nt)):
        r0 = 0.004 + 0.012 * (tk - 0.001) / 0.003
        r = np.sqrt((X - 0.03) ** 2 + (Y - 0.03) ** 2 + (Z - 0.02 - 5 * tk) ** 2)
        out[k] = (300 + 1700 / (1 + np.exp((r - r0) / 0.0015))).transpose(2, 1, 0)
    np.save(path, out)


def flame_worker(npy: str, rendering: str, repeats: int, per_pixel: bool) -> dict:
    """Seconds of each of ``repeats`` GIFs of the flame's 9 frames in ``rendering``, this process's
    package; ``per_pixel``: its render_grid made to cast one ray per pixel (what an older default
    interpolated)."""
    import functools

    import numpy as np

    import rot4d_widget
    from rot4d_widget.core.state import RotationState
    from rot4d_widget.keep.pictures import ray_caster
    from rot4d_widget.keep.recorder import Recorder
    from rot4d_widget.keep.animation import render_animation
    from rot4d_widget.sources.field.container import Field4D

    if per_pixel:
        ray_caster.render_grid = functools.partial(ray_caster.render_grid, pixels_per_ray=1)
    ext = (0.01, 0.05)
    field = Field4D(np.load(npy), axes="wzyx", extent=(ext, ext, ext, (0.001, 0.004)), name="T", units="K",
                    space_units="m", w_units="s", w_per_unit=3e-3 / 59 / (0.04 / 79))
    st = RotationState(c0=0.0025, c0_step=1e-4)
    rec = Recorder(st, clock=lambda: 0.0)
    action, inverted = st.keymap.resolve("4")
    for k in range(1, 9):
        rec.record("4", False, action, inverted, t=k / 10)
    recording = rec.recording()
    import tempfile

    times = []
    with tempfile.TemporaryDirectory() as tmp:
        render_animation(recording, None, field, os.path.join(tmp, "warm.gif"), size=(120, 100), max_frames=40,
                         rendering=rendering, progress=False)  # numba's kernels loaded, caches warm
        for r in range(repeats):
            t = time.perf_counter()
            n = render_animation(recording, None, field, os.path.join(tmp, f"a{r}.gif"), fps=10,
                                 rendering=rendering, progress=False)
            times.append(time.perf_counter() - t)
            assert n == 9, n
    return {"times": times, "package": rot4d_widget.__file__}


def flame_main(rev: str, repeats: int, new_rev=None) -> None:
    from revisions import Revisions

    rows = []
    with tempfile.TemporaryDirectory() as tmp, Revisions([rev, new_rev]) as (old, new):
        npy = os.path.join(tmp, "flame.npy")
        _flame(npy)
        for rendering in FLAME_RENDERINGS:
            got = {}
            for label, revision, per_pixel in (("old, one ray per pixel", old, True), ("old, its default", old, False),
                                               ("new", new, False)):
                if rendering == "surface" and label == "old, its default":
                    continue  # no rays to cast: the same as the row above
                out = subprocess.run([sys.executable, os.path.abspath(__file__), "--flame-worker", npy, rendering,
                                      str(repeats), "1" if per_pixel else "0"],
                                     env=revision.env(), capture_output=True, text=True, check=True)
                res = json.loads(out.stdout.strip().splitlines()[-1])
                revision.check(res["package"])
                got[label] = statistics.median(res["times"])
                print(f"  {rendering} {label}: {res['times']}", file=sys.stderr)
            rows.append((rendering, got))
    print(f"render_animation of the flame (80^3 x 60 float32), 9 frames 600 x 500 GIF, median of {repeats} (s); "
          f"old = {old.label}, new = {new.label}; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| rendering | old, one ray per pixel | old, its default | new (one ray per pixel) | speed-up at the same "
          "resolution |")
    print("|---|---:|---:|---:|---:|")
    for rendering, got in rows:
        same = got["old, one ray per pixel"]
        dflt = got.get("old, its default")
        print(f"| {rendering} | {same:.2f} | {'—' if dflt is None else f'{dflt:.2f}'} | {got['new']:.2f} | "
              f"{same / got['new']:.1f}x |")


def _run(tree: str, case: str, ext: str, repeats: int, parts: bool = False) -> list:
    env = {**os.environ, "PYTHONPATH": tree}
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--worker", case, ext, str(repeats)]
                         + (["--parts"] if parts else []),
                         env=env, cwd=tree, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--old", default="/tmp/old-anim", help="a checkout of 7ba6e62 (git worktree add ... 7ba6e62)")
    p.add_argument("--parts", action="store_true", help="also time the new code's slicing, building, drawing, "
                   "encoder tail")
    p.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    p.add_argument("--rev", help="time the flame's ray-cast animations on this git revision and the working tree")
    p.add_argument("--new", help="with --rev: this git revision instead of the working tree")
    p.add_argument("--flame-worker", nargs=4, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.flame_worker:
        npy, rendering, repeats, per_pixel = a.flame_worker
        print(json.dumps(flame_worker(npy, rendering, int(repeats), per_pixel == "1")))
        return
    if a.rev:
        flame_main(a.rev, a.repeats, a.new)
        return
    if a.worker:
        case, ext, repeats = a.worker
        print(json.dumps(worker(case, ext, int(repeats), new=True, parts=a.parts)))
        return
    new_tree = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if not os.path.isdir(os.path.join(a.old, "rot4d_widget")):
        sys.exit(f"No old checkout at {a.old}: git worktree add {a.old} 7ba6e62")
    rows, split = [], []
    for case, ext in CASES:
        old = _run(a.old, case, ext, a.repeats)
        new = _run(new_tree, case, ext, a.repeats, a.parts)
        if a.parts:
            split.append((case, ext, {k: statistics.median(r[k] for r in new) for k in ("total", *PARTS)}))
            new = [r["total"] for r in new]
        rows.append((case, ext, statistics.median(old), statistics.median(new)))
        print(f"  {case} {ext}: old {old}, new {new}", file=sys.stderr)
    print(f"render_animation, 33 frames 600 x 500, median of {a.repeats} (s); load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| source | file | old 7ba6e62 | new | speed-up |")
    print("|---|---|---:|---:|---:|")
    for case, ext, o, n in rows:
        name = "24-cell" if case == "24-cell" else "moving_sphere() field"
        print(f"| {name} | {ext} | {o:.2f} | {n:.2f} | {o / n:.1f}x |")
    if split:
        print("\nwhere the new code's time went (medians, s; the parts are timed in the same renders)")
        print("| source | file | total | " + " | ".join(PARTS) + " | rest |")
        print("|---|---|" + "---:|" * (len(PARTS) + 2))
        for case, ext, m in split:
            name = "24-cell" if case == "24-cell" else "moving_sphere() field"
            rest = m["total"] - sum(m[k] for k in PARTS)
            print(f"| {name} | {ext} | {m['total']:.2f} | " + " | ".join(f"{m[k]:.2f}" for k in PARTS)
                  + f" | {rest:.2f} |")


if __name__ == "__main__":
    main()
