"""Where a frame of the widget's drawing goes on the page (headless Chromium, SwiftShader).

    python benchmarks/browser_draw.py [--cases 24-cell,600-cell]  (or star polychora by name)
        [--variants default,msaa] [--phases held,rest] [--hold 2] [--rounds 1]
        [--screenshots DIR [--compare OTHER]] [--rev HEAD~1,WORK]

About 40 s per case and variant.  One JupyterLab 4 server, one headless
Chromium; for each polychoron and variant a notebook shows
``Rot4DWidget(name, **options)``, and two phases are measured, each for
``--hold`` s timed per pass and ``--hold`` s timed per frame:

held
    "4" is held on the canvas, so every frame drawn is a new slice (rows
    arrive, are unpacked and uploaded).
rest
    the slice of one fixed state (reset, then the keys `SHOT_KEYS`) while the
    mouse turns the camera (OrbitControls): every frame draws the same rows
    from a new eye -- what a frame of the picture at rest costs.

A page init script wraps the WebGL context's ``clear``, draw calls and buffer
uploads, and ``requestAnimationFrame``; a frame is an animation-frame
callback that draws (pythreejs renders in one: its ``beforeRender`` -- the
companion's unpacking of new rows -- three.js's render, ``afterRender``).

Timed per pass: each call is preceded and followed by a 1-pixel
``readPixels`` (which waits until the GPU -- here the CPU -- has finished),
and the time between the two reads is charged to the call: by shader program
for draws -- balls (the program with the ``ball`` attribute), bars (``bar_a``),
faces (``tri_a``; a ``--rev`` before a0f17bf drew two face calls, summed) --
"upload" for ``bufferData``/``bufferSubData``, "clear".  Two back-to-back
reads, timed the same way, give the overhead of a read (on a multisampled
canvas it includes a resolve); it is subtracted from every call.  "js" is
the rest of the frame's callback: the page's JavaScript (unpacking, three.js's
bookkeeping) and waits for work queued outside the timed calls.  The forced
synchronisation serialises what the GPU process might overlap.

Timed per frame: nothing is synchronised but the end of each frame (one
read after the callback): "frame" is the callback's start to the drawn
frame -- the figure to hold to a frame's budget (33 ms at 30 frames/s).

``--screenshots DIR`` saves each canvas in the fixed state of the rest phase
(before the mouse turns it), so the pictures of two variants or two versions
can be compared pixel by pixel: the variants against the first one, and with
``--compare OTHER`` each picture against the one of the same name in OTHER
(say, made with ``--rev`` of an earlier version).

``--rev`` names the code measured: git revisions (a clean ``git archive`` of each) and ``WORK``
(the working tree, the default), comma-separated.  Each gets its own JupyterLab server in the same
browser, and every round measures each case with each code in turn (a different one first each
round), so two versions are compared under the same load (the machine is shared: runs minutes
apart are not comparable).  With several, the table has a ``code`` column and ``--screenshots
DIR`` keeps each code's pictures in a subfolder and compares them with the first code's.

Variants: ``default`` (the widget as shipped: no multisampling), ``msaa``
(``antialias=True``: WebGL's 4x multisampling).  Prints a table of medians
(ms) per pass, their sum, and the median frame.  The figures this benchmark
produced, and the commands, are in docs/performance.md.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from browser_latency import (  # noqa: E402
    POLYCHORA,
    cpu_name,
    export_revision,
    find_chromium,
    median,
    working_tree_description,
)
from browser_setup import CHROMIUM_FLAGS, JupyterServer  # noqa: E402
from jupyter_page import JupyterPage, write_notebook  # noqa: E402

from rot4d_widget.geometry.star_regular import SPECS  # noqa: E402

#: the ten regular star polychora (issue 22) may be cases too, by name
STAR = list(SPECS)
VARIANTS = {"default": {}, "msaa": {"antialias": True}}
PASSES = ["clear", "balls", "bars", "faces", "upload", "js"]
PHASES = ["held", "rest"]

#: Installed before any page script.  While ``__draw.on``: in mode "pass" every clear, draw call and
#: buffer upload is timed between 1-pixel reads (charged by shader program); in mode "frame" only
#: the end of each frame waits for the GPU.  Every animation-frame callback that draws is a frame:
#: its wall time, and (mode "pass") the time outside the timed calls -- the page's JavaScript.
DRAW_HOOK = r"""
(() => {
  const T = window.__draw = {on: false, mode: 'pass', rec: [], frames: [], names: new Map()};
  const px = new Uint8Array(4);
  const sync = gl => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let frame = null;  // the animation-frame callback running now: {gl, timed}
  const pass = gl => {
    const p = gl.getParameter(gl.CURRENT_PROGRAM);
    if (!p) return 'other';
    if (!T.names.has(p)) {
      const has = a => gl.getAttribLocation(p, a) >= 0;
      T.names.set(p, has('ball') ? 'balls' : has('bar_a') ? 'bars' : has('tri_a') ? 'faces' : 'other');
    }
    return T.names.get(p);
  };
  const onscreen = gl => gl.getParameter(gl.FRAMEBUFFER_BINDING) === null;
  for (const Ctx of [window.WebGL2RenderingContext, window.WebGLRenderingContext]) {
    if (!Ctx) continue;
    for (const fn of ['clear', 'drawArrays', 'drawArraysInstanced', 'drawElements', 'drawElementsInstanced',
                      'bufferData', 'bufferSubData']) {
      const orig = Ctx.prototype[fn];
      if (!orig) continue;
      const upload = fn.startsWith('buffer');
      Ctx.prototype[fn] = function (...args) {
        if (!T.on || !frame || (!upload && !onscreen(this))) return orig.apply(this, args);
        if (!upload) frame.gl = this;
        if (T.mode !== 'pass') return orig.apply(this, args);
        const tp = performance.now();
        sync(this);
        const t0 = performance.now();
        sync(this);
        const t1 = performance.now();
        orig.apply(this, args);
        sync(this);
        const t2 = performance.now();
        frame.timed += t2 - tp;
        T.rec.push([fn === 'clear' ? 'clear' : upload ? 'upload' : pass(this), t2 - t1, t1 - t0, t2]);
      };
    }
  }
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = cb => raf(ts => {
    if (!T.on || frame) return cb(ts);
    const f = frame = {gl: null, timed: 0};
    const t0 = performance.now();
    try {
      return cb(ts);
    } finally {
      frame = null;
      if (f.gl) {
        if (T.mode !== 'pass') sync(f.gl);  // the frame is drawn when this read returns
        const total = performance.now() - t0;
        T.frames.push([T.mode, total, total - f.timed]);
      }
    }
  });
})();
"""

#: the state of the screenshots: 13 steps of R_xw, 5 of the double rotation R_xz,yw, 3 of R_yz
SHOT_KEYS = "4" * 13 + "z" * 5 + "6" * 3

CELLS = [
    f"from rot4d_widget import Rot4DWidget\nSHOT_KEYS = {SHOT_KEYS!r}",
    "w = Rot4DWidget({name!r}, **{options!r})\nw",
]


def _measure(page, hold: float, mode: str) -> None:
    page.evaluate("m => { window.__draw.mode = m; window.__draw.on = true; }", mode)
    time.sleep(hold)
    page.evaluate("() => { window.__draw.on = false; }")


def _orbit(page, box, hold: float, modes) -> None:
    """Turn the camera with the mouse (OrbitControls) in a slow circle while each mode is timed."""
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(cx + 40, cy)
    page.mouse.down()
    k = 0
    for mode in modes:
        page.evaluate("m => { window.__draw.mode = m; window.__draw.on = true; }", mode)
        end = time.monotonic() + hold
        while time.monotonic() < end:
            k += 1
            a = 0.05 * k
            page.mouse.move(cx + 40 * np.cos(a), cy + 40 * np.sin(a))
            time.sleep(0.015)
        page.evaluate("() => { window.__draw.on = false; }")
    page.mouse.up()


def run_one(context, server, case: str, variant: str, hold: float, shots: pathlib.Path | None,
            phases=tuple(PHASES)) -> dict:
    name = f"draw_{re.sub(r'[^A-Za-z0-9]+', '_', case)}_{variant}.ipynb"
    write_notebook(server.root / name, [c.format(name=case, options=VARIANTS[variant]) for c in CELLS])
    page = context.new_page()
    try:
        jp = JupyterPage(page, server, name).open(timeout=180)
        jp.run_all(timeout=300)
        sel = f".{jp.kernel('print(w.scene.canvas_class)').strip()} canvas"
        page.wait_for_selector(sel, timeout=120_000)
        if not jp.wait_for(lambda: (s := jp.canvas_stats(sel)) and s["count"] > 50, timeout=60):
            raise RuntimeError(f"{case}: nothing drawn")
        page.locator(sel).scroll_into_view_if_needed()
        box = page.locator(sel).bounding_box()
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        time.sleep(0.5)
        page.evaluate("() => { window.__draw.rec = []; window.__draw.frames = []; }")
        got = {}
        if "held" in phases:
            page.keyboard.down("4")
            time.sleep(0.3)  # past the hold delay
            for mode in ("pass", "frame"):
                _measure(page, hold, mode)
            page.keyboard.up("4")
            time.sleep(0.5)
            got["held"] = page.evaluate("() => { const T = window.__draw; const r = [T.rec, T.frames];"
                                        " T.rec = []; T.frames = []; return r; }")
        # the fixed state: its picture, then the camera turned around it
        page.mouse.move(0, 0)
        jp.kernel("w.press('r')\nfor k in SHOT_KEYS: w.press(k)")
        time.sleep(1.0)
        if shots is not None:
            page.locator(sel).screenshot(path=str(shots / f"{case}-{variant}.png"))
        if "rest" in phases:
            _orbit(page, box, hold, ("pass", "frame"))
            got["rest"] = page.evaluate("() => { const T = window.__draw; return [T.rec, T.frames]; }")
        capacity = int(jp.kernel("print(w.scene.capacity)"))
        counts = jp.kernel_json("w.scene.counts")
        jp.shutdown_kernel()
    finally:
        page.close()
    out = {"capacity": capacity, "counts": counts}
    for phase, (rec, frames) in got.items():
        # per pass: the timed calls of each frame, in order; a frame starts with its clear
        per = {p: [] for p in PASSES}
        n = 0
        for kind, ms, overhead, _ in rec:
            if kind == "clear":
                n += 1
                for p in PASSES:
                    per[p].append(0.0)
            if kind in per and n:
                per[kind][-1] += max(ms - overhead, 0.0)
        per["js"] = [other for mode, _, other in frames if mode == "pass"]
        out[phase] = {"per": per, "frames": n, "overhead": [o for _, _, o, _ in rec],
                      "frame": [total for mode, total, _ in frames if mode == "frame"]}
    return out


def _pixels(path):
    import matplotlib.image

    return np.asarray(matplotlib.image.imread(str(path)))[..., :3].astype(np.float64) * 255.0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", default=",".join(POLYCHORA), help="comma-separated polychora (default: all six)")
    ap.add_argument("--variants", default="default,msaa", help=f"comma-separated, from {', '.join(VARIANTS)}")
    ap.add_argument("--phases", default=",".join(PHASES), help=f"comma-separated, from {', '.join(PHASES)}")
    ap.add_argument("--hold", type=float, default=2.0,
                    help="seconds each phase is timed per pass, and again per frame (default 2)")
    ap.add_argument("--rev", default="WORK",
                    help="the code measured, comma-separated: git revisions (a clean `git archive` of each) "
                         "and WORK (the working tree); interleaved in every round (default WORK)")
    ap.add_argument("--screenshots", default=None, help="save each canvas in the rest phase's state in this folder")
    ap.add_argument("--compare", default=None,
                    help="with --screenshots: compare each picture with the one of the same name in this "
                         "folder (e.g. made with --rev of another version)")
    ap.add_argument("--json", default=None, help="also write every frame's figures, by code, case, variant and "
                                                 "phase and round, to this file")
    ap.add_argument("--rounds", type=int, default=1,
                    help="repeat every case and variant, interleaved; frames are pooled (default 1)")
    args = ap.parse_args(argv)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    variants = [v.strip() for v in args.variants.split(",") if v.strip()]
    phases = [v.strip() for v in args.phases.split(",") if v.strip()]
    if not cases or any(c not in POLYCHORA + STAR for c in cases):
        ap.error(f"choose cases from {', '.join(POLYCHORA + STAR)}")
    if not variants or any(v not in VARIANTS for v in variants) or len(set(variants)) != len(variants):
        ap.error(f"choose distinct variants from {', '.join(VARIANTS)}")
    if not phases or any(v not in PHASES for v in phases) or len(set(phases)) != len(phases):
        ap.error(f"choose distinct phases from {', '.join(PHASES)}")
    if args.rounds < 1:
        ap.error("--rounds must be >= 1")

    from playwright.sync_api import sync_playwright

    chromium = find_chromium()
    version = subprocess.run([chromium, "--version"], capture_output=True, text=True).stdout.strip()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="rot4d-draw-"))
    codes = [c.strip() for c in args.rev.split(",") if c.strip()]
    if not codes or len(set(codes)) != len(codes):
        ap.error("--rev: distinct revisions or WORK, comma-separated")
    servers, described = {}, {}
    for i, c in enumerate(codes):
        servers[c] = JupyterServer("lab", tmp / f"server{i}")
        if c == "WORK":
            described[c] = working_tree_description()
        else:
            described[c] = export_revision(c, tmp / f"src{i}")
            servers[c].env["PYTHONPATH"] = os.pathsep.join(
                filter(None, [str(tmp / f"src{i}"), servers[c].env.get("PYTHONPATH")]))
    shots = pathlib.Path(args.screenshots) if args.screenshots else None
    folders = {c: (shots if len(codes) == 1 else shots / re.sub(r"[^A-Za-z0-9._-]+", "_", c)) for c in codes} \
        if shots is not None else {c: None for c in codes}
    for f in folders.values():
        if f is not None:
            f.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()
    pooled: dict = {}
    raw: list = []
    try:
        for server in servers.values():
            server.start()
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                str(tmp / "profile"), executable_path=chromium, headless=True, args=CHROMIUM_FLAGS,
                viewport={"width": 1400, "height": 1200},
            )
            context.add_init_script(DRAW_HOOK)
            try:
                for k in range(args.rounds):
                    for case in cases:
                        for variant in variants:
                            for c in codes[k % len(codes):] + codes[:k % len(codes)]:  # each code first in turn
                                r = run_one(context, servers[c], case, variant, args.hold, folders[c], phases)
                                raw.append({"code": c, "case": case, "variant": variant, "round": k,
                                            **{ph: {"per": r[ph]["per"], "frame": r[ph]["frame"]} for ph in phases}})
                                print(f"{c}, {case} {variant}: " + ", ".join(f"{ph} {r[ph]['frames']} frames"
                                                                            for ph in phases),
                                      file=sys.stderr, flush=True)
                                for ph in phases:
                                    acc = pooled.setdefault((c, case, variant, ph), {
                                        "per": {q: [] for q in PASSES}, "frames": 0, "overhead": [], "frame": []})
                                    for q in PASSES:
                                        acc["per"][q] += r[ph]["per"][q]
                                    acc["frames"] += r[ph]["frames"]
                                    acc["overhead"] += r[ph]["overhead"]
                                    acc["frame"] += r[ph]["frame"]
                                    acc["capacity"], acc["counts"] = r["capacity"], r["counts"]
            finally:
                context.close()
    finally:
        for server in servers.values():
            server.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(raw))
    several = len(codes) > 1
    print("| " + ("code | " if several else "") + "case | variant | phase | balls, bars, faces | frames | "
          + " | ".join(PASSES) + " | sum | frame (n) |")
    print("|" + "---|" * (5 + several + len(PASSES) + 2))
    for key in sorted(pooled, key=lambda k: (cases.index(k[1]), variants.index(k[2]), phases.index(k[3]),
                                             codes.index(k[0]))):
        c, case, variant, ph = key
        r = pooled[key]
        meds = [median(r["per"][p]) for p in PASSES]
        print("| " + (f"{c} | " if several else "") + f"{case} | {variant} | {ph} | "
              f"{', '.join(str(n) for n in r['counts'])} | {r['frames']} | "
              + " | ".join(f"{m:.1f}" for m in meds) + f" | {sum(meds):.1f} | "
              f"{median(r['frame']):.1f} ({len(r['frame'])}) |")
    def compare(title, pairs):
        print(f"\n{title} -- pixels that differ by more than 2/255 and by more than 8/255 in some channel:")
        for label, mine, ref in pairs:
            if not ref.exists():
                print(f"- {label}: no {ref}")
                continue
            d = np.abs(_pixels(mine) - _pixels(ref)).max(axis=-1)
            print(f"- {label}: {100 * np.mean(d > 2):.2f} %, {100 * np.mean(d > 8):.2f} % "
                  f"(largest difference {d.max():.0f}/255)")

    if shots is not None:
        first = codes[0]
        if len(variants) > 1:
            compare(f"Screenshots in {folders[first]}: each variant against `{variants[0]}`",
                    [(f"{case}, {v}", folders[first] / f"{case}-{v}.png", folders[first] / f"{case}-{variants[0]}.png")
                     for case in cases for v in variants[1:]])
        if several:
            compare(f"Screenshots in {shots}: each code against {first}",
                    [(f"{c}, {case}, {v}", folders[c] / f"{case}-{v}.png", folders[first] / f"{case}-{v}.png")
                     for c in codes[1:] for case in cases for v in variants])
        if args.compare:
            other = pathlib.Path(args.compare)
            compare(f"Against the pictures of the same name in {other}",
                    [(f"{c}, {case}, {v}" if several else f"{case}, {v}", folders[c] / f"{case}-{v}.png",
                      other / f"{case}-{v}.png") for c in codes for case in cases for v in variants])
    overhead = median([o for r in pooled.values() for o in r["overhead"]])
    print(f"\n{args.rounds} round(s), {args.hold:g} s per phase and timing; frames pooled. Medians in ms per "
          f"frame: per pass synchronised by 1-pixel reads (read overhead {overhead:.1f} ms subtracted), js the "
          f"rest of the frame's callback; frame unsynchronised but for its end (n frames). "
          f"{os.cpu_count()} CPUs ({cpu_name()}), load {' '.join(f'{x:.1f}' for x in load_before)} before, "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())} after; {version.split(' built')[0]}, headless, "
          f"SwiftShader; canvas 600×500; code: {'; '.join(f'{c} = {described[c]}' for c in codes)}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
