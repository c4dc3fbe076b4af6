"""Key -> pixel latency, held-key frame rate and bytes per update, in a real browser.

One run, one JupyterLab 4 server, one headless Chromium (SwiftShader WebGL):
a baseline -- a bare pythreejs tetrahedron (Mesh + BufferGeometry) whose
ipyevents keydown handler assigns a new float32 position array, drawn by a
Renderer with the widget's settings (600 x 500, no multisampling) -- and
``Rot4DWidget(name)`` for each of the six regular polychora.

    python benchmarks/browser_latency.py [--presses 40] [--hold 2]
        [--tap 60-120] [--cases 5-cell,600-cell] [--seed 0] [--rev HEAD]
        [--nagle] [--runs 1] [--json out.json] [--ceiling] [--trace [--profile]]
        [--targets own|slow|issue4] [--cpus 0 [--busy 1]] [--in-flight N] [--volume-step S]

Issue 22's cases ``proj120`` (the 120-cell with ``projection=True``), ``sstel120`` and ``gicos120``
(the small stellated and great icosahedral 120-cells): judged as the 600- and 120-cell are.

Issue 21's cases ``blob64-surface``, ``blob64-volume``, ``blob64-mip`` (and issue 36's ``blob64-sections``,
every rendering): a 64^4 field (a Gaussian
blob travelling along x as w grows, the array of benchmarks/volume_step.py) in each rendering,
with a table of held fps, its ratio to the same run's baseline (target >= 0.6x for volume and
mip) and bytes per update; ``--volume-step S`` sets the ray's sample spacing (a diagnosis).
Figures and commands: docs/performance.md.  Since issue 36 the page draws a field's held pictures
from its own copy of the data: a field's case waits (up to 2 min) for the readout to say so and
reports how long that took ("page's copy after"); a revision without it (``--rev``) is measured as
it was.

About 4 minutes for the default run (headless, runs as root).  The machine
is shared and noisy: ``--runs 3`` repeats the whole measurement and ends
with each target's figure per run and its median over the runs.

Each polychoron gets a notebook (own kernel, own page, same server and
browser) showing the baseline canvas and the widget's canvas, both 600 x 500,
both on screen.  Single presses alternate between the two canvases in random
order, so the baseline is measured in the same minute as the widget: the
machine is shared and its load drifts; the excess is taken against this
*paired* baseline.  The baseline row pools every pairing.

``--rev REV`` measures a clean ``git archive`` of that revision (first on the
kernel's PYTHONPATH) instead of the working tree, so uncommitted edits
elsewhere in the checkout do not leak into the numbers.  The package's
server extension (rot4d_widget._server) sets TCP_NODELAY on the kernel
WebSockets; ``--nagle`` switches it off to show what jupyter_server's default
costs: Nagle's algorithm then holds every frame of a burst after the first
(kernel status, comm updates) until the browser's delayed ACK, up to 40 ms.

How each quantity is measured (clocks: the page's performance.now()):

key -> pixel
    A requestAnimationFrame loop posts, every frame, a task that runs after
    that frame's rendering step (pythreejs renders in its own rAF callback):
    it draws the active WebGL canvas (preserveDrawingBuffer) into a 2-D
    canvas, hashes every pixel and stamps the time after the read (the read
    waits for the GL draw).  A capture-phase keydown listener on ``window``
    stamps the key.  Latency = first frame whose hash differs from the last
    frame before the key, minus the key stamp.  ``--presses`` single presses
    per canvas (random rotation keys; keyup ``--tap`` ms after keydown, a
    human tap -- an instant keyup would carry the TCP ACK that releases the
    Nagle-held reply and hide the stall), each 0.1-0.3 s (random: the frame
    phase averages out) after the mouse moved onto the canvas.
    Reported: median (p10-p90), mean +- std; excess = widget minus paired
    baseline, mean (median).
key -> msg, msg -> px, kernel
    A WebSocket wrapper installed before the app loads (page init script)
    stamps every kernel-channel message on arrival (and its size); the update
    is the first ``comm_msg`` with binary buffers after the key.  key -> msg =
    page -> kernel -> page; msg -> px = deserialise + wait for a frame + draw
    + read-back.  kernel = time per update in the kernel (the widget's
    ``_send``, the update pump's callback: slice + scene.show + readout; the
    baseline's handler), timed
    by wrapping it from the notebook (benchmark side only).  The widget's
    probe also stamps, with time.time() (the page's timeOrigin + now() is the
    same wall clock, checked to < 1 ms), when the key and each "drawn" ack
    reach the widget and when each update is computed: key -> kernel, kernel
    handling, sent -> arrival.
held fps
    Hold "4" on the canvas for ``--hold`` s (headless Chromium sends no
    auto-repeat): frames whose hash changed per second over [keydown + 0.5 s,
    keyup] (past the 0.25 s hold delay).  The cycle of one held update is
    split with the same stamps: update arrives -> page sends its "drawn" ack
    (page: deserialise, frame, draw, one more frame) -> ack reaches the
    widget -> next update computed (or waits for a tick) -> arrives.  The baseline (first notebook
    only) repeats from a kernel thread at 30 Hz after 0.25 s, no flow control.
after release
    Frames whose hash changed after the keyup stamp (2 s watched) and when the
    last one came.  The widget's kernel also records, at keyup, whether an
    update was in flight, and afterwards whether the state moved after keyup
    and how many updates were sent after it.  ok = no step after keyup, at
    most 2 frames (the update in flight, then the latest state it held back),
    the last within 0.5 s.
bytes/update
    Every byte the page receives on the kernel WebSocket during the hold and
    the 2 s after it (updates, readouts, kernel status and echo messages),
    divided by the updates the kernel sent meanwhile; in brackets the median
    size of the update message itself.

the cycle's ceiling (``--ceiling``)
    One more hold with every mesh hidden: the rows still travel in full and are
    applied and acknowledged after a render that draws nothing.  "drawn" acks per
    second is what the update cycle delivers when the draw is free (a GPU's view).
where the page's time goes (``--trace``, ``--profile``)
    One more hold under a Chromium trace (CDP Tracing, every process): busy time
    per thread, and the page's main thread split by task -- kernel messages
    (parse, deserialise, apply), animation frames (three.js render), style/layout/
    paint (the readout's DOM), the benchmark's own read-back, other, idle -- as ms
    per update.  ``--profile`` adds the page's JavaScript by self time.  Every hold
    also counts the kernel WebSocket messages per update by kind, both ways.

The pages' ``console.debug`` is a no-op unless ``--console-debug``: pythreejs logs
one line per "child changed" event (tens per update) and with DevTools attached,
as Playwright always is, each is sent to the driver -- a cost a user's browser
does not have.

Targets (``--targets``, default ``own``; ``slow`` with ``--cpus``): issue 8's, as
ratios of the same run's baseline -- at the machine's own speed held fps >= 0.8x
the baseline's (small four) and >= 0.5x (600-/120-cell), mean key -> pixel excess
<= one frame and two frames; on a machine ~3x slower >= 0.6x / >= 0.35x and two /
four frames.  ``issue4`` checks the old absolute targets (20 / 10 fps; one / three
frames).  Nothing drawn after release beyond the updates in flight.

``--cpus 0 [--busy N]`` emulates a slower machine: this process and everything it
starts (server, kernels, Chromium and its GPU process) run on those CPUs, with N
busy-loop processes competing there.  Quote medians; run it more than once.
"""

from __future__ import annotations

import argparse
import bisect
import json
import math
import os
import pathlib
import platform
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))

from browser_setup import (  # noqa: E402  (the browser tests' building blocks, not their conftest)
    RemoteServer,
    CHROMIUM_FLAGS,
    INSTALL_HINT,
    JupyterServer,
    apt_install_chromium,
    installed_chromium,
    playwright_chromium,
)
from jupyter_page import JupyterPage, write_notebook  # noqa: E402

POLYCHORA = ["5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell"]
#: 4-D fields (issue 9), not in the default run: ``--cases sphere64,...``.  Each builds ``field``.
FIELD_CASES = {
    # f = R^2 - |q|^2 sampled on a 64^4 grid (numpy, float32): a ball in every slice
    "sphere64": (
        "import numpy as np\nfrom rot4d_widget import Field4D\n"
        "g = np.linspace(-1.0, 1.0, 64, dtype=np.float32)\n"
        "x, y, z, t = np.ix_(g, g, g, g)\n"
        "field = Field4D(0.64 - (x * x + y * y + z * z + t * t), extent=[(-1.0, 1.0)] * 4, levels=[0.0])"
    ),
    # a smooth random-looking field on a 128^3 x 32 grid (sums of a few plane waves)
    "waves128": (
        "import numpy as np\nfrom rot4d_widget import Field4D\n"
        "x, y, z = (np.linspace(-1, 1, 128, dtype=np.float32)[s] for s in np.ix_(*[range(128)] * 3))\n"
        "t = np.linspace(-1, 1, 32, dtype=np.float32)[:, None, None, None]\n"
        "field = Field4D(np.cos(4 * x + 2 * t) * np.cos(3 * y - t) + np.cos(5 * z + 3 * t) * np.cos(2 * x),"
        " axes='wxyz', extent=[(-1.0, 1.0)] * 4, levels=[0.3])"
    ),
}
# notebook 04's data: the Allen-Cahn simulation (py-pde; cached after its first run)
FIELD_CASES["allen-cahn"] = (
    "from rot4d_widget import Field4D\nfrom rot4d_widget.sources.datasets import phase_separation\n"
    "field = Field4D.from_xarray(phase_separation(), w='time', levels=[0.0])"
)
#: Issue 21: a Gaussian blob travelling along x as w grows, f[x, y, z, w] on a 64^4 float32 array
#: (benchmarks/volume_step.py's blob_array, as notebook-cell text), drawn in each rendering: ``--cases blob64-volume,...``.
BLOB64 = (
    "import numpy as np\nfrom rot4d_widget import Field4D\n"
    "_g = np.linspace(-1.0, 1.0, 64, dtype=np.float32)\n"
    "_yz = _g[None, :, None] ** 2 + _g[None, None, :] ** 2\n"
    "_a = np.empty((64,) * 4, dtype=np.float32)\n"
    "for _i, _w in enumerate(_g):\n"
    "    _a[..., _i] = np.exp(-((_g[:, None, None] - 0.6 * _w) ** 2 + _yz) / 0.18)\n"
    "field = Field4D(_a, axes='xyzw', extent=[(-1.0, 1.0)] * 4, levels=[0.5], name='blob')"
)
#: The widget's ``rendering`` per case (the fields above draw "surface").
FIELD_RENDERING = {}
for _r in ("surface", "volume", "mip", "sections"):
    FIELD_CASES[f"blob64-{_r}"] = BLOB64
    FIELD_RENDERING[f"blob64-{_r}"] = _r
#: Issue 21's speed target: volume and mip held keys at >= 0.6x the baseline's held frame rate
#: (same run), whatever ``--targets`` says for the rest.
RATIO_FPS = {"blob64-volume": 0.6, "blob64-mip": 0.6}
#: Parallel slices (issue 10): the widget's arguments.
STACK_CASES = {
    "oval24": "'24-cell', slices=12, spacing=0.3, arrangement='oval'",
    "oval600": "'600-cell', slices=12, spacing=0.3, arrangement='oval'",
}
#: The biggest uniform polychoron (issue 11): 14400 vertices, 28800 edges, 2640 cells.
UNIFORM_CASES = {
    "omni120": "'omnitruncated 120-cell'",
}
#: Issue 22: the 120-cell with its projection beside the slice (the page also projects and draws the
#: 4-D skeleton each update), and two regular star polychora: the small stellated 120-cell (star
#: faces; 1,200 triangles a slice) and the great icosahedral 120-cell (12,000 fill triangles, 1.5 MB
#: an update).  Judged as the large cases (no target of their own).
ISSUE22_CASES = {
    "proj120": "'120-cell', projection=True",
    "sstel120": "'small stellated 120-cell'",
    "gicos120": "'great icosahedral 120-cell'",
}
ALL_CASES = POLYCHORA + list(FIELD_CASES) + list(STACK_CASES) + list(UNIFORM_CASES) + list(ISSUE22_CASES)
LARGE = {"600-cell", "120-cell", *FIELD_CASES, *STACK_CASES, *UNIFORM_CASES, *ISSUE22_CASES}
#: Cases with an absolute held-fps target of their own issue (distinct frames/s on software
#: WebGL): issue 10's 12 slices of the 24-cell, issue 11's largest uniform polychoron.
ABSOLUTE_FPS = {"oval24": 10.0, "omni120": 5.0}

FRAME_MS = 1000.0 / 60.0
PRESS_KEYS = ["2", "3", "4", "6", "8", "c", "y", "z", "w"]
HOLD_KEY = "4"
FPS_SKIP = 0.5  # s after keydown before the held frame rate is counted
WATCH_AFTER = 2.0  # s watched after keyup
VIEWPORT = {"width": 1400, "height": 1500}  # both canvases on screen
BASE, WIDGET = 0, 1

# -- page side ----------------------------------------------------------------

#: Installed before any page script: stamps kernel-channel WebSocket traffic.
WS_HOOK = r"""
(() => {
  if (window.__wsLog) return;
  const L = window.__wsLog = {on: false, log: [], acks: [], out: []};
  const Orig = window.WebSocket;
  const dec = new TextDecoder('utf-8', {fatal: false});
  const UPDATE = /"buffer_paths"\s*:\s*\[\s*\[/;
  const ACK = /"event"\s*:\s*"drawn"/;
  const TYPE = /"msg_type"\s*:\s*"(\w+)"/;
  const STATE = /"execution_state"\s*:\s*"(\w+)"/;
  const METHOD = /"method"\s*:\s*"(\w+)"/;
  const EVENT = /"(?:event|type)"\s*:\s*"(\w+)"/;
  const STATE_KEYS = /"state"\s*:\s*\{\s*((?:"\w+"\s*:\s*[^,{}]*,?\s*)+)/;
  const head = (d) => {
    if (typeof d === 'string') return d.slice(0, 8192);
    if (d instanceof ArrayBuffer) return dec.decode(new Uint8Array(d, 0, Math.min(d.byteLength, 8192)));
    if (ArrayBuffer.isView(d)) return dec.decode(new Uint8Array(d.buffer, d.byteOffset, Math.min(d.byteLength, 8192)));
    return '';
  };
  const onMessage = (e) => {
    if (!L.on) return;
    const t = performance.now();
    const d = e.data;
    const n = typeof d === 'string' ? d.length : (d.byteLength !== undefined ? d.byteLength : (d.size || 0));
    const h = head(d);
    const mt = TYPE.exec(h), st = STATE.exec(h), me = METHOD.exec(h);
    L.log.push([t, n, h.includes('comm_msg') && UPDATE.test(h) ? 1 : 0,
                (mt ? mt[1] : '?') + (me ? ':' + me[1] : '') + (st ? ':' + st[1] : '')]);
  };
  class HookedWebSocket extends Orig {
    constructor(url, protocols) {
      super(url, protocols);
      this.__kernel = String(url).includes('/channels');
      if (this.__kernel) this.addEventListener('message', onMessage);  // before the app's own
    }
    send(d) {
      if (L.on && this.__kernel) {
        const h = head(d);
        if (ACK.test(h)) L.acks.push(performance.now());
        const mt = TYPE.exec(h), me = METHOD.exec(h), ev = EVENT.exec(h);
        const sk = me && me[1] === 'update' ? STATE_KEYS.exec(h) : null;
        L.out.push([performance.now(), (mt ? mt[1] : '?') + (me ? ':' + me[1] : '') + (ev ? ':' + ev[1] : '')
                    + (sk ? ':' + sk[1].replace(/[^\w,]/g, '') : '')]);
      }
      return super.send(d);
    }
  }
  window.WebSocket = HookedWebSocket;
})();
"""

#: Without ``--console-debug``: console.debug does nothing on the measured pages.  pythreejs
#: logs a console.debug line for every "child changed" event (about 30 per update here);
#: with DevTools attached -- Playwright always is -- each call is serialised and sent to
#: the driver, a cost a user's browser without DevTools open does not pay.
QUIET_DEBUG = "console.debug = () => {};"

#: Reads the active canvas back after every frame's rendering step; stamps keys.
RECORDER = r"""
(sels) => {
  if (window.__bench && window.__bench.stop) window.__bench.stop();
  const cs = sels.map((s) => document.querySelector(s));
  if (cs.some((c) => !c)) return null;
  const B = window.__bench = {t: [], h: [], g: [], cost: [], keys: [], lastChange: -1, lastKey: -1,
                              run: true, cur: 0};
  const tmps = cs.map((c) => {
    const tmp = document.createElement('canvas');
    tmp.width = c.width; tmp.height = c.height;
    return tmp.getContext('2d', {willReadFrequently: true});
  });
  let prev = null;
  B.setTarget = (i) => { B.cur = i; prev = null; };
  const ch = new MessageChannel();
  ch.port1.onmessage = () => {
    if (!B.run) return;
    const g = B.cur, c = cs[g], ctx = tmps[g];
    const t0 = performance.now();
    ctx.drawImage(c, 0, 0);
    const d = new Int32Array(ctx.getImageData(0, 0, c.width, c.height).data.buffer);
    let h = -2128831035;
    for (let i = 0; i < d.length; i++) h = Math.imul(h ^ d[i], 16777619);
    const t = performance.now();
    B.t.push(t); B.h.push(h); B.g.push(g); B.cost.push(t - t0);
    if (prev !== null && h !== prev) B.lastChange = t;
    prev = h;
  };
  const loop = () => { if (!B.run) return; requestAnimationFrame(loop); ch.port2.postMessage(0); };
  requestAnimationFrame(loop);
  const onKey = (e) => {
    const t = performance.now();
    B.keys.push([e.type, t, e.code, e.repeat]);
    if (e.type === 'keydown' && !e.repeat) B.lastKey = t;
  };
  window.addEventListener('keydown', onKey, true);
  window.addEventListener('keyup', onKey, true);
  B.stop = () => {
    B.run = false;
    window.removeEventListener('keydown', onKey, true);
    window.removeEventListener('keyup', onKey, true);
  };
  const gl = cs[1].getContext('webgl2') || cs[1].getContext('webgl');
  let renderer = null;
  if (gl) {
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    renderer = gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
  }
  return {width: cs[1].width, height: cs[1].height, dpr: window.devicePixelRatio, renderer,
          timeOrigin: performance.timeOrigin};
}
"""

# -- kernel side --------------------------------------------------------------

#: Written next to the notebooks and imported by them: the baseline and the probes.
HELPERS = r'''
"""Helpers for benchmarks/browser_latency.py (generated; imported by its notebooks)."""
import json, threading, time
import numpy as np
import pythreejs as p3
from ipyevents import Event

# -- baseline: a bare pythreejs tetrahedron, a new float32 position array per key --
_T = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=np.float64) * 0.73
_FACES = np.array([(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]).ravel()
_axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
_K = np.array([[0, -_axis[2], _axis[1]], [_axis[2], 0, -_axis[0]], [-_axis[1], _axis[0], 0]])
_th = np.pi / 64
_STEP = np.eye(3) + np.sin(_th) * _K + (1 - np.cos(_th)) * _K @ _K

def _positions(R):
    return np.ascontiguousarray((_T @ R.T)[_FACES], dtype=np.float32)

_colors = np.repeat(np.array([[.78, .06, .18], [.2, .4, .8], [.2, .7, .3], [.9, .7, .1]], dtype=np.float32),
                    3, axis=0)
geometry = p3.BufferGeometry(attributes={
    "position": p3.BufferAttribute(array=_positions(np.eye(3))),
    "color": p3.BufferAttribute(array=_colors),
})
mesh = p3.Mesh(geometry, p3.MeshBasicMaterial(vertexColors="VertexColors", side="DoubleSide"),
               frustumCulled=False)
camera = p3.PerspectiveCamera(position=[0, 0, 5], fov=40, aspect=600 / 500, near=0.1, far=100)
renderer = p3.Renderer(camera=camera, scene=p3.Scene(children=[mesh, camera]), width=600, height=500,
                       antialias=False, background="#ffffff", background_opacity=1.0, clearColor="#ffffff",
                       controls=[p3.OrbitControls(controlling=camera, enableKeys=False)])
renderer.add_class("bench-baseline")
_lock = threading.Lock()
_st = {"R": np.eye(3), "held": {}}
_base = {"kernel": [], "up": None, "n": 0}

def _step():
    with _lock:
        t0 = time.perf_counter()
        _st["R"] = _STEP @ _st["R"]
        geometry.attributes["position"].array = _positions(_st["R"])
        _base["n"] += 1
        _base["kernel"].append(time.perf_counter() - t0)

def _repeat(code, token):
    # held: repeat at 30 Hz after 0.25 s, like the widget, but with no flow control
    due = time.monotonic() + 0.25
    while True:
        time.sleep(max(0.0, due - time.monotonic()))
        if _st["held"].get(code) is not token:
            return
        _step()
        due += 1 / 30

def _on_event(ev):
    if ev.get("type") == "keydown":
        if ev.get("repeat"):
            return
        _step()
        token = object()
        _st["held"][ev.get("code")] = token
        threading.Thread(target=_repeat, args=(ev.get("code"), token), daemon=True).start()
    elif ev.get("type") == "keyup":
        _st["held"].pop(ev.get("code"), None)
        _base["up"] = {"n": _base["n"], "in_flight": None, "R": _st["R"].tolist()}

events = Event(source=renderer, watched_events=["keydown", "keyup"], prevent_default_action=True)
events.on_dom_event(_on_event)

def read_baseline():
    print(json.dumps(dict(n_updates=_base["n"], kernel_ms=[1000 * x for x in _base["kernel"]],
                          up=_base["up"], final=_st["R"].tolist())))

# -- probes around a Rot4DWidget (timing only; the widget's behaviour is unchanged) --
def probe(w):
    # epoch stamps (time.time(), same clock as the page's timeOrigin + now()) of: key events and
    # "drawn" acks as they reach the widget, and every update's computation (start, end, thread)
    rec = {"kernel": [], "up": None, "keys": [], "acks": [], "renders": []}
    main = threading.main_thread()
    pump = w._pump
    render = pump._send  # the widget's _send: slice + scene.show + readout, once per update
    def timed_render(*a, **k):
        e0, t0 = time.time(), time.perf_counter()
        try:
            return render(*a, **k)
        finally:
            rec["kernel"].append(time.perf_counter() - t0)
            rec["renders"].append((e0, time.time(), threading.current_thread() is main))
    pump._send = timed_render
    handle_event, handle_drawn = w._handle_event, w._handle_drawn
    def stamped_event(ev):
        if isinstance(ev, dict) and ev.get("type") == "keydown" and not ev.get("repeat"):
            rec["keys"].append(time.time())
        return handle_event(ev)
    def stamped_drawn(*a, **k):
        rec["acks"].append(time.time())
        return handle_drawn(*a, **k)
    w.events.on_dom_event(handle_event, remove=True)
    w.events.on_dom_event(stamped_event)
    w.companion.on_drawn(handle_drawn, remove=True)
    w.companion.on_drawn(stamped_drawn)
    def on_keyup(ev):  # registered after the widget's own handler: runs after it
        if isinstance(ev, dict) and ev.get("type") == "keyup":
            rec["up"] = {"n": w.stats.updates, "in_flight": w.in_flight, "R": w.state.matrix.tolist(),
                         "max_in_flight": getattr(w._pump, "max_in_flight", 2)}
    w.events.on_dom_event(on_keyup)
    w._bench_probe = rec
    return w

def read_widget(w):
    rec = w._bench_probe
    print(json.dumps(dict(n_updates=w.stats.updates, kernel_ms=[1000 * x for x in rec["kernel"]], up=rec["up"],
                          final=w.state.matrix.tolist(), acks=w.stats.acks, timeouts=w.stats.timeouts,
                          capacity=w.scene.capacity, canvas_class=w.scene.canvas_class,
                          stamps={k: rec[k] for k in ("keys", "acks", "renders")})))
'''

#: ``--nagle``: switch off the package's server extension (rot4d_widget._server), which
#: sets TCP_NODELAY on kernel WebSockets; jupyter_server itself leaves Nagle's algorithm on,
#: and it then holds the 2nd and later frames of a burst (status busy, comm update,
#: readout, status idle) until the browser's delayed ACK (40 ms on Linux).
NAGLE_CONFIG = {"ServerApp": {"jpserver_extensions": {"rot4d_widget._server": False}}}

CELLS = [
    "import rot4d_bench_helpers as bench\nbench.renderer",
    "from rot4d_widget import Rot4DWidget\nw = bench.probe(Rot4DWidget({name!r}))\nw",
]
READ = {BASE: "bench.read_baseline()", WIDGET: "bench.read_widget(w)"}
def release_ok(h: dict) -> bool:
    """The view settled at once after the key's release: the state did not move, at most the
    updates the widget may have had in flight at keyup (its pump's bound, read from the widget
    measured) plus the latest state (rows re-sent at rest) were drawn, the last within 0.5 s."""
    allowed = int(h.get("max_in_flight") or 2) + 1
    return (not h["moved_after_up"]) and h["after_frames"] <= allowed and h["settle_ms"] <= 500


#: Targets, per ``--targets``: (excess key->pixel in frames, held fps) for the small four and for
#: the 600-/120-cell; held fps is absolute ("issue4") or a ratio of the same run's baseline.
TARGETS = {
    "own": {"frames": (1, 2), "fps": (0.8, 0.5), "ratio": True,
            "text": "issue 8, at the machine's own speed"},
    "slow": {"frames": (2, 4), "fps": (0.6, 0.35), "ratio": True,
             "text": "issue 8, on a machine about 3x slower"},
    "issue4": {"frames": (1, 3), "fps": (20, 10), "ratio": False, "text": "issue 4 (absolute)"},
}
TARGET = "own"


def targets_for(case: str, base_fps: float) -> tuple[float, float, str]:
    """(excess key->pixel limit in ms, minimum held fps, fps target as text) under ``TARGET``."""
    t = TARGETS[TARGET]
    k = 1 if case in LARGE else 0
    lat = t["frames"][k] * FRAME_MS
    if case in ABSOLUTE_FPS:
        return lat, ABSOLUTE_FPS[case], f"≥ {ABSOLUTE_FPS[case]:g} (its issue)"
    if case in RATIO_FPS:
        return lat, RATIO_FPS[case] * base_fps, f"≥ {RATIO_FPS[case]:g}× = {RATIO_FPS[case] * base_fps:.1f} (issue 21)"
    if t["ratio"]:
        return lat, t["fps"][k] * base_fps, f"≥ {t['fps'][k]:g}× = {t['fps'][k] * base_fps:.1f}"
    return lat, t["fps"][k], f"≥ {t['fps'][k]:g}"


#: ``--in-flight N``: set the widget's bound on updates in flight (None: the package's default).
IN_FLIGHT = None
#: ``--volume-step S``: the ray-cast renderings sample every S grid spacings (None: the package's
#: ``volume_layer.STEP``, 0.5) -- to see how the page's time follows the samples per ray.
VOLUME_STEP = None


# -- helpers ------------------------------------------------------------------


def pct(xs, q):
    xs = sorted(xs)
    if not xs:
        return math.nan
    k = (len(xs) - 1) * q
    lo, hi = math.floor(k), math.ceil(k)
    return xs[lo] + (xs[hi] - xs[lo]) * (k - lo)


def median(xs):
    return statistics.median(xs) if xs else math.nan


def mean(xs):
    return statistics.fmean(xs) if xs else math.nan


def find_chromium() -> str:
    path = installed_chromium() or apt_install_chromium() or playwright_chromium()
    if not path:
        sys.exit(INSTALL_HINT)
    return path


def export_revision(rev: str, dest: pathlib.Path) -> str:
    """A clean copy of the package at ``rev`` under ``dest``; returns its description."""
    dest.mkdir(parents=True)
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "rot4d_widget"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    sha = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", rev], check=True,
                         capture_output=True, text=True).stdout.strip()
    return f"git archive {rev} ({sha})"


def working_tree_description() -> str:
    try:
        sha = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], check=True,
                             capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "rot4d_widget"],
                               check=True, capture_output=True, text=True).stdout.strip()
        return f"working tree at {sha}" + (" + uncommitted changes in rot4d_widget/" if dirty else "")
    except Exception:
        return "installed package"


def cpu_name() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "?"


def ws_on(page):
    page.evaluate("() => { const L = window.__wsLog; L.log = []; L.acks = []; L.out = []; L.on = true; }")


# -- one notebook: the baseline and one polychoron, interleaved -----------------


def run_case(context, server, case: str, args, rng: random.Random, hold_baseline: bool) -> dict:
    name = f"bench_{case.replace('-', '_')}.ipynb"
    cells = [c.format(name=case) for c in CELLS]
    if case in STACK_CASES:
        cells[1] = f"from rot4d_widget import Rot4DWidget\nw = bench.probe(Rot4DWidget({STACK_CASES[case]}))\nw"
    if case in UNIFORM_CASES or case in ISSUE22_CASES:
        args_ = UNIFORM_CASES.get(case) or ISSUE22_CASES[case]
        cells[1] = f"from rot4d_widget import Rot4DWidget\nw = bench.probe(Rot4DWidget({args_}))\nw"
    if case in FIELD_CASES:
        rendering = f", rendering={FIELD_RENDERING[case]!r}" if case in FIELD_RENDERING else ""
        step = ""
        if VOLUME_STEP is not None:  # --volume-step: the ray's sample spacing (volume_layer.STEP), a diagnosis
            step = f"import rot4d_widget.view.volume_layer as _vl\n_vl.STEP = {VOLUME_STEP!r}\n"
        cells[1] = (f"{FIELD_CASES[case]}\n{step}from rot4d_widget import Rot4DWidget\n"
                    f"w = bench.probe(Rot4DWidget(field{rendering}))\nw")
    if IN_FLIGHT is not None:  # --in-flight: the widget's bound on updates in flight, for comparisons
        head, _, last = cells[1].rpartition("\n")  # ... w = bench.probe(...) / w
        cells[1] = f"{head}\nw._pump.max_in_flight = {IN_FLIGHT}\n{last}"
    write_notebook(server.root / name, cells)
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: None if page.__dict__.get("closing") else errors.append(str(e)))
    try:
        jp = JupyterPage(page, server, name).open(timeout=180)
        jp.run_all(timeout=300)
        cls = jp.kernel("print(w.scene.canvas_class)").strip()
        sels = [".bench-baseline canvas", f".{cls} canvas"]
        for sel in sels:
            page.wait_for_selector(sel, timeout=120_000)
            if not jp.wait_for(lambda: (s := jp.canvas_stats(sel)) and s["count"] > 50, timeout=60):
                raise RuntimeError(f"{case}: nothing drawn on {sel}")
        page_copy = None
        if case in FIELD_CASES:  # issue 36: the page draws a field's held pictures once it holds its copy
            t0 = time.monotonic()
            readout = lambda: jp.kernel("print(w.readout.value)")  # noqa: E731
            if "turning" in readout() and jp.wait_for(lambda: "page draws" in readout(), timeout=120):
                page_copy = time.monotonic() - t0
        page.locator(sels[WIDGET]).scroll_into_view_if_needed()
        time.sleep(0.3)
        centres = []
        for sel in sels:
            box = page.locator(sel).bounding_box()
            if box["y"] < 0 or box["y"] + box["height"] > VIEWPORT["height"]:
                raise RuntimeError(f"{case}: canvas {sel} is not on screen ({box})")
            centres.append((box["x"] + box["width"] / 2, box["y"] + box["height"] / 2))
        info = page.evaluate(RECORDER, sels)

        def hover(g):
            page.evaluate("(g) => window.__bench.setTarget(g)", g)
            page.mouse.move(*centres[g], steps=2)

        hover(WIDGET)
        time.sleep(1.0)  # idle frames: the page's frame rate
        before = {g: kernel_read(jp, READ[g]) for g in (BASE, WIDGET)}

        # -- single presses, alternating canvases in random order --------------
        order = []
        for _ in range(args.presses):
            pair = [BASE, WIDGET]
            rng.shuffle(pair)
            order += pair
        ws_on(page)
        for g in order:
            hover(g)
            time.sleep(rng.uniform(0.1, 0.3))
            page.keyboard.press(rng.choice(PRESS_KEYS), delay=rng.uniform(*args.tap))
            try:
                page.wait_for_function("() => window.__bench.lastChange > window.__bench.lastKey",
                                       polling=10, timeout=5000)
            except Exception:
                pass  # counted as a miss
        time.sleep(0.5)
        page.evaluate("() => { window.__wsLog.on = false; }")
        ws_presses = page.evaluate("() => window.__wsLog.log.slice()")
        after_presses = {g: kernel_read(jp, READ[g]) for g in (BASE, WIDGET)}

        # -- holds: the widget, then (first notebook only) the baseline ----------
        holds = {}
        for g in ([WIDGET, BASE] if hold_baseline else [WIDGET]):
            hover(g)
            time.sleep(0.5)
            ws_on(page)
            page.keyboard.down(HOLD_KEY)
            time.sleep(args.hold)
            page.keyboard.up(HOLD_KEY)
            time.sleep(WATCH_AFTER + 0.2)
            page.evaluate("() => { window.__wsLog.on = false; }")
            holds[g] = {
                "ws": page.evaluate("() => window.__wsLog.log.slice()"),
                "out": page.evaluate("() => window.__wsLog.out.slice()"),
                "acks": page.evaluate("() => window.__wsLog.acks.slice()"),
                "kernel": kernel_read(jp, READ[g]),
            }
        rec = page.evaluate("() => { const B = window.__bench; B.stop();"
                            " return {t: B.t, h: B.h, g: B.g, cost: B.cost, keys: B.keys}; }")
        # -- the protocol's ceiling: the same hold with nothing drawn (every mesh hidden) --
        ceiling = None
        if args.ceiling:
            hover(WIDGET)
            ceiling = ceiling_hold(page, jp, args)
            hover(WIDGET)
        # -- one more hold of the widget under a Chromium trace: where the page's time goes --
        trace = None
        if args.trace:
            hover(WIDGET)
            time.sleep(0.5)
            trace = traced_hold(context, page, jp, args)
        page.__dict__["closing"] = True  # "Cannot send" from views of a kernel being shut down
        jp.shutdown_kernel()
    finally:
        page.close()
    out = analyse(case, info, rec, order, ws_presses, holds, before, after_presses, args, errors)
    out["trace"] = trace
    out["ceiling"] = ceiling
    out["page_copy_s"] = page_copy  # a field: seconds after its view drew until the page held its copy
    return out


def ceiling_hold(page, jp, args) -> dict:
    """Hold the key with every mesh hidden: what the update cycle delivers when drawing is free.

    The rows still travel at full size and the page still applies them and acknowledges each
    after a render (three.js then draws nothing): "drawn" acks per second over [keydown +
    FPS_SKIP, keyup] is the cycle's own ceiling, what a GPU that draws in no time would see.
    """
    jp.kernel("w.show_balls = w.show_bars = w.show_faces = False")
    n0 = kernel_read(jp, READ[WIDGET])["n_updates"]
    time.sleep(0.5)
    ws_on(page)
    t_down = page.evaluate("() => performance.now()")
    page.keyboard.down(HOLD_KEY)
    time.sleep(args.hold)
    t_up = page.evaluate("() => performance.now()")
    page.keyboard.up(HOLD_KEY)
    time.sleep(1.0)
    page.evaluate("() => { window.__wsLog.on = false; }")
    acks = page.evaluate("() => window.__wsLog.acks.slice()")
    ws = page.evaluate("() => window.__wsLog.log.slice()")
    n1 = kernel_read(jp, READ[WIDGET])["n_updates"]
    jp.kernel("w.show_balls = w.show_bars = w.show_faces = True")
    w0 = t_down + 1000 * FPS_SKIP
    inside = [a for a in acks if w0 <= a <= t_up]
    arrivals = sorted(m[0] for m in ws if m[2] and w0 <= m[0] <= t_up)
    return {
        "acks_per_s": len(inside) / ((t_up - w0) / 1000) if t_up > w0 else math.nan,
        "interval_ms": median([b - a for a, b in zip(arrivals, arrivals[1:])]),
        "updates": n1 - n0,
        "update_msg_bytes": median([m[1] for m in ws if m[2]]),
    }


TRACE_CATEGORIES = ["toplevel", "devtools.timeline", "disabled-by-default-devtools.timeline", "gpu", "viz"]
#: Renderer main-thread work inside a task, by trace event name (the rest of a task counts as script).
LAYOUT_EVENTS = {"UpdateLayoutTree", "Layout", "PrePaint", "Paint", "Layerize", "UpdateLayer",
                 "RecalculateStyles", "ScheduleStyleRecalculation"}


def traced_hold(context, page, jp, args) -> dict | None:
    """Hold the key on the widget under a Chromium trace; where each thread's time went.

    The trace (CDP ``Tracing``, categories ``TRACE_CATEGORIES``) covers every process.
    Over [keydown + FPS_SKIP, keyup] it sums, per thread, the time inside top-level tasks
    (busy), and splits the page's main thread by what each task did: a kernel message
    (WebSocket ``message``: parse, deserialise, apply to the models), an animation frame
    (pythreejs' render of the scene with three.js, the companion), style/layout/paint (the
    readout's DOM), the benchmark's own read-back (its MessagePort task), the rest; idle
    is the remainder.  Figures are fractions of wall time and ms per update (fraction x
    the hold's median interval between update arrivals).
    """
    cdp = context.new_cdp_session(page)
    done: dict = {}
    cdp.on("Tracing.tracingComplete", lambda ev: done.update(ev))
    ws_on(page)
    cdp.send("Tracing.start", {"traceConfig": {"includedCategories": TRACE_CATEGORIES},
                               "transferMode": "ReturnAsStream"})
    if args.profile:
        cdp.send("Profiler.enable")
        cdp.send("Profiler.setSamplingInterval", {"interval": 200})
        cdp.send("Profiler.start")
    page.keyboard.down(HOLD_KEY)
    time.sleep(args.hold)
    page.keyboard.up(HOLD_KEY)
    time.sleep(0.3)
    profile = cdp.send("Profiler.stop")["profile"] if args.profile else None
    cdp.send("Tracing.end")
    for _ in range(600):
        if done:
            break
        page.wait_for_timeout(50)
    page.evaluate("() => { window.__wsLog.on = false; }")
    ws = page.evaluate("() => window.__wsLog.log.slice()")
    if not done.get("stream"):
        return None
    chunks = []
    while True:
        r = cdp.send("IO.read", {"handle": done["stream"], "size": 1 << 22})
        data = r.get("data", "")
        chunks.append(__import__("base64").b64decode(data).decode() if r.get("base64Encoded") else data)
        if r.get("eof"):
            break
    cdp.send("IO.close", {"handle": done["stream"]})
    cdp.detach()
    text = "".join(chunks)
    if args.trace_dir:
        pathlib.Path(args.trace_dir).mkdir(parents=True, exist_ok=True)
        (pathlib.Path(args.trace_dir) / f"trace-{int(time.time() * 1000)}.json").write_text(text)
    doc = json.loads(text)
    events = doc["traceEvents"] if isinstance(doc, dict) else doc
    arrivals = sorted(m[0] for m in ws if m[2])
    interval = median([b - a for a, b in zip(arrivals, arrivals[1:])])
    out = trace_breakdown(events, interval)
    if profile:
        out["js_self_ms"] = js_self_time(profile)
    return out


def js_self_time(profile: dict, top: int = 25) -> list:
    """The page's JavaScript by self time over the hold (CDP Profiler samples): [(ms, function, script)]."""
    nodes = {n["id"]: n for n in profile["nodes"]}
    dt: dict = {}
    for sid, d in zip(profile.get("samples", []), profile.get("timeDeltas", [])):
        dt[sid] = dt.get(sid, 0) + d
    agg: dict = {}
    for nid, us in dt.items():
        cf = nodes[nid]["callFrame"]
        key = (cf.get("functionName") or "(anonymous)", cf.get("url", "").rsplit("/", 1)[-1].split("?")[0]
               + f":{cf.get('lineNumber', -1) + 1}:{cf.get('columnNumber', -1) + 1}")
        agg[key] = agg.get(key, 0) + us
    return [(round(us / 1000, 1), f, u) for (f, u), us in sorted(agg.items(), key=lambda kv: -kv[1])[:top]]


def trace_breakdown(events: list, interval_ms: float) -> dict:
    """Per-thread busy time and the page main thread's split (see `traced_hold`)."""
    names, procs = {}, {}
    for e in events:
        if e.get("ph") == "M" and e.get("name") == "thread_name":
            names[(e["pid"], e["tid"])] = e["args"]["name"]
        elif e.get("ph") == "M" and e.get("name") == "process_name":
            procs[e["pid"]] = e["args"]["name"]
    keys = sorted((e["ts"], e["args"]["data"]["type"]) for e in events
                  if e.get("name") == "EventDispatch" and e.get("args", {}).get("data", {}).get("type")
                  in ("keydown", "keyup"))
    downs = [t for t, k in keys if k == "keydown"]
    ups = [t for t, k in keys if k == "keyup"]
    if not downs or not ups:
        return {"error": "no key events in the trace"}
    lo, hi = downs[0] + 1e6 * FPS_SKIP, ups[-1]
    span = hi - lo
    if span <= 0:
        return {"error": "hold too short"}
    tasks: dict = {}
    inner: dict = {}
    for e in events:
        if e.get("ph") != "X" or "dur" not in e:
            continue
        key = (e["pid"], e["tid"])
        if "toplevel" in e.get("cat", "") and e["name"] in ("ThreadControllerImpl::RunTask", "RunTask"):
            tasks.setdefault(key, []).append((e["ts"], e["ts"] + e["dur"]))
        else:
            inner.setdefault(key, []).append(e)

    def clip(a, b):
        return max(0.0, min(b, hi) - max(a, lo))

    def busy(spans):  # union of top-level spans inside the window (nested RunTasks happen)
        total, end = 0.0, -math.inf
        for a, b in sorted(spans):
            if b <= end:
                continue
            a = max(a, end)
            total += clip(a, b)
            end = b
        return total

    threads = {}
    for key, spans in tasks.items():
        label = f"{procs.get(key[0], '?')}: {names.get(key, '?')}"
        threads[label] = threads.get(label, 0.0) + busy(spans)
    # the page: the busiest renderer main thread in the window (the page under test)
    mains = [k for k in tasks if names.get(k) == "CrRendererMain"]
    split, task_counts = {}, {}
    if mains:
        main = max(mains, key=lambda k: busy(tasks[k]))
        evs = sorted(inner.get(main, []), key=lambda e: e["ts"])
        starts = [e["ts"] for e in evs]
        cats = {"kernel message (parse, deserialise, apply)": 0.0, "animation frame (three.js render)": 0.0,
                "style, layout, paint (readout DOM)": 0.0, "benchmark read-back": 0.0, "other tasks": 0.0}
        counts: dict = {}
        end_prev = -math.inf
        for a, b in sorted(tasks[main]):
            if b <= end_prev or clip(a, b) <= 0:
                end_prev = max(end_prev, b)
                continue
            end_prev = b
            i, j = bisect.bisect_left(starts, a), bisect.bisect_right(starts, b)
            within = evs[i:j]
            lay = sum(clip(e["ts"], e["ts"] + e["dur"]) for e in within if e["name"] in LAYOUT_EVENTS)
            rest = max(0.0, clip(a, b) - lay)
            cats["style, layout, paint (readout DOM)"] += lay
            kinds = {e["name"] for e in within}
            fns = {str(e.get("args", {}).get("data", {}).get("functionName", "")) for e in within
                   if e["name"] == "FunctionCall"}
            if "FireAnimationFrame" in kinds:
                kind = "animation frame (three.js render)"
            elif kinds & {"CommandBufferHelper::Finish", "CommandBufferProxyImpl::WaitForGetOffset"}:
                kind = "benchmark read-back"  # drawImage + getImageData of the WebGL canvas: a GPU sync
            elif fns & {"_onWSMessage", "onMessage"}:  # the benchmark's WebSocket hook runs first on each
                kind = "kernel message (parse, deserialise, apply)"
            else:
                kind = "other tasks"
            cats[kind] += rest
            counts[kind] = counts.get(kind, 0) + 1
        total = sum(cats.values())
        cats["idle"] = max(0.0, span - total)
        split = cats
        task_counts = counts
    per_update = (lambda us: us / span * interval_ms) if interval_ms == interval_ms else (lambda us: math.nan)
    return {
        "window_ms": span / 1000,
        "interval_ms": interval_ms,
        "threads": {k: {"share": v / span, "ms_per_update": per_update(v)}
                    for k, v in sorted(threads.items(), key=lambda kv: -kv[1]) if v / span >= 0.01},
        "page": {k: {"share": v / span, "ms_per_update": per_update(v), "tasks_per_s": task_counts.get(k, 0) / span * 1e6}
                 for k, v in split.items()},
    }


def kernel_read(jp: JupyterPage, code: str):
    """Run ``code`` (it prints one JSON document) in the kernel; the parsed document."""
    return json.loads(jp.kernel(code))


# -- analysis -----------------------------------------------------------------


def _changes(rec, g):
    """Times of frames of canvas g whose hash differs from the previous frame of the same canvas."""
    out = []
    t, h, gs = rec["t"], rec["h"], rec["g"]
    for i in range(1, len(t)):
        if gs[i] == g and gs[i - 1] == g and h[i] != h[i - 1]:
            out.append(t[i])
    return out


def _first_after(xs, x, slack=0.0):
    """The first element of sorted ``xs`` that is >= x - slack (None if none)."""
    i = bisect.bisect_left(xs, x - slack)
    return xs[i] if i < len(xs) else None


def _kernel_stamps(kernel_read, origin):
    """The probe's epoch stamps as page times (ms since the page's timeOrigin)."""
    st = (kernel_read or {}).get("stamps") or {}
    conv = lambda e: 1000.0 * e - origin  # noqa: E731
    renders = sorted((conv(a), conv(b), main) for a, b, main in st.get("renders", []))
    return {
        "keys": sorted(conv(x) for x in st.get("keys", [])),
        "acks": sorted(conv(x) for x in st.get("acks", [])),
        "render_start": [r[0] for r in renders],
        "renders": renders,
    }


SLACK = 2.0  # ms: page and kernel clocks are the same wall clock, read in different processes


def _press_latencies(rec, downs, order, ws, g, ks):
    t_all, h_all, g_all = rec["t"], rec["h"], rec["g"]
    updates = sorted(m[0] for m in ws if m[2])
    out = {k: [] for k in ("latency_ms", "key_msg_ms", "msg_px_ms", "key_kernel_ms", "kernel_handling_ms",
                           "sent_arrival_ms")}
    misses = 0
    for i, (tk, gi) in enumerate(zip(downs, order)):
        if gi != g:
            continue
        limit = downs[i + 1] if i + 1 < len(downs) else math.inf
        h0, hit = None, None
        for tf, hf, gf in zip(t_all, h_all, g_all):
            if gf != g:
                continue
            if tf <= tk:
                h0 = hf
            elif tf >= limit:
                break
            elif h0 is not None and hf != h0:
                hit = tf
                break
        if hit is None:
            misses += 1
            continue
        out["latency_ms"].append(hit - tk)
        msg = _first_after(updates, tk)
        if msg is None or msg > hit:
            continue
        out["key_msg_ms"].append(msg - tk)
        out["msg_px_ms"].append(hit - msg)
        if ks and ks["keys"]:
            kk = _first_after(ks["keys"], tk, SLACK)
            j = bisect.bisect_left(ks["render_start"], kk - SLACK) if kk is not None else None
            if kk is not None and kk < msg and j is not None and j < len(ks["renders"]):
                r_end = ks["renders"][j][1]
                if r_end <= msg + SLACK:
                    out["key_kernel_ms"].append(kk - tk)
                    out["kernel_handling_ms"].append(r_end - kk)
                    out["sent_arrival_ms"].append(msg - r_end)
    out["misses"] = misses
    return out


def _hold(rec, g, t_down, t_up, hold, n_before, ks):
    changes = _changes(rec, g)
    w0 = t_down + 1000 * FPS_SKIP
    held = [x for x in changes if w0 <= x <= t_up]
    after = [x for x in changes if t_up < x <= t_up + 1000 * WATCH_AFTER]
    ws, acks = hold["ws"], hold["acks"]
    arrivals = sorted(m[0] for m in ws if m[2] and w0 <= m[0] <= t_up)
    acks_in = sorted(a for a in acks if w0 <= a <= t_up)
    cyc = {k: [] for k in ("page_ms", "ack_kernel_ms", "kernel_wait_ms", "compute_ms", "sent_arrival_ms")}
    for u in arrivals:  # arrival -> the page's "drawn" ack for it
        a = _first_after(acks_in, u)
        if a is not None:
            cyc["page_ms"].append(a - u)
    n_ticker = n_renders = 0
    if ks:
        for a in acks_in:  # ack sent -> reaches the widget -> next update computed -> arrives
            ka = _first_after(ks["acks"], a, SLACK)
            if ka is None:
                continue
            cyc["ack_kernel_ms"].append(ka - a)
            j = bisect.bisect_left(ks["render_start"], ka - 0.5)
            if j < len(ks["renders"]) and ks["renders"][j][0] <= t_up:
                cyc["kernel_wait_ms"].append(max(0.0, ks["renders"][j][0] - ka))
        for r0, r1, main in ks["renders"]:
            if w0 <= r0 <= t_up:
                n_renders += 1
                n_ticker += not main
                cyc["compute_ms"].append(r1 - r0)
                u = _first_after(arrivals, r1)
                if u is not None:
                    cyc["sent_arrival_ms"].append(u - r1)
    k = hold["kernel"]
    up = k.get("up") or {}
    n_updates = k["n_updates"] - n_before
    window = [m for m in ws if t_down <= m[0] <= t_up + 1000 * WATCH_AFTER]
    return {
        "fps": len(held) / ((t_up - w0) / 1000) if t_up > w0 else math.nan,
        "frames": len([x for x in changes if t_down <= x <= t_up]),
        "seconds": (t_up - t_down) / 1000,
        "updates": n_updates,
        "interval_ms": median([b - a for a, b in zip(arrivals, arrivals[1:])]),
        **{key: median(v) for key, v in cyc.items()},
        "ticker_share": n_ticker / n_renders if n_renders else math.nan,
        "after_frames": len(after),
        "settle_ms": (after[-1] - t_up) if after else 0.0,
        "in_flight_at_up": up.get("in_flight"),
        "max_in_flight": up.get("max_in_flight"),
        "moved_after_up": bool(up) and up.get("R") != k.get("final"),
        "sent_after_up": k["n_updates"] - up["n"] if up else None,
        "bytes_per_update": sum(m[1] for m in window) / n_updates if n_updates else math.nan,
        "update_msg_bytes": median([m[1] for m in window if m[2]]),
        "msgs_per_update": len(window) / n_updates if n_updates else math.nan,
        "sent_kinds_per_update": {k: round(v / n_updates, 2) for k, v in sorted(
            __import__("collections").Counter(m[1] for m in hold.get("out", [])
                                              if t_down <= m[0] <= t_up + 1000 * WATCH_AFTER).items())}
        if n_updates else {},
        "msg_kinds_per_update": {k: round(v / n_updates, 2) for k, v in sorted(
            __import__("collections").Counter(m[3] if len(m) > 3 else "?" for m in window).items())}
        if n_updates else {},
    }


def analyse(case, info, rec, order, ws_presses, holds, before, after_presses, args, errors) -> dict:
    downs = [k[1] for k in rec["keys"] if k[0] == "keydown" and not k[3]]
    ups = [k[1] for k in rec["keys"] if k[0] == "keyup"]
    n = len(order)
    origin = (info or {}).get("timeOrigin", 0.0)
    ks = _kernel_stamps(holds[WIDGET]["kernel"], origin)
    out = {"case": case, "canvas": info, "page_errors": errors}
    for g, label in ((BASE, "base"), (WIDGET, "widget")):
        side = _press_latencies(rec, downs[:n], order, ws_presses, g, ks if g == WIDGET else None)
        k0, k1 = before[g], after_presses[g]
        side.update(presses=order.count(g), kernel_ms=k1["kernel_ms"][len(k0["kernel_ms"]):],
                    press_updates=k1["n_updates"] - k0["n_updates"], hold=None)
        out[label] = side
    hold_order = [WIDGET, BASE][: len(holds)]
    for j, g in enumerate(hold_order):
        label = "widget" if g == WIDGET else "base"
        out[label]["hold"] = _hold(rec, g, downs[n + j], ups[n + j], holds[g], after_presses[g]["n_updates"],
                                   ks if g == WIDGET else None)
    first = downs[0] if downs else math.inf
    idle = [x for x in rec["t"] if x < first]
    out["idle_fps"] = (len(idle) - 1) / ((idle[-1] - idle[0]) / 1000) if len(idle) > 2 else math.nan
    out["readback_ms"] = median(rec["cost"])
    final = holds[WIDGET]["kernel"]
    out["widget_kernel_final"] = {k: final.get(k) for k in ("acks", "timeouts", "capacity")}
    return out


# -- report -------------------------------------------------------------------


def fmt(x, nd=0):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def fmt_opt(x):
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return str(x)


def _spread(lat, misses):
    s = f"{fmt(median(lat))} ({fmt(pct(lat, 0.1))}–{fmt(pct(lat, 0.9))})"
    return s + (f", {misses} missed" if misses else "")


def report(results: dict, meta: dict) -> str:
    ok = lambda b: "ok" if b else "MISSED"  # noqa: E731
    base_lat = [x for r in results.values() for x in r["base"]["latency_ms"]]
    base_miss = sum(r["base"]["misses"] for r in results.values())
    base_hold = next((r["base"]["hold"] for r in results.values() if r["base"]["hold"]), None)
    lines = [
        "| case | key→px median (p10–p90) ms | mean ± std ms | paired baseline median / mean ms "
        "| excess mean (median) ms | target | ok | held fps | target | ok "
        "| after release: frames, last at | ok | bytes/update (update msg) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    bh = base_hold or {}
    lines.append(
        f"| baseline (tetrahedron, all pairings) | {_spread(base_lat, base_miss)} "
        f"| {fmt(mean(base_lat))} ± {fmt(statistics.stdev(base_lat) if len(base_lat) > 1 else math.nan)} | — | — "
        f"| — | — | {fmt(bh.get('fps'), 1)} (30 Hz push) | — | — "
        f"| {bh.get('after_frames', '–')}, {fmt(bh.get('settle_ms'))} ms | — "
        f"| {fmt(bh.get('bytes_per_update'))} ({fmt(bh.get('update_msg_bytes'))}) |"
    )
    for case, r in results.items():
        w, b = r["widget"], r["base"]
        lat, blat = w["latency_ms"], b["latency_ms"]
        lat_target, fps_target, fps_text = targets_for(case, bh.get("fps", math.nan))
        excess, excess_med = mean(lat) - mean(blat), median(lat) - median(blat)
        h = w["hold"]
        lat_ok = excess <= lat_target and not w["misses"]
        fps_ok = h["fps"] >= fps_target
        rel_ok = release_ok(h)
        after = f"{h['after_frames']}, {fmt(h['settle_ms'])} ms" + (", state moved after keyup" if h["moved_after_up"] else "")
        std = statistics.stdev(lat) if len(lat) > 1 else math.nan
        lines.append(
            f"| {case} | {_spread(lat, w['misses'])} | {fmt(mean(lat))} ± {fmt(std)} "
            f"| {fmt(median(blat))} / {fmt(mean(blat))} | {excess:+.0f} ({excess_med:+.0f}) | ≤ {lat_target:.1f} "
            f"| {ok(lat_ok)} | {fmt(h['fps'], 1)} | {fps_text} | {ok(fps_ok)} | {after} | {ok(rel_ok)} "
            f"| {fmt(h['bytes_per_update'])} ({fmt(h['update_msg_bytes'])}) |"
        )
    prof = [
        "",
        "Single presses, medians (ms): key→msg = page → kernel → page; msg→px = deserialise + frame + draw + "
        "read-back. Widget only (kernel stamps): key→kernel, kernel handling (key in → update computed and "
        "sent), sent→arrival.",
        "",
        "| case | key→px | key→msg | msg→px | key→kernel | kernel handling | sent→arrival | kernel per update "
        "| idle page fps | read-back per frame |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for case, r in results.items():
        for label, side in ((f"baseline ({case} nb)", r["base"]), (case, r["widget"])):
            prof.append(
                f"| {label} | {fmt(median(side['latency_ms']), 1)} | {fmt(median(side['key_msg_ms']), 1)} "
                f"| {fmt(median(side['msg_px_ms']), 1)} | {fmt(median(side['key_kernel_ms']), 1)} "
                f"| {fmt(median(side['kernel_handling_ms']), 1)} | {fmt(median(side['sent_arrival_ms']), 1)} "
                f"| {fmt(median(side['kernel_ms']), 2)} | {fmt(r['idle_fps'])} | {fmt(r['readback_ms'], 1)} |"
            )
    prof += [
        "",
        "Held key, one update's cycle, medians (ms): arrival → \"drawn\" ack sent (page: deserialise, frame, "
        "draw, one more frame) → ack reaches the widget → next update starts (waits for a tick if no step "
        "is pending) → computed → arrives.",
        "",
        "| case | updates / hold | update→update | arrival→ack (page) | ack→kernel | kernel wait | compute "
        "| sent→arrival | from ticker thread | WS msgs/update | in flight at keyup | sent after keyup |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for case, r in results.items():
        for label, side in ((f"baseline ({case} nb)", r["base"]), (case, r["widget"])):
            h = side["hold"]
            if not h:
                continue
            share = h.get("ticker_share")
            prof.append(
                f"| {label} | {h['updates']} / {fmt(h['seconds'], 2)} s | {fmt(h['interval_ms'], 1)} "
                f"| {fmt(h['page_ms'], 1)} | {fmt(h['ack_kernel_ms'], 1)} | {fmt(h['kernel_wait_ms'], 1)} "
                f"| {fmt(h['compute_ms'], 1)} | {fmt(h['sent_arrival_ms'], 1)} "
                f"| {'–' if share is None or math.isnan(share) else f'{100 * share:.0f} %'} "
                f"| {fmt(h['msgs_per_update'], 1)} | {fmt_opt(h['in_flight_at_up'])} | {fmt_opt(h['sent_after_up'])} |"
            )
    if any(r.get("ceiling") for r in results.values()):
        prof += [
            "",
            "The cycle's ceiling: the same hold with every mesh hidden (rows still sent in full, applied, "
            "rendered as nothing, acknowledged) -- updates drawn per second when the draw costs nothing, "
            "what a GPU would see, against the held frame rate with the draw.",
            "",
            "| case | held fps (drawn) | ceiling: acks/s, nothing drawn | update→update ms | update msg bytes |",
            "|---|---|---|---|---|",
        ]
        for case, r in results.items():
            c = r.get("ceiling")
            if c:
                prof.append(f"| {case} | {fmt(r['widget']['hold']['fps'], 1)} | {fmt(c['acks_per_s'], 1)} "
                            f"| {fmt(c['interval_ms'], 1)} | {fmt(c['update_msg_bytes'])} |")
    traced = {case: r["trace"] for case, r in results.items() if r.get("trace") and "page" in r["trace"]}
    if traced:
        cats = list(next(iter(traced.values()))["page"])
        prof += [
            "",
            "Where the page's time goes while '4' is held (one more hold under a Chromium trace; the trace "
            "itself slows the page): the page's main thread per update (ms; share of wall time), split by "
            "task, and the other busy threads. ms per update = share × the traced hold's median interval "
            "between update arrivals.",
            "",
            "| case | interval | " + " | ".join(cats) + " |",
            "|---|---|" + "---|" * len(cats),
        ]
        for case, t in traced.items():
            prof.append(f"| {case} | {fmt(t['interval_ms'], 1)} | " + " | ".join(
                f"{fmt(t['page'][k]['ms_per_update'], 1)} ({100 * t['page'][k]['share']:.0f} %)" for k in cats) + " |")
        prof += ["", "| case | busy threads: ms per update (share of wall time) |", "|---|---|"]
        for case, t in traced.items():
            prof.append(f"| {case} | " + "; ".join(
                f"{k} {fmt(v['ms_per_update'], 1)} ({100 * v['share']:.0f} %)" for k, v in list(t["threads"].items())[:6])
                + " |")
        for case, t in traced.items():
            if t.get("js_self_ms"):
                top = [x for x in t["js_self_ms"] if x[1] not in ("(program)", "(idle)")][:8]
                prof.append(f"\n{case}, page JavaScript by self time over the traced hold (ms): "
                            + "; ".join(f"{f} [{u}] {ms}" for ms, f, u in top))
    kinds = {case: r["widget"]["hold"].get("msg_kinds_per_update") for case, r in results.items()}
    if any(kinds.values()):
        prof += ["", "Kernel WebSocket messages the page received per update while '4' was held, by kind "
                 "(msg_type[:method][:execution_state]):", ""]
        for case, k in kinds.items():
            if k:
                sent = results[case]["widget"]["hold"].get("sent_kinds_per_update") or {}
                prof.append(f"- {case}: " + ", ".join(f"{n} {v}" for n, v in k.items())
                            + "; sent by the page: " + ", ".join(f"{n} {v}" for n, v in sent.items()))
    prof += renderings_table(results, bh.get("fps", math.nan))
    m = meta
    note = [
        "",
        f"Machine: {m['cpus']} CPUs ({m['cpu']})"
        + (f", emulating a slower machine: {m['emulation']}" if m.get("emulation") else "")
        + ", load average (1/5/15 min) "
        f"{' '.join(f'{x:.1f}' for x in m['load_before'])} before, "
        f"{' '.join(f'{x:.1f}' for x in m['load_after'])} after; {m['chromium']}, headless, WebGL "
        f"{m.get('renderer') or '?'}; canvas {m.get('canvas')}; code: {m['code']}; "
        f"server: {m['server']}; {m['presses']} presses per canvas per notebook, taps "
        f"{m['tap'][0]:g}–{m['tap'][1]:g} ms, hold {m['hold']} s; run took {m['elapsed']:.0f} s. "
        "Shared, noisy machine: compare medians across runs.",
    ]
    errs = [f"{c}: {e}" for c, r in results.items() for e in r["page_errors"]]
    if errs:
        note.append("Page errors: " + "; ".join(errs[:5]))
    return "\n".join(lines + prof + note)


def renderings_table(results: dict, base_fps: float) -> list:
    """Issue 21's table, when a field is measured in several renderings (``FIELD_RENDERING``): held
    fps, its ratio to the baseline's (same run), the kernel's held step and the bytes per update."""
    cases = [c for c in results if c in FIELD_RENDERING]
    if not cases:
        return []
    out = ["", f"Issue 21, a 64⁴ field in each rendering while '4' is held (baseline held fps {fmt(base_fps, 1)}, "
               "30 Hz push): distinct frames/s, ratio to the baseline, updates per hold, median interval between "
               "update arrivals and the page's part of it (arrival → \"drawn\" ack: deserialise, upload, draw), "
               "every byte the page received per update (the update message alone, median)"
               + (f"; rays sampled every {VOLUME_STEP:g} grid spacings (--volume-step)" if VOLUME_STEP else "")
               + ".", "",
           "| case | held fps | ÷ baseline | target | ok | updates / hold | update→update ms | arrival→ack (page) ms "
           "| bytes/update | update msg bytes | page's copy after (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        h = results[case]["widget"]["hold"]
        copy = results[case].get("page_copy_s")
        ratio = h["fps"] / base_fps if base_fps else math.nan
        goal = RATIO_FPS.get(case)
        out.append(f"| {case} | {fmt(h['fps'], 1)} | {fmt(ratio, 2)} | {f'≥ {goal:g}×' if goal else '—'} "
                   f"| {('ok' if ratio >= goal else 'MISSED') if goal else '—'} "
                   f"| {h['updates']} / {fmt(h['seconds'], 2)} s "
                   f"| {fmt(h['interval_ms'], 1)} | {fmt(h['page_ms'], 1)} "
                   f"| {fmt(h['bytes_per_update'])} | {fmt(h['update_msg_bytes'])} "
                   f"| {'—' if copy is None else fmt(copy, 1)} |")
    return out


def renderings_summary(runs: list[dict], base: list[float]) -> list:
    """Issue 21's table over the runs: held fps, ratio and bytes per update per run, their medians."""
    cases = [c for c in FIELD_RENDERING if any(c in r for r in runs)]
    if not cases:
        return []
    out = ["", "Issue 21 over the runs (a 64⁴ field held on '4'; the same run's baseline):", "",
           "| case | held fps, per run | median | ÷ baseline, per run | median | target | ok "
           "| update msg bytes, median over runs | bytes/update (all WS), median over runs |",
           "|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        hs = [(r[case]["widget"]["hold"], b) for r, b in zip(runs, base) if case in r]
        fps = [h["fps"] for h, _ in hs]
        ratios = [h["fps"] / b for h, b in hs]
        goal = RATIO_FPS.get(case)
        out.append(f"| {case} | {', '.join(fmt(x, 1) for x in fps)} | {fmt(median(fps), 1)} "
                   f"| {', '.join(fmt(x, 2) for x in ratios)} | {fmt(median(ratios), 2)} "
                   f"| {f'≥ {goal:g}×' if goal else '—'} "
                   f"| {('ok' if median(ratios) >= goal else 'MISSED') if goal else '—'} "
                   f"| {fmt(median([h['update_msg_bytes'] for h, _ in hs]))} "
                   f"| {fmt(median([h['bytes_per_update'] for h, _ in hs]))} |")
    return out


# -- main ---------------------------------------------------------------------


def verdicts(case: str, r: dict) -> dict:
    """The run's figures for the targets: excess mean (ms), held fps, release ok."""
    w, b = r["widget"], r["base"]
    h = w["hold"]
    return {
        "excess": mean(w["latency_ms"]) - mean(b["latency_ms"]),
        "misses": w["misses"],
        "fps": h["fps"],
        "base_fps": r.get("base_fps", math.nan),
        "release_ok": release_ok(h),
    }


def summary(runs: list[dict]) -> str:
    """Every run's excess and held fps per case, their medians and the targets."""
    ok = lambda b: "ok" if b else "MISSED"  # noqa: E731
    n = len(runs)
    cases = [c for c in ALL_CASES if any(c in r for r in runs)]
    lines = [
        f"Over {n} runs (each a full measurement as above): mean key→pixel excess over the paired "
        "baseline and distinct frames per second while '4' is held, per run and their median.",
        "",
        "| case | excess ms, per run | median | target | ok | held fps, per run | median | target | ok "
        "| release ok in every run |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    base = [median([v["base_fps"] for v in [verdicts(c, r[c]) for c in r]]) for r in runs]
    lines.insert(2, f"Targets: {TARGETS[TARGET]['text']}. Baseline held fps per run: "
                    f"{', '.join(fmt(b, 1) for b in base)}; median {fmt(median(base), 1)}.\n")
    lines[3] = lines[3].replace("| release ok", "| held / baseline, per run | median | release ok")
    lines[4] = "|---|---|---|---|---|---|---|---|---|---|---|---|"
    for case in cases:
        vs = [verdicts(case, r[case]) for r in runs if case in r]
        lat_target, fps_target, fps_text = targets_for(case, median(base))
        ex = [v["excess"] for v in vs]
        fps = [v["fps"] for v in vs]
        ratios = [v["fps"] / v["base_fps"] for v in vs]
        missed = sum(v["misses"] for v in vs)
        t = TARGETS[TARGET]
        if case in RATIO_FPS:
            fps_ok = median(ratios) >= RATIO_FPS[case]
        elif case in ABSOLUTE_FPS or not t["ratio"]:
            fps_ok = median(fps) >= fps_target
        else:
            fps_ok = median(ratios) >= t["fps"][case in LARGE]
        lines.append(
            f"| {case} | {', '.join(f'{round(x):+d}' for x in ex)} | {round(median(ex)):+d} | ≤ {lat_target:.1f} "
            f"| {ok(median(ex) <= lat_target and not missed)} | {', '.join(fmt(x, 1) for x in fps)} "
            f"| {fmt(median(fps), 1)} | {fps_text} | {ok(fps_ok)} "
            f"| {', '.join(fmt(x, 2) for x in ratios)} | {fmt(median(ratios), 2)} "
            f"| {'yes' if all(v['release_ok'] for v in vs) else 'no'} |"
        )
    base_per_run = [next((v["base_fps"] for v in [verdicts(c, r[c]) for c in r]), math.nan) for r in runs]
    return "\n".join(lines + renderings_summary(runs, base_per_run))


def measure(args, rng: random.Random, rtt: float = 0.0) -> tuple[dict, dict, dict]:
    """One full measurement: a server, a browser, every case.  (results, meta, failed).  ``rtt`` (ms):
    the page sees the server through a proxy holding every byte for half of it each way."""
    from playwright.sync_api import sync_playwright

    started = time.monotonic()
    meta: dict = {"presses": args.presses, "hold": args.hold, "cpus": len(os.sched_getaffinity(0)), "cpu": cpu_name(),
                  "emulation": (f"pinned to CPU {args.cpus}" + (f" with {args.busy} busy-loop process(es)"
                                                                 if args.busy else "")) if args.cpus else None,
                  "load_before": os.getloadavg(), "code": working_tree_description()}
    chromium = find_chromium()
    version = subprocess.run([chromium, "--version"], capture_output=True, text=True).stdout.strip()
    meta["chromium"] = version.split(" built")[0] or chromium
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="rot4d-latency-"))
    server = JupyterServer("lab", tmp / "server")
    (server.root / "rot4d_bench_helpers.py").write_text(HELPERS)
    pythonpath = [server.env.get("PYTHONPATH")]
    if args.nagle:
        (pathlib.Path(server.env["JUPYTER_CONFIG_DIR"]) / "jupyter_server_config.json").write_text(
            json.dumps(NAGLE_CONFIG))
    meta["tap"] = args.tap
    if args.rev:
        meta["code"] = export_revision(args.rev, tmp / "src")
        pythonpath.insert(0, str(tmp / "src"))
    if any(pythonpath):
        server.env["PYTHONPATH"] = os.pathsep.join(filter(None, pythonpath))
    results: dict = {}
    failed: dict = {}
    meta["rtt_ms"] = rtt
    remote = None
    try:
        server.start()
        remote = RemoteServer(server, rtt) if rtt else None
        server.log.flush()
        nodelay = "TCP_NODELAY" in pathlib.Path(server.log.name).read_text()
        meta["server"] = ("rot4d_widget server extension: TCP_NODELAY on kernel WebSockets" if nodelay
                          else "jupyter_server defaults (Nagle's algorithm on)")
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                str(tmp / "chromium-profile"), executable_path=chromium, headless=True,
                args=CHROMIUM_FLAGS, viewport=VIEWPORT,
            )
            context.add_init_script(WS_HOOK)
            if not args.console_debug:
                context.add_init_script(QUIET_DEBUG)
            try:
                for case in args.case_list:
                    t0 = time.monotonic()
                    try:
                        r = run_case(context, remote or server, case, args, rng, hold_baseline=not results)
                    except Exception as exc:  # report the others; say which failed and why
                        failed[case] = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
                        print(f"{case}: FAILED {failed[case]}", file=sys.stderr, flush=True)
                        continue
                    results[case] = r
                    c = r["canvas"] or {}
                    meta.setdefault("renderer", c.get("renderer"))
                    meta.setdefault("canvas", f"{c.get('width')}×{c.get('height')} px, dpr {c.get('dpr')}")
                    print(f"{case}: key→px median {fmt(median(r['widget']['latency_ms']))} ms "
                          f"(paired baseline {fmt(median(r['base']['latency_ms']))} ms), "
                          f"held {fmt(r['widget']['hold']['fps'], 1)} fps, "
                          f"{r['widget']['hold']['after_frames']} frames after release "
                          f"[{time.monotonic() - t0:.0f} s]", file=sys.stderr, flush=True)
            finally:
                context.close()
    finally:
        if remote is not None:
            remote.stop()
        server.stop()
        if args.keep:
            print(f"kept {tmp}", file=sys.stderr)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    base_fps = next((r["base"]["hold"]["fps"] for r in results.values() if r["base"]["hold"]), math.nan)
    for r in results.values():
        r["base_fps"] = base_fps
    meta["load_after"] = os.getloadavg()
    meta["elapsed"] = time.monotonic() - started
    return results, meta, failed


def rtt_table(by_rtt: dict) -> str:
    """Per round trip and case: the held frame rate as a ratio to the same run's baseline (median
    over runs), that ratio against the same case's at the smallest round trip, and the tap's key ->
    first changed pixel (median of the presses, median over runs) beside the baseline's."""
    rtts = sorted(by_rtt)
    cases = sorted({c for runs in by_rtt.values() for r in runs for c in r}, key=str)

    def ratio(r):
        f, b = r["widget"]["hold"].get("fps") if r["widget"]["hold"] else None, r.get("base_fps")
        return f / b if f and b and b == b else math.nan

    def med(xs):
        xs = [x for x in xs if x == x]
        return statistics.median(xs) if xs else math.nan

    lines = ["| round trip ms | baseline held fps | " + " | ".join(f"{c} held (x base) | {c} tap ms" for c in cases)
             + " |", "|" + "---|" * (2 + 2 * len(cases))]
    first = {}
    for rtt in rtts:
        runs = by_rtt[rtt]
        base = med([r.get("base_fps", math.nan) for res in runs for r in res.values()][:1] or [math.nan])
        row = [f"{rtt:g}", f"{base:.1f}"]
        for c in cases:
            rs = [res[c] for res in runs if c in res]
            x = med([ratio(r) for r in rs])
            first.setdefault(c, x)
            tap = med([median(r["widget"]["latency_ms"]) for r in rs])
            btap = med([median(r["base"]["latency_ms"]) for r in rs])
            rel = f" ({x / first[c]:.2f} of {rtts[0]:g} ms)" if rtt != rtts[0] and first[c] == first[c] else ""
            row += [f"{x:.2f}{rel}", f"{tap:.0f} ({btap:.0f})"]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--presses", type=int, default=40, help="single presses per canvas per notebook (default 40)")
    ap.add_argument("--hold", type=float, default=2.0, help="seconds to hold '4' (default 2)")
    ap.add_argument("--cases", default=",".join(POLYCHORA), help="comma-separated polychora (default: all six), "
                         "fields (sphere64, waves128, allen-cahn, "
                         "blob64-surface, blob64-volume, blob64-mip, blob64-sections) or "
                         "parallel slices (oval24, oval600) or the largest uniform polychoron (omni120) or "
                         "issue 22's projection and star polychora (proj120, sstel120, gicos120)")
    ap.add_argument("--tap", default="60-120",
                    help="ms between keydown and keyup of a single press, a range drawn uniformly "
                         "(default 60-120, a human tap; 0 = Playwright's instant press)")
    ap.add_argument("--nagle", action="store_true",
                    help="disable the package's TCP_NODELAY server extension (jupyter_server's default)")
    ap.add_argument("--runs", type=int, default=1,
                    help="repeat the whole measurement; with 2 or more, end with the median of each target's "
                         "figure over the runs (default 1)")
    ap.add_argument("--seed", type=int, default=None, help="random seed for keys, order and spacing")
    ap.add_argument("--rev", default=None, help="measure a clean `git archive` of this revision (e.g. HEAD)")
    ap.add_argument("--json", default=None, help="also write the raw results here")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory (server log)")
    ap.add_argument("--targets", choices=sorted(TARGETS), default=None,
                    help="which targets to check: own (issue 8 at this machine's speed, the default), "
                         "slow (issue 8 on a ~3x slower machine; the default with --cpus), issue4 (absolute)")
    ap.add_argument("--cpus", default=None,
                    help="emulate a slower machine: pin this process and everything it starts (server, "
                         "kernels, Chromium) to these CPUs, e.g. 0")
    ap.add_argument("--busy", type=int, default=0,
                    help="with --cpus: also run this many busy-loop processes on the same CPUs")
    ap.add_argument("--ceiling", action="store_true",
                    help="one more hold of the widget per case with every mesh hidden: updates drawn "
                         "(acknowledged) per second when drawing costs nothing, the protocol's ceiling")
    ap.add_argument("--trace", action="store_true",
                    help="one more hold of the widget per case under a Chromium trace: where the page's "
                         "and the browser's threads spend each update's time")
    ap.add_argument("--console-debug", action="store_true",
                    help="leave console.debug as it is (by default the pages' console.debug does nothing: "
                         "with DevTools attached every call is sent to Playwright, which a user's browser "
                         "does not do)")
    ap.add_argument("--profile", action="store_true",
                    help="with --trace: also sample the page's JavaScript (CDP Profiler) and list the top "
                         "functions by self time")
    ap.add_argument("--trace-dir", default=None, help="with --trace: also keep each raw trace here")
    ap.add_argument("--in-flight", type=int, default=None,
                    help="updates the widget may have in flight (default: the package's; 1 = the old protocol)")
    ap.add_argument("--rtt", default="0",
                    help="round trips to measure through a proxy delaying every byte by half of it each way "
                         "(ms, comma-separated, e.g. 0,120,300; default 0: no proxy); ends with a table of "
                         "held frame rates as ratios to the baseline at each round trip")
    ap.add_argument("--volume-step", type=float, default=None,
                    help="ray-cast renderings (blob64-volume, -mip): sample every this many grid spacings "
                         "(default: the package's volume_layer.STEP, 0.5); a diagnosis of the shader's cost")
    args = ap.parse_args(argv)
    global IN_FLIGHT, VOLUME_STEP
    VOLUME_STEP = args.volume_step
    if args.in_flight is not None and args.in_flight < 1:
        ap.error("--in-flight must be >= 1")
    IN_FLIGHT = args.in_flight
    if args.presses < 1 or args.hold <= FPS_SKIP or args.runs < 1:
        ap.error(f"need --presses >= 1, --hold > {FPS_SKIP} and --runs >= 1")
    try:
        lo, _, hi = args.tap.partition("-")
        args.tap = (float(lo), float(hi or lo))
        assert 0 <= args.tap[0] <= args.tap[1] < 250  # shorter than the widget's hold delay
    except (ValueError, AssertionError):
        ap.error("--tap: milliseconds 'A' or 'A-B', 0 <= A <= B < 250")
    global TARGET
    TARGET = args.targets or ("slow" if args.cpus else "own")
    busy = []
    if args.cpus:
        try:
            cpus = {int(c) for c in args.cpus.split(",")}
            os.sched_setaffinity(0, cpus)
        except (ValueError, OSError) as exc:
            ap.error(f"--cpus: a comma-separated list of CPU numbers this machine has ({exc})")
        for _ in range(max(0, args.busy)):  # inherits the affinity
            busy.append(subprocess.Popen([sys.executable, "-c", "while True: pass"]))
    elif args.busy:
        ap.error("--busy needs --cpus")
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in ALL_CASES]
    if unknown or not cases:
        ap.error(f"unknown cases {unknown}; choose from {', '.join(ALL_CASES)}")
    args.case_list = cases
    try:
        args.rtts = [float(x) for x in args.rtt.split(",") if x.strip()]
        assert args.rtts and all(0 <= x < 5000 for x in args.rtts)
    except (ValueError, AssertionError):
        ap.error("--rtt: milliseconds, comma-separated, each in [0, 5000)")
    rng = random.Random(args.seed)

    try:
        return _main_runs(args, rng)
    finally:
        for b in busy:
            b.kill()


def _main_runs(args, rng) -> int:
    runs, raw, any_failed = [], [], False
    by_rtt: dict = {}  # rtt -> [results of each run]
    for k in range(args.runs * len(args.rtts)):
        rtt = args.rtts[k % len(args.rtts)]
        if args.runs > 1 or len(args.rtts) > 1:
            print(f"-- run {k // len(args.rtts) + 1} of {args.runs}, round trip {rtt:g} ms", file=sys.stderr, flush=True)
        results, meta, failed = measure(args, rng, rtt)
        by_rtt.setdefault(rtt, []).append(results)
        if args.runs > 1:
            print(f"\n### Run {k + 1} of {args.runs}\n")
        if results:
            print(report(results, meta))
            runs.append(results)
        for case, why in failed.items():
            print(f"\n{case}: not measured ({why})")
        any_failed = any_failed or bool(failed)
        raw.append({"meta": meta, "results": results, "failed": failed})
    if args.runs > 1 and runs and len(args.rtts) == 1:
        print("\n### Summary\n")
        print(summary(runs))
    if len(args.rtts) > 1 or args.rtts != [0.0]:
        print("\n### Round trips\n")
        print(rtt_table(by_rtt))
    if args.json:
        doc = raw[0] if args.runs == 1 else {"runs": raw}
        pathlib.Path(args.json).write_text(json.dumps(doc, indent=1, default=str))
    return 1 if any_failed else 0


if __name__ == "__main__":
    sys.exit(main())
