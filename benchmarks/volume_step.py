"""The kernel's held-key step of a 64^4 field: ray-cast renderings (volume, mip) against the coarse isosurface.

Issue 21's kernel target: the held-key step for ``rendering="volume"`` no slower than today's
coarse isosurface step, on the same field in the same run.

The field (`blob64`): a Gaussian blob that travels along x as w grows, on a 64^4 float32 array,
``Field4D(a, axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.5])`` (resolution 64, coarse 32 by
default: the coarse copy is 32^4 and a held step samples a 32-node grid).  The same array is the
browser benchmark's ``blob64-*`` cases (benchmarks/browser_latency.py).

What one held step does in the kernel (the painter, rot4d_widget/view/painter.py, while a key is
held, ``coarse=True``), timed in parts for ``--orientations`` random orientations (seed 0),
c0 = 0.1, each part's time the best of ``--repeats``; the table shows the median over orientations:

surface (today's coarse isosurface step)
    slice     ``checked_slice(field, m, c0, coarse=True)`` = ``field.slice(m, c0, coarse=True)`` +
              the protocol check (coarse resampling, marching cubes per level, the box's bars)
    show      ``scene.show(data)``: rows, the quantised surface message, serialised to the comm
volume / mip (the ``elif cast:`` branch)
    slice     ``grid_cut(field, m, c0, coarse=True, lock, scale)`` (``field.sample(..., coarse=True)``:
              the coarse grid, NaN outside the box, the box's bars, readout rows)
    clim      ``default_clim(cut.finite_values)`` (the widget's ``clim`` is None: 1st-99th percentile)
    message   ``volume_message(cut.parts, rendering, cmap, clim, sections)`` (quantise, atlas tiles,
              the colour map's table)
    show      ``scene.show(cut.data, volume=message)``, serialised to the comm

``show`` is timed once per orientation (not best of): shown again, an equal message is not re-sent.

``whole`` is the sum; ``widget`` is the same step measured end to end through a real
``Rot4DWidget(field, rendering=...)`` per rendering (a "4" keydown reaching the ipyevents model's
comm handler -> the update handed to the comm, the widget's own coarse held step; the page's
"drawn" ack given between steps), median over ``--presses`` presses at random orientations.
The renderings take turns at each orientation, in random order (the shared machine's load
drifts), and "÷ surface" is the median over orientations of the step's time over the surface
step's at the same orientation.  ``bytes``:
the update's messages as tests/recording_comm.py sizes them (JSON + binary buffers, as ipykernel
sends them); ``atlas`` the atlas's share.

    python benchmarks/volume_step.py [--orientations 30] [--repeats 3] [--presses 60] [--n 64]
        [--coarse-resolution 32] [--profile]

``--profile`` ends with cProfile's top functions of 100 volume steps (the parts above).
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import threading
import time
from functools import partial

import numpy as np

from rot4d_widget import Field4D
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.core.colours import default_clim
from rot4d_widget.view.cuts import grid_cut
from rot4d_widget.view.painter import checked_slice
from rot4d_widget.view.volume_layer import volume_message

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from field_step import best  # noqa: E402  (benchmarks/ is on the path when run as a script)
from recording_comm import RecordingComm, install  # noqa: E402  (serialises like ipykernel)

C0 = 0.1


def blob_array(n: int = 64) -> np.ndarray:
    """(n, n, n, n) float32, f[x, y, z, w]: exp(-|(x, y, z) - (0.6 w, 0, 0)|^2 / 0.18) on [-1, 1]^4."""
    g = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    yz = g[None, :, None] ** 2 + g[None, None, :] ** 2
    a = np.empty((n,) * 4, dtype=np.float32)
    for i, w in enumerate(g):
        a[..., i] = np.exp(-((g[:, None, None] - 0.6 * w) ** 2 + yz) / 0.18)
    return a


def blob_field(n: int = 64, coarse_resolution=None) -> Field4D:
    kw = {} if coarse_resolution is None else {"coarse_resolution": coarse_resolution}
    return Field4D(blob_array(n), axes="xyzw", extent=[(-1.0, 1.0)] * 4, levels=[0.5], name="blob", **kw)


def comm_bytes(n0: int) -> tuple[int, int]:
    """(bytes, messages) the comms recorded since log index ``n0``."""
    log = RecordingComm.log[n0:]
    return sum(n for _, _, n, _ in log), len(log)


RENDERINGS = ("surface", "volume", "mip")


def one_step(field, scene, rendering: str, m, repeats: int, lock) -> dict:
    """Each part's best time (s) of one held step at orientation ``m``, its bytes and grid."""
    r = {}
    if rendering == "surface":
        data, r["slice"] = best(partial(checked_slice, field, m, C0, True, lock), repeats)
        r["clim"] = r["message"] = 0.0
        n0 = len(RecordingComm.log)
        _, r["show"] = best(partial(scene.show, data, force=True), 1)  # once: a repeat would send less
        r["bytes"], r["msgs"] = comm_bytes(n0)
        r["atlas"] = 0
        r["grid"] = f"{field.coarse_resolution} (longest side)"
    else:
        cut, r["slice"] = best(partial(grid_cut, field, m, C0, True, lock, 1.0), repeats)
        clim, r["clim"] = best(partial(default_clim, cut.finite_values), repeats)
        msg, r["message"] = best(partial(volume_message, cut.parts, rendering, "viridis", clim, (0.5, 0.5, 0.5)),
                                 repeats)
        n0 = len(RecordingComm.log)
        _, r["show"] = best(partial(scene.show, cut.data, volume=msg, force=True), 1)  # once (as above)
        r["bytes"], r["msgs"] = comm_bytes(n0)
        r["atlas"] = len(msg["atlas"]) if msg else 0
        r["grid"] = "×".join(str(s) for s in cut.grids[0].values.shape)
    r["whole"] = r["slice"] + r["clim"] + r["message"] + r["show"]
    return r


def parts(field, scene, orientations, repeats: int, rng) -> dict:
    """Per rendering: the median over orientations of each part (`one_step`); the renderings take
    turns at each orientation, in random order (the machine's load drifts)."""
    lock = threading.RLock()
    rows = {r: [] for r in RENDERINGS}
    for m in orientations:
        for r in rng.permutation(RENDERINGS):
            rows[str(r)].append(one_step(field, scene, str(r), m, repeats, lock))
    out = {}
    for r, rs in rows.items():
        out[r] = {k: statistics.median(x[k] for x in rs) for k in rs[0] if k != "grid"}
        out[r]["grid"] = statistics.mode(x["grid"] for x in rs)
        out[r]["ratio"] = statistics.median(x["whole"] / y["whole"] for x, y in zip(rs, rows["surface"]))
    return out


def key_msg(kind, t):
    event = {"type": kind, "event": kind, "key": "4", "code": "Digit4", "shiftKey": False, "altKey": False,
             "ctrlKey": False, "metaKey": False, "repeat": False, "timeStamp": t, "location": 0, "target": {}}
    return {"content": {"data": {"method": "custom", "content": event}}, "buffers": []}


def drawn_msg(seq):
    return {"content": {"data": {"method": "custom", "content": {"event": "drawn", "seq": seq}}}, "buffers": []}


def widget_steps(field, orientations, rng) -> dict:
    """Real widgets' held step, one per rendering, taking turns in random order at each orientation:
    keydown '4' -> update handed to the comm (coarse: the key is held); then keyup and the ack."""
    from rot4d_widget.view.widget import Rot4DWidget

    ws = {r: Rot4DWidget(field, rendering=r, _autotick=False) for r in RENDERINGS}
    times, sizes = {r: [] for r in RENDERINGS}, {r: [] for r in RENDERINGS}
    try:
        for i, m in enumerate(orientations):
            for r in map(str, rng.permutation(RENDERINGS)):
                w = ws[r]
                handler, companion = w.events.comm.handler, w.companion.comm.handler
                w.state.matrix = m
                companion(drawn_msg(w.scene.update_id))
                updates = w.stats.updates
                n0 = len(RecordingComm.log)
                t0 = time.perf_counter()
                handler(key_msg("keydown", float(i)))
                t1 = time.perf_counter()
                b, _ = comm_bytes(n0)
                held = w._painter.shown.coarse if w._painter.shown is not None else None
                handler(key_msg("keyup", float(i)))
                companion(drawn_msg(w.scene.update_id))
                if i < 5:
                    continue
                if w.stats.updates == updates:
                    raise RuntimeError(f"{r}: a keydown sent no update")
                if held is False:
                    raise RuntimeError(f"{r}: the keydown's step was not the coarse (held) one")
                times[r].append(t1 - t0)
                sizes[r].append(b)
    finally:
        for w in ws.values():
            w.close()
    return {r: {"ms": 1e3 * statistics.median(times[r]), "p90": 1e3 * float(np.percentile(times[r], 90)),
                "bytes": statistics.median(sizes[r]),
                "ratio": statistics.median(a / b for a, b in zip(times[r], times["surface"]))} for r in RENDERINGS}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--orientations", type=int, default=30)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--presses", type=int, default=60, help="keydowns per rendering through a real widget")
    ap.add_argument("--n", type=int, default=64, help="nodes per axis of the 4-D array (default 64)")
    ap.add_argument("--coarse-resolution", type=int, default=None, help="the field's coarse_resolution "
                    "(default: the field's own, 32 for resolution 64)")
    ap.add_argument("--profile", action="store_true", help="cProfile 100 volume steps, top functions")
    args = ap.parse_args(argv)
    install()

    import rot4d_widget

    print(f"rot4d_widget from {pathlib.Path(rot4d_widget.__file__).parent}")
    field = blob_field(args.n, args.coarse_resolution)
    t0 = time.perf_counter()
    field.coarse()
    t_coarse = time.perf_counter() - t0
    rng = np.random.default_rng(0)
    orientations = [random_rotation(rng) for _ in range(args.orientations)]
    from rot4d_widget.view.widget import Rot4DWidget

    holder = Rot4DWidget(field, _autotick=False)  # its scene: the layers a widget has, on a recording comm
    scene = holder.scene
    lock = threading.RLock()
    checked_slice(field, orientations[0], C0, True, lock)  # compile (or load) the kernels outside the timing
    grid_cut(field, orientations[0], C0, True, lock, 1.0)
    res = parts(field, scene, orientations, args.repeats, np.random.default_rng(2))
    holder.close()
    wrng = np.random.default_rng(1)
    worient = [random_rotation(wrng) for _ in range(args.presses + 5)]
    wid = widget_steps(field, worient, np.random.default_rng(3))

    print(f"Field: blob {args.n}^4 float32, resolution {field.resolution}, coarse_resolution "
          f"{field.coarse_resolution} (coarse copy {'x'.join(map(str, field.coarse().values.shape))}, "
          f"built once in {t_coarse:.2f} s, outside the timing); c0 = {C0}; {args.orientations} orientations "
          f"(seed 0), best of {args.repeats}, median over orientations.\n")
    print("| held step (coarse) | grid | slice / sample ms | clim ms | message ms | scene.show + comm ms "
          "| whole ms | ÷ surface | widget keydown→comm ms, median (p90) | ÷ surface | bytes/update (atlas) "
          "| widget bytes/keydown |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in RENDERINGS:
        x, wx = res[r], wid[r]
        print(f"| {r} | {x['grid']} | {1e3 * x['slice']:.2f} | {1e3 * x['clim']:.2f} | {1e3 * x['message']:.2f} "
              f"| {1e3 * x['show']:.2f} | {1e3 * x['whole']:.2f} | {x['ratio']:.2f} "
              f"| {wx['ms']:.2f} ({wx['p90']:.2f}) | {wx['ratio']:.2f} "
              f"| {x['bytes'] / 1024:.1f} KiB ({x['atlas'] / 1024:.1f} KiB) | {wx['bytes'] / 1024:.1f} KiB |")
    ok = res["volume"]["ratio"] <= 1.0 and wid["volume"]["ratio"] <= 1.0
    print("\n÷ surface: the median over orientations of the step's time over the surface step's at the same "
          "orientation (they take turns, in random order).")
    print(f"\nTarget (issue 21): volume's held step no slower than the coarse isosurface step: "
          f"{'met' if ok else 'NOT MET'} (parts {res['volume']['ratio']:.2f}x, widget {wid['volume']['ratio']:.2f}x)")
    if args.profile:
        import cProfile
        import pstats

        holder = Rot4DWidget(field, _autotick=False)
        scene = holder.scene

        def steps():
            for k in range(100):
                m = orientations[k % len(orientations)]
                cut = grid_cut(field, m, C0, True, lock, 1.0)
                clim = default_clim(cut.finite_values)
                msg = volume_message(cut.parts, "volume", "viridis", clim, (0.5, 0.5, 0.5))
                scene.show(cut.data, volume=msg, force=True)

        pr = cProfile.Profile()
        pr.runcall(steps)
        holder.close()
        print("\ncProfile, 100 volume steps (the parts above), by cumulative time:")
        pstats.Stats(pr).sort_stats("cumulative").print_stats(25)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
