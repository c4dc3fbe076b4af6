"""The largest single update the widget sends, per kind of view: what the update cap must allow.

For each case the widget is shown at rest in ``--orientations`` random orientations (each
settled, so the picture is the full-resolution one) and the bytes of every update message are
counted as ipykernel would send them (JSON + binary buffers, tests/recording_comm.py).  Printed:
the largest message and the median of each orientation's largest, and the cap (`rot4d_widget.view.buffers.MAX_UPDATE_BYTES`) as a
multiple of the largest.  Then a user's source of millions of points (3 M and 30 M): how long
making the widget takes to refuse it, and how long a key takes until the error is under the
readout when the source grows past the cap after the widget was made.

    python benchmarks/update_size.py [--orientations 12] [--seed 0]
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np
from scipy.stats import special_ortho_group

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from recording_comm import RecordingComm, install  # noqa: E402  (serialises like ipykernel)

from rot4d_widget import SliceData  # noqa: E402
from rot4d_widget.sources.field.container import Field4D  # noqa: E402
from rot4d_widget.view.buffers import MAX_UPDATE_BYTES  # noqa: E402
from rot4d_widget.view.widget import Rot4DWidget  # noqa: E402


def gyroid_field(n=64):
    def f(x, y, z, w):
        return np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z + w) + np.sin(z) * np.cos(x - w)

    return Field4D.from_function(f, extent=[(-np.pi, np.pi)] * 4, levels=(-0.5, 0.0, 0.5), resolution=n)


CASES = [
    ("600-cell", lambda: Rot4DWidget("600-cell", _autotick=False)),
    ("120-cell", lambda: Rot4DWidget("120-cell", _autotick=False)),
    ("omnitruncated 120-cell", lambda: Rot4DWidget("omnitruncated 120-cell", _autotick=False)),
    ("great icosahedral 120-cell", lambda: Rot4DWidget("great icosahedral 120-cell", _autotick=False)),
    ("600-cell, 12-slice oval", lambda: Rot4DWidget("600-cell", slices=12, arrangement="oval", _autotick=False)),
    ("24-cell, 64 slices in a grid", lambda: Rot4DWidget("24-cell", slices=64, arrangement="grid", _autotick=False)),
    ("field 64^4, 3 surfaces", lambda: Rot4DWidget(gyroid_field(), _autotick=False)),
    ("field 64^4, volume", lambda: Rot4DWidget(gyroid_field(), rendering="volume", _autotick=False)),
    ("field 64^4, 12 slices, volume", lambda: Rot4DWidget(gyroid_field(), slices=12, arrangement="grid",
                                                           rendering="volume", _autotick=False)),
]


def _message(content):
    return {"content": {"data": {"method": "custom", "content": content}}, "buffers": []}


def _key(kind, t):
    return _message({"type": kind, "key": "4", "code": "Digit4", "shiftKey": False, "altKey": False,
                     "ctrlKey": False, "metaKey": False, "repeat": False, "timeStamp": t})


def largest_update(make, orientations) -> tuple[int, float]:
    """The largest single message and the median of each orientation's largest, in bytes: a tap of
    "4" (keydown, keyup) at each orientation, every update acknowledged as drawn."""
    w = make()
    try:
        keys, drawn = w.events.comm.handler, w.companion.comm.handler
        sizes = []
        for i, m in enumerate(orientations):
            w.state.matrix = m
            n0 = len(RecordingComm.log)
            keys(_key("keydown", 1000.0 * i))
            drawn(_message({"event": "drawn", "seq": w.scene.update_id}))
            keys(_key("keyup", 1000.0 * i + 50.0))
            drawn(_message({"event": "drawn", "seq": w.scene.update_id}))
            sizes.append(max(n for _, _, n, _ in RecordingComm.log[n0:]))
        return max(sizes), statistics.median(sizes)
    finally:
        w.close()


class Cloud:
    """A user's source: ``n`` points, ``big`` of them while c0 > 0.01."""

    size = 1.0
    n_groups = 1

    def __init__(self, n, big):
        rng = np.random.default_rng(0)
        self.small = rng.random((n, 3)) - 0.5
        self.large = self.small if big == n else rng.random((big, 3)) - 0.5

    def slice(self, matrix, c0):
        p = self.large if c0 > 0.01 else self.small
        return SliceData(p, np.zeros((0, 2), int), np.zeros((0, 3), int), np.zeros(0, int))

    def describe(self):
        return {"kind": "cloud"}


def big_source(n) -> tuple[float, float]:
    """(s to refuse a widget on ``n`` points, s from a key to the error when the source grows to ``n``);
    both include the source's own slice (SliceData copies its arrays)."""
    cloud = Cloud(n, n)
    t = time.perf_counter()
    try:
        Rot4DWidget(cloud, _autotick=False).close()
    except ValueError:
        pass
    refused = time.perf_counter() - t
    del cloud
    w = Rot4DWidget(Cloud(30, n), _autotick=False)
    try:
        w.state.c0_step = 0.05
        keys = w.events.comm.handler
        t = time.perf_counter()
        keys(_message({"type": "keydown", "key": "l", "code": "KeyL", "repeat": False, "timeStamp": 0.0,
                       "shiftKey": False, "altKey": False, "ctrlKey": False, "metaKey": False}))
        error = time.perf_counter() - t if w.errors.outputs else float("nan")
    finally:
        w.close()
    return refused, error


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--orientations", type=int, default=12)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    install()
    rng = np.random.default_rng(args.seed)
    orientations = special_ortho_group.rvs(4, size=args.orientations, random_state=rng)
    rows = [(name, *largest_update(make, orientations)) for name, make in CASES]
    width = max(len(r[0]) for r in rows)
    print(f"largest update at rest over {args.orientations} random orientations (bytes on the comm)")
    print(f"{'case':<{width}} {'largest KB':>11} {'median KB':>10}")
    for name, most, med in rows:
        print(f"{name:<{width}} {most / 1024:>11.1f} {med / 1024:>10.1f}")
    biggest = max(r[1] for r in rows)
    print(f"cap MAX_UPDATE_BYTES = {MAX_UPDATE_BYTES / 2**20:.0f} MiB = {MAX_UPDATE_BYTES / biggest:.1f}x the largest")
    print()
    print(f"{'a source of':>12} {'refused at construction s':>26} {'key -> error s':>15}")
    for n in (3_000_000, 30_000_000):
        refused, error = big_source(n)
        print(f"{n:>12,} {refused:>26.3f} {error:>15.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
