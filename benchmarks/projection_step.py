"""Kernel cost of the projection view (issue 22): a held key's update with ``projection=True``
against ``projection=False``.

For the 120-cell (600 vertices, 1200 edges) and a 64^4 field (a 4-ball, level 0: its data box, a
tesseract, is what the projection draws): the time from the keydown's event dict arriving at the
ipyevents model's comm handler to the last message of the update being handed to the comm
(lookup, step, slice -- a field's coarse one, as while a key is held --, buffers, scene, and
with the projection its state -- the 4x4 matrix and the hyperplanes' offsets -- put into the
same message: the page projects the skeleton it was sent once), with JSON + buffer
serialisation as ipykernel does it (tests/recording_comm.py).  Each press starts
from a fresh random orientation (the same ones for both settings) so that every update slices;
each update is acknowledged as the page does, so the next goes out at once.  Median and 90th
percentile over ``--presses`` presses, after 10 of warm-up; the two settings alternate press by
press so that drift in the machine's speed hits both alike.

The work the kernel no longer does is done in the page: a second table times companion.js's
``projectSkeleton`` (rotate, project, colour, find the crossings) under Node (the V8 engine of
Chromium) on the same rotations, when Node is installed: the median of a second pass over them
(and p90), and of the first pass, which includes the calls made before V8 optimises the function.

    python benchmarks/projection_step.py [--presses 200] [--seed 0]

Target (issue 22): the projection adds at most 20 % to the median.
"""

from __future__ import annotations

import argparse
import base64
import json
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.stats import special_ortho_group

from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.view import projection as pj
from rot4d_widget.view.bundle import page_module
from rot4d_widget.view.widget import Rot4DWidget

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from recording_comm import RecordingComm, install  # noqa: E402  (serialises like ipykernel)
from widget_update import drawn_msg, key_msg  # noqa: E402  (the same event and ack dicts)

KEYS = [("4", "Digit4"), ("8", "Digit8"), ("c", "KeyC"), ("z", "KeyZ")]
WARMUP = 10


def ball_field(n: int = 64) -> Field4D:
    x = np.linspace(-1, 1, n, dtype=np.float32)
    r2 = x[:, None, None] ** 2 + x[None, :, None] ** 2 + x[None, None, :] ** 2
    a = np.empty((n, n, n, n), dtype=np.float32)
    for i, w in enumerate(x):  # builds the data once, not timed
        a[..., i] = 0.64 - r2 - w * w
    f = Field4D(a, axes="xyzw", extent=((-1, 1),) * 4, name="ball 64^4")
    f.levels = 0.0
    return f


def press_time(w, m, i):
    """One keydown at orientation ``m``: seconds to the update handed to the comm, and its bytes."""
    key, code = KEYS[i % len(KEYS)]
    w.state.matrix = m
    w.companion.comm.handler(drawn_msg(w.scene.update_id))  # the previous update was drawn
    n0 = len(RecordingComm.log)
    t0 = time.perf_counter()
    w.events.comm.handler(key_msg("keydown", key, code, float(i)))
    t1 = time.perf_counter()
    sent = sum(n for _, _, n, _ in RecordingComm.log[n0:])
    w.events.comm.handler(key_msg("keyup", key, code, float(i) + 0.01))
    w.companion.comm.handler(drawn_msg(w.scene.update_id))
    return t1 - t0, sent


NODE_DRIVER = r"""
import { pathToFileURL } from "node:url";
import { readFileSync } from "node:fs";
const m = await import(pathToFileURL(process.argv[2]).href);
const { skeleton, states } = JSON.parse(readFileSync(0, "utf8"));
const sk = m.decodeSkeleton({ ...skeleton, vertices: Buffer.from(skeleton.vertices, "base64"),
                              edges: Buffer.from(skeleton.edges, "base64") });
// two passes over the states: the first includes the calls V8 runs before optimising the function
const times = [[], []];
for (const pass of [0, 1]) {
  for (const st of states) {
    const t0 = performance.now();
    m.projectSkeleton(sk, st);
    times[pass].push(performance.now() - t0);
  }
}
console.log(JSON.stringify(times));
"""


def page_times(w, states):
    """ms of the page's projectSkeleton for the skeleton of ``w``'s source and each state, under
    Node, ``[first pass, second pass]`` (None without Node)."""
    node = shutil.which("node") or shutil.which("nodejs")
    if node is None:
        return None
    sk = pj.skeleton_message(w.source, w._showing.scale)
    sk.update({k: base64.b64encode(bytes(sk[k])).decode() for k in ("vertices", "edges")})
    with tempfile.TemporaryDirectory() as tmp:
        js = pathlib.Path(tmp) / "page.mjs"
        js.write_text(page_module())
        driver = pathlib.Path(tmp) / "driver.mjs"
        driver.write_text(NODE_DRIVER)
        proc = subprocess.run([node, str(driver), str(js)], capture_output=True, text=True, timeout=300,
                              input=json.dumps({"skeleton": sk, "states": states}))
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def bench(label, make, presses, rng):
    on, off = make(True), make(False)
    times = {True: [], False: []}
    sizes = {True: [], False: []}
    states = []  # what the page projected, press by press
    try:
        for i, m in enumerate(special_ortho_group.rvs(4, size=presses + WARMUP, random_state=rng)):
            for w, flag in ((on, True), (off, False)) if i % 2 else ((off, False), (on, True)):
                dt, n = press_time(w, m, i)
                if i >= WARMUP:
                    times[flag].append(dt)
                    sizes[flag].append(n)
            states.append(dict(on.scene.buffer.projection))
        page = page_times(on, states)
    finally:
        on.close()
        off.close()
    row = {"name": label}
    for flag in (False, True):
        row[flag] = (1e3 * statistics.median(times[flag]), 1e3 * float(np.percentile(times[flag], 90)),
                     statistics.median(sizes[flag]) / 1024)
    row["ratio"] = row[True][0] / row[False][0]
    row["page"] = None if page is None else (statistics.median(page[1]), float(np.percentile(page[1], 90)),
                                             statistics.median(page[0]))
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--presses", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    install()
    rng = np.random.default_rng(args.seed)
    field = ball_field()
    cases = [
        ("120-cell", lambda p: Rot4DWidget("120-cell", projection=p, _autotick=False)),
        ("field 64^4", lambda p: Rot4DWidget(field, projection=p, _autotick=False)),
    ]
    rows = [bench(label, make, args.presses, rng) for label, make in cases]
    print(f"held key's update in the kernel (keydown -> update handed to the comm), {args.presses} presses")
    print(f"{'source':<11} {'off ms':>8} {'off p90':>8} {'off KB':>7} {'on ms':>8} {'on p90':>8} {'on KB':>7} "
          f"{'on/off':>7}")
    for r in rows:
        off, on = r[False], r[True]
        print(f"{r['name']:<11} {off[0]:>8.3f} {off[1]:>8.3f} {off[2]:>7.1f} {on[0]:>8.3f} {on[1]:>8.3f} "
              f"{on[2]:>7.1f} {r['ratio']:>7.2f}")
    if all(r["page"] is not None for r in rows):
        print("\nthe page's share: the page's projectSkeleton under Node, the same rotations, second pass"
              " (first pass: before V8 optimises)")
        print(f"{'source':<11} {'page ms':>8} {'page p90':>8} {'1st pass':>8}")
        for r in rows:
            print(f"{r['name']:<11} {r['page'][0]:>8.3f} {r['page'][1]:>8.3f} {r['page'][2]:>8.3f}")
    else:
        print("(Node not found: the page's share not measured)")
    ok = all(r["ratio"] <= 1.2 for r in rows)
    print("target (the projection adds <= 20 % to the median):", "met" if ok else "NOT MET")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
