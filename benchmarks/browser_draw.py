"""What each draw call of the widget costs on the page (headless Chromium, SwiftShader).

    python benchmarks/browser_draw.py [--cases 24-cell,600-cell]  (or star polychora by name)
        [--variants default,msaa] [--hold 2] [--rounds 1] [--screenshots DIR [--compare OTHER]]
        [--rev HEAD]

About 30 s per case and variant.  One JupyterLab 4 server, one headless
Chromium; for each polychoron and variant a notebook shows
``Rot4DWidget(name, **options)`` and "4" is held on its canvas for
``--hold`` s, so every frame drawn is a different slice.

A page init script wraps the WebGL2 context's ``clear`` and draw calls: each
call is preceded and followed by a 1-pixel ``readPixels`` (which waits until
the GPU -- here the CPU -- has finished), and the time between the two reads
is charged to the call, by shader program: balls (the program with the
``ball`` attribute), bars (``bar_a``), faces (``tri_a``: one call since
a0f17bf -- the kernel orders the triangles back to front for the eye; a
``--rev`` before it drew back faces then front faces, two calls summed into
the one pass), summed per frame (a frame starts with its ``clear``).  Two
back-to-back reads, timed the same way, give the overhead of a read (on a
multisampled canvas it includes a resolve); it is subtracted from every
call.  The forced synchronisation serialises what the GPU process might
overlap, so the per-pass times add up to more than an unsynchronised frame costs: use
them to compare passes and variants, and the latency benchmark
(``browser_latency.py``) for the targets.

``--screenshots DIR`` saves each canvas after the hold, in one fixed state
(reset, then the keys `SHOT_KEYS`), so the pictures of two variants or two
versions can be compared pixel by pixel: the variants against the first
one, and with ``--compare OTHER`` each picture against the one of the same
name in OTHER (say, made with ``--rev`` of an earlier version).

Variants: ``default`` (the widget as shipped: no multisampling), ``msaa``
(``antialias=True``: WebGL's 4x multisampling).  Prints a table of medians (ms) per pass and their sum.
The figures this benchmark produced, and the commands, are in docs/design.md.
"""

from __future__ import annotations

import argparse
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
PASSES = ["clear", "balls", "bars", "faces"]

#: Installed before any page script: times clear and draw calls while __draw.on.
DRAW_HOOK = r"""
(() => {
  const T = window.__draw = {on: false, rec: [], names: new Map()};
  const px = new Uint8Array(4);
  const sync = gl => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const pass = gl => {
    const p = gl.getParameter(gl.CURRENT_PROGRAM);
    if (!p) return 'other';
    if (!T.names.has(p)) {
      const has = a => gl.getAttribLocation(p, a) >= 0;
      T.names.set(p, has('ball') ? 'balls' : has('bar_a') ? 'bars' : has('tri_a') ? 'faces' : 'other');
    }
    return T.names.get(p);
  };
  for (const Ctx of [window.WebGL2RenderingContext, window.WebGLRenderingContext]) {
    if (!Ctx) continue;
    for (const fn of ['clear', 'drawArrays', 'drawArraysInstanced', 'drawElements', 'drawElementsInstanced']) {
      const orig = Ctx.prototype[fn];
      if (!orig) continue;
      Ctx.prototype[fn] = function (...args) {
        if (!T.on || this.getParameter(this.FRAMEBUFFER_BINDING) !== null) return orig.apply(this, args);
        sync(this);
        const t0 = performance.now();
        sync(this);
        const t1 = performance.now();
        orig.apply(this, args);
        sync(this);
        const t2 = performance.now();
        T.rec.push([fn === 'clear' ? 'clear' : pass(this), t2 - t1, t1 - t0, t2]);
      };
    }
  }
})();
"""

#: the state of the screenshots: 13 steps of R_xw, 5 of the double rotation R_xz,yw, 3 of R_yz
SHOT_KEYS = "4" * 13 + "z" * 5 + "6" * 3

CELLS = [
    f"from rot4d_widget import Rot4DWidget\nSHOT_KEYS = {SHOT_KEYS!r}",
    "w = Rot4DWidget({name!r}, **{options!r})\nw",
]


def run_one(context, server, case: str, variant: str, hold: float, shots: pathlib.Path | None) -> dict:
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
        page.evaluate("() => { window.__draw.rec = []; window.__draw.on = true; }")
        page.keyboard.down("4")
        time.sleep(hold)
        page.keyboard.up("4")
        time.sleep(0.5)
        rec = page.evaluate("() => { window.__draw.on = false; return window.__draw.rec; }")
        if shots is not None:  # one fixed state, so pictures of two versions can be compared
            page.mouse.move(0, 0)
            jp.kernel("w.press('r')\nfor k in SHOT_KEYS: w.press(k)")
            time.sleep(1.0)
            page.locator(sel).screenshot(path=str(shots / f"{case}-{variant}.png"))
        capacity = int(jp.kernel("print(w.scene.capacity)"))
        jp.shutdown_kernel()
    finally:
        page.close()
    # a frame starts with its clear; a pass may be several draw calls (one each today; faces were
    # two, back then front, in a --rev before a0f17bf), summed
    per = {p: [] for p in PASSES}
    frames = 0
    for kind, ms, overhead, _ in rec:
        if kind == "clear":
            frames += 1
            for p in PASSES:
                per[p].append(0.0)
        if kind in per and frames:
            per[kind][-1] += max(ms - overhead, 0.0)
    return {"per": per, "frames": frames, "capacity": capacity,
            "overhead": median([o for _, _, o, _ in rec])}


def _pixels(path):
    import matplotlib.image

    return np.asarray(matplotlib.image.imread(str(path)))[..., :3].astype(np.float64) * 255.0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", default=",".join(POLYCHORA), help="comma-separated polychora (default: all six)")
    ap.add_argument("--variants", default="default,msaa", help=f"comma-separated, from {', '.join(VARIANTS)}")
    ap.add_argument("--hold", type=float, default=2.0, help="seconds to hold '4' per case (default 2)")
    ap.add_argument("--rev", default=None, help="measure a clean `git archive` of this revision")
    ap.add_argument("--screenshots", default=None, help="save each canvas after the hold in this folder")
    ap.add_argument("--compare", default=None,
                    help="with --screenshots: compare each picture with the one of the same name in this "
                         "folder (e.g. made with --rev of another version)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="repeat every case and variant, interleaved; frames are pooled (default 1)")
    args = ap.parse_args(argv)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    variants = [v.strip() for v in args.variants.split(",") if v.strip()]
    if not cases or any(c not in POLYCHORA + STAR for c in cases):
        ap.error(f"choose cases from {', '.join(POLYCHORA + STAR)}")
    if not variants or any(v not in VARIANTS for v in variants) or len(set(variants)) != len(variants):
        ap.error(f"choose distinct variants from {', '.join(VARIANTS)}")
    if args.rounds < 1:
        ap.error("--rounds must be >= 1")

    from playwright.sync_api import sync_playwright

    chromium = find_chromium()
    version = subprocess.run([chromium, "--version"], capture_output=True, text=True).stdout.strip()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="rot4d-draw-"))
    code = working_tree_description()
    server = JupyterServer("lab", tmp / "server")
    if args.rev:
        code = export_revision(args.rev, tmp / "src")
        server.env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(tmp / "src"), server.env.get("PYTHONPATH")]))
    shots = pathlib.Path(args.screenshots) if args.screenshots else None
    if shots is not None:
        shots.mkdir(parents=True, exist_ok=True)
    load_before = os.getloadavg()
    pooled: dict = {}
    try:
        server.start()
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                str(tmp / "profile"), executable_path=chromium, headless=True, args=CHROMIUM_FLAGS,
                viewport={"width": 1400, "height": 1200},
            )
            context.add_init_script(DRAW_HOOK)
            try:
                for _ in range(args.rounds):
                    for case in cases:
                        for variant in variants:
                            r = run_one(context, server, case, variant, args.hold, shots)
                            print(f"{case} {variant}: {r['frames']} frames", file=sys.stderr, flush=True)
                            acc = pooled.setdefault((case, variant), {"per": {q: [] for q in PASSES},
                                                                      "frames": 0, "overhead": []})
                            for q in PASSES:
                                acc["per"][q] += r["per"][q]
                            acc["frames"] += r["frames"]
                            acc["overhead"].append(r["overhead"])
                            acc["capacity"] = r["capacity"]
            finally:
                context.close()
    finally:
        server.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    print("| case | variant | rows | frames | " + " | ".join(PASSES) + " | sum | read overhead |")
    print("|---|---|---|---|" + "---|" * len(PASSES) + "---|---|")
    for (case, variant), r in pooled.items():
        meds = [median(r["per"][p]) for p in PASSES]
        print(f"| {case} | {variant} | {r['capacity']} | {r['frames']} | "
              + " | ".join(f"{m:.1f}" for m in meds) + f" | {sum(meds):.1f} | {median(r['overhead']):.1f} |")
    if shots is not None and len(variants) > 1:
        print(f"\nScreenshots in {shots}; pixels that differ from the `{variants[0]}` picture by more "
              "than 8/255 in some channel:")
        for case in cases:
            ref = _pixels(shots / f"{case}-{variants[0]}.png")
            for v in variants[1:]:
                d = np.abs(_pixels(shots / f"{case}-{v}.png") - ref).max(axis=-1)
                print(f"- {case}, {v}: {100 * np.mean(d > 8):.2f} % (largest difference {d.max():.0f}/255)")
    if shots is not None and args.compare:
        other = pathlib.Path(args.compare)
        print(f"\nPixels that differ from the picture of the same name in {other} by more than 8/255 in "
              "some channel:")
        for case in cases:
            for v in variants:
                name = f"{case}-{v}.png"
                if not (other / name).exists():
                    print(f"- {name}: not in {other}")
                    continue
                d = np.abs(_pixels(shots / name) - _pixels(other / name)).max(axis=-1)
                print(f"- {name}: {100 * np.mean(d > 8):.2f} % (largest difference {d.max():.0f}/255)")
    print(f"\n{args.rounds} round(s), {args.hold:g} s hold each; frames pooled. "
          f"Medians in ms per frame, per pass, synchronised by 1-pixel reads (overhead subtracted). "
          f"{os.cpu_count()} CPUs ({cpu_name()}), load {' '.join(f'{x:.1f}' for x in load_before)} before, "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())} after; {version.split(' built')[0]}, headless, "
          f"SwiftShader; canvas 600×500; code: {code}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
