"""What a scientist sees while turning a 2 GB store, second by second from the moment it is shown.

    python benchmarks/store_timeline.py [--gb 2] [--rendering volume] [--seconds 40] [--rev REV]

The store is `benchmarks/field_zarr.py`'s (written once if missing: ``--gb 2`` is 150^4 float32,
2.0 GB in 625 chunks of 32^4, over a field's memory budget).  One JupyterLab 4 server, one
headless Chromium (SwiftShader WebGL), one notebook whose cell is the README's line for a store:

    w = Rot4DWidget(Field4D.from_xarray(xarray.open_zarr(store)["f"]), rendering=...)

The cell is run; from the moment the widget's canvas is on the page ("shown", t = 0) the pointer
is on it and "4" is held down for ``--seconds`` -- a user who starts turning as soon as there is a
picture.  Every second the page's own DOM is read (not the kernel, which may be busy): the
readout's row saying who draws while keys are held ("turning"), the progress bar's text, and the
number of distinct pictures drawn in that second (every frame's pixels hashed after drawing, as
`browser_latency.py` does).  Then the same function sampled on 64^4 nodes, an array in memory
(``field_zarr.values``), in the same rendering, is held for 4 s in the same page: the frame rate a
store should reach once the page holds its copy (the 64^4 figures of docs/performance.md).

Prints one row a second and a summary.  ``--rev`` measures a clean ``git archive`` of a revision.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from browser_latency import (  # noqa: E402  (the same browser, recorder and helpers as the latency benchmark)
    CHROMIUM_FLAGS,
    QUIET_DEBUG,
    RECORDER,
    VIEWPORT,
    JupyterPage,
    JupyterServer,
    export_revision,
    find_chromium,
    write_notebook,
)

#: read in the page every second: the readout's "turning" row, the progress bar's text
DOM_READ = r"""
() => {
  const text = (el) => el ? el.innerText.replace(/\s+/g, ' ').trim() : null;
  const rows = [...document.querySelectorAll('.rot4d-readout tr')].map(text);
  const turning = rows.find((r) => r && r.startsWith('turning')) || null;
  const bar = document.querySelector('.rot4d-progress');
  const shown = bar && bar.offsetParent !== null ? text(bar) : null;
  return {turning, progress: shown, now: performance.now()};
}
"""


@contextlib.contextmanager
def lab_browser(prefix: str, rev: str | None = None):
    """A JupyterLab 4 server and a headless Chromium on it, both gone afterwards: yields
    ``(server, browser context, the code measured)`` -- with ``rev``, a clean `git archive` of that
    revision first on the kernels' path, else the working tree."""
    from playwright.sync_api import sync_playwright

    tmp = pathlib.Path(tempfile.mkdtemp(prefix=prefix))
    server = JupyterServer("lab", tmp / "server")
    code = "working tree"
    if rev:
        code = export_revision(rev, tmp / "src")
        server.env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(tmp / "src"), server.env.get("PYTHONPATH")]))
    try:
        server.start()
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(str(tmp / "profile"), executable_path=find_chromium(),
                                                           headless=True, args=CHROMIUM_FLAGS, viewport=VIEWPORT)
            context.add_init_script(QUIET_DEBUG)
            try:
                yield server, context, code
            finally:
                context.close()
    finally:
        server.stop()
        shutil.rmtree(tmp, ignore_errors=True)


def store_path(gb: float, chunk: int) -> pathlib.Path:
    """The store of ``gb`` GB (field_zarr.py's), written in a separate process if missing."""
    size = int(round((gb * 1e9 / 4) ** 0.25))
    store = pathlib.Path(f"/tmp/rot4d-field-{size}-{chunk}.zarr")
    if not (store / "COMPLETE").exists():
        print(f"writing {store} ...", file=sys.stderr, flush=True)
        subprocess.run([sys.executable, str(HERE / "field_zarr.py"), "--size", str(size), "--chunk", str(chunk),
                        "--store", str(store), "--create-only"], check=True)
    return store


def frames_per_second(t: list, h: list, start: float, seconds: int) -> list:
    """Distinct pictures drawn in each second after ``start`` (page ms): frames whose hash differs
    from the frame before."""
    out = [0] * seconds
    for i in range(1, len(t)):
        k = int((t[i] - start) // 1000)
        if 0 <= k < seconds and h[i] != h[i - 1]:
            out[k] += 1
    return out


def cpu_seconds(pid: int) -> float:
    """CPU time (user + system) of process ``pid`` so far, from /proc."""
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def hold(page, sel: str, seconds: float, every: float = 1.0, pid: int | None = None, repress: float | None = None):
    """Hold "4" on the canvas ``sel`` for ``seconds``: (page time of the keydown, DOM reads each
    ``every`` s -- with the kernel's CPU seconds so far when ``pid`` is given --, frame times,
    frame hashes).  ``repress``: release "4" and press it again this many seconds into the hold."""
    page.evaluate(RECORDER, [sel, sel])  # the recorder's second canvas names the renderer; frames of the first
    box = page.locator(sel).bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, steps=2)
    time.sleep(0.2)
    page.keyboard.down("4")
    t_down = page.evaluate("() => performance.now()")
    reads = []
    end = time.monotonic() + seconds
    again = None if repress is None else time.monotonic() + repress
    while time.monotonic() < end:
        if again is not None and time.monotonic() >= again:
            page.keyboard.up("4")
            time.sleep(0.1)
            page.keyboard.down("4")
            again = None
        read = page.evaluate(DOM_READ)
        if pid is not None:
            read["kernel_cpu"] = cpu_seconds(pid)
        reads.append(read)
        time.sleep(max(0.0, min(every, end - time.monotonic())))
    page.keyboard.up("4")
    time.sleep(0.3)
    rec = page.evaluate("() => { window.__bench.stop(); return {t: window.__bench.t, h: window.__bench.h}; }")
    return t_down, reads, rec["t"], rec["h"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--gb", type=float, default=2.0, help="the store's size in GB (default 2: 150^4)")
    ap.add_argument("--chunk", type=int, default=32)
    ap.add_argument("--rendering", default="volume", choices=("volume", "mip", "sections", "surface"))
    ap.add_argument("--seconds", type=int, default=40, help="how long '4' is held from the moment shown")
    ap.add_argument("--rev", default=None, help="measure a clean `git archive` of this revision")
    ap.add_argument("--repress", type=float, default=None,
                    help="release '4' and press it again this many seconds after the store is shown")
    ap.add_argument("--nodes", type=int, default=64,
                    help="nodes a side of the in-memory comparison (default 64: the 64^4 figures)")
    args = ap.parse_args(argv)
    store = store_path(args.gb, args.chunk)
    opening = (f"import os, xarray\nfrom rot4d_widget import Field4D, Rot4DWidget\n"
               f"open('kernel.pid', 'w').write(str(os.getpid()))\n"
               f"field = Field4D.from_xarray(xarray.open_zarr({str(store)!r})['f'])\n"
               f"w = Rot4DWidget(field, rendering={args.rendering!r})\nw")
    blob = (f"import sys\nsys.path.insert(0, {str(HERE)!r})\nimport numpy as np\nfrom field_zarr import values\n"
            f"from rot4d_widget import Field4D, Rot4DWidget\n"
            f"field = Field4D(values(np.arange({args.nodes}), {args.nodes}), axes='xyzw', extent=[(-1.0, 1.0)] * 4)\n"
            f"b = Rot4DWidget(field, rendering={args.rendering!r})\nb")
    load_before = os.getloadavg()
    with lab_browser("rot4d-timeline-", args.rev) as (server, context, code):
        write_notebook(server.root / "store.ipynb", [opening])
        write_notebook(server.root / "blob.ipynb", [blob])
        page = context.new_page()
        jp = JupyterPage(page, server, "store.ipynb").open(timeout=180)
        t_run = time.monotonic()
        page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
        sel = ".rot4d-canvas canvas"
        page.wait_for_selector(sel, timeout=300_000)
        shown = time.monotonic() - t_run
        t_down, reads, t, h = hold(page, sel, args.seconds, pid=int((server.root / "kernel.pid").read_text()),
                                   repress=args.repress)
        jp.wait_idle(timeout=300)
        jp.shutdown_kernel()
        page.close()
        page = context.new_page()
        jb = JupyterPage(page, server, "blob.ipynb").open(timeout=180)
        jb.run_all(timeout=300)
        readout = lambda: jb.kernel("print(b.readout.value)")  # noqa: E731
        jb.wait_for(lambda: "page draws" in readout(), timeout=120)
        b_down, _, bt, bh = hold(page, sel, 4.5)
        jb.shutdown_kernel()

    per_second = frames_per_second(t, h, t_down, args.seconds)
    blob_fps = statistics.median(frames_per_second(bt, bh, b_down + 500, 4))
    print(f"\n{args.rendering}, store {store.name} ({args.gb:g} GB), code: {code}; the cell run -> canvas on the "
          f"page: {shown:.1f} s; '4' held from then on (t = 0)\n")
    print("| s | pictures drawn | kernel's CPU % | the readout's turning row | progress bar |")
    print("|---:|---:|---:|---|---|")
    for k, n in enumerate(per_second):
        near = sorted(reads, key=lambda r: abs(r["now"] - (t_down + 1000 * k + 500)))[:1]
        r = near[0] if near else {}
        i = reads.index(r) if near else 0
        cpu = (f"{100 * (reads[i + 1]['kernel_cpu'] - r['kernel_cpu']) / ((reads[i + 1]['now'] - r['now']) / 1000):.0f}"
               if near and i + 1 < len(reads) else "—")
        print(f"| {k}–{k + 1} | {n} | {cpu} | {r.get('turning') or '—'} | {r.get('progress') or '—'} |")
    page_from = next((k for k, r in enumerate(reads) if r.get("turning") and "page draws" in r["turning"]), None)
    tail = per_second[page_from + 1:] if page_from is not None else []
    print(f"\nThe page draws from its own copy from second {page_from if page_from is not None else '—'}; "
          f"pictures a second after that, median: {statistics.median(tail) if tail else math.nan:g}; "
          f"the same function on {args.nodes}^4 nodes in memory, the same rendering, same page, held 4 s: "
          f"{blob_fps:g} a second.")
    print(f"Load average before {' '.join(f'{x:.1f}' for x in load_before)}, after "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}; {len(os.sched_getaffinity(0))} CPUs.")
    print(json.dumps({"shown_s": shown, "per_second": per_second, "reads": reads, "blob_fps": blob_fps}),
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
