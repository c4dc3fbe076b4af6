"""Kernel-side cost of one key press in Rot4DWidget, per regular polychoron.

For each polytope: the time from the event dict arriving at the ipyevents
model's comm handler to the last message of the update being handed to the
comm (keymap lookup, state step, slice, buffers, scene assignment, readout,
JSON + buffer serialisation as ipykernel's comm does it), median and 90th
percentile over many presses at random orientations; and the messages and
total bytes (JSON + binary buffers) one update sends, as recorded by the comm
of tests/recording_comm.py (it serialises like ipykernel; the widget itself
counts nothing).  Each update is acknowledged the way the page does it, by a
"drawn" message from the companion, so the next press goes out at once.
The update is what the keydown sends: while a key is down the readout changes
at most every 0.25 s (rot4d_widget.view.widget.READOUT_PERIOD), so presses this
close together send the buffer alone, and the readout follows at rest.

    python benchmarks/widget_update.py [--presses 300] [--seed 0] [--star]

Targets (issue 3): <= 2 ms for the 120-cell and 600-cell, <= 64 KB per update.  ``--star`` adds
the ten regular star polychora (issue 22) after the six convex ones, reported against no target:
the great icosahedral 120-cell's slice has some 40 times the 600-cell's triangles (the even-odd
fill of star sections; this benchmark's last-slice column), and an update's bytes grow with them.
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np
from scipy.stats import special_ortho_group

from rot4d_widget.geometry.regular import POLYTOPE_NAMES
from rot4d_widget.geometry.star_regular import SPECS
from rot4d_widget.view.widget import Rot4DWidget

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from recording_comm import RecordingComm, install  # noqa: E402  (serialises like ipykernel)

KEYS = [("4", "Digit4"), ("2", "Digit2"), ("c", "KeyC"), ("z", "KeyZ"), ("w", "KeyW"), ("8", "Digit8")]


def key_msg(kind, key, code, t):
    event = {
        "type": kind, "event": kind, "key": key, "code": code, "shiftKey": False,
        "altKey": False, "ctrlKey": False, "metaKey": False, "repeat": False,
        "timeStamp": t, "location": 0, "target": {},
    }
    return {"content": {"data": {"method": "custom", "content": event}}, "buffers": []}


def drawn_msg(seq):
    """The companion's "drawn" acknowledgement of update ``seq``, as the front end delivers it."""
    return {"content": {"data": {"method": "custom", "content": {"event": "drawn", "seq": seq}}}, "buffers": []}


def bench(name, presses, rng):
    w = Rot4DWidget(name, _autotick=False)
    handler = w.events.comm.handler
    companion = w.companion.comm.handler
    orientations = special_ortho_group.rvs(4, size=presses + 20, random_state=rng)
    times, sizes, counts = [], [], []
    try:
        for i, m in enumerate(orientations):
            key, code = KEYS[i % len(KEYS)]
            w.state.matrix = m
            companion(drawn_msg(w.scene.update_id))  # the previous update was drawn
            if w.in_flight:
                raise RuntimeError(f"{name}: the acknowledgement did not release the flow control")
            updates = w.stats.updates
            n0 = len(RecordingComm.log)
            t0 = time.perf_counter()
            handler(key_msg("keydown", key, code, float(i)))
            t1 = time.perf_counter()
            update = RecordingComm.log[n0:]
            handler(key_msg("keyup", key, code, float(i)))
            if i < 20:  # warm-up
                continue
            if w.stats.updates != updates + 1 or not w.in_flight:
                raise RuntimeError(f"{name}: a key press sent no scene update")
            times.append(t1 - t0)
            sizes.append(sum(n for _, _, n, _ in update))
            counts.append(len(update))
        s = w.slice  # points, segments, triangles and their groups (the 4-D cells cut)
        return {
            "name": name,
            "median_ms": 1e3 * statistics.median(times),
            "p90_ms": 1e3 * float(np.percentile(times, 90)),
            "messages": statistics.median(counts),
            "median_kb": statistics.median(sizes) / 1024,
            "max_kb": max(sizes) / 1024,
            "slice": f"V={len(s.points)} E={len(s.segments)} F={len(np.unique(s.groups))} T={len(s.triangles)}",
        }
    finally:
        w.close()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--presses", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--star", action="store_true", help="also the ten regular star polychora (no target)")
    args = parser.parse_args(argv)
    install()
    rng = np.random.default_rng(args.seed)
    names = list(POLYTOPE_NAMES) + (list(SPECS) if args.star else [])
    rows = [bench(name, args.presses, rng) for name in names]
    print(f"Rot4DWidget: event dict -> update handed to the comm, {args.presses} presses at random orientations")
    width = max(len(n) for n in names)
    print(f"{'polytope':<{width}} {'median ms':>10} {'p90 ms':>8} {'msgs':>5} {'KB/update':>10} "
          f"{'max KB':>7}  last slice")
    ok = True
    for r in rows:
        print(
            f"{r['name']:<{width}} {r['median_ms']:>10.3f} {r['p90_ms']:>8.3f} {r['messages']:>5.0f} "
            f"{r['median_kb']:>10.1f} {r['max_kb']:>7.1f}  {r['slice']}"
        )
        if r["name"] in SPECS:
            continue  # no target (see the docstring)
        if r["max_kb"] > 64 or (r["name"] in ("120-cell", "600-cell") and r["median_ms"] > 2.0):
            ok = False
    print("targets (<= 2 ms for 120/600-cell, <= 64 KB per update):", "met" if ok else "NOT MET")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
