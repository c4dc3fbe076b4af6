"""Pictures to look at: notebook 04's simulation and nibabel's fMRI run turned in every rendering.

    python benchmarks/field_screens.py --out DIR [--rev REV] [--datasets allen-cahn,fmri]

One JupyterLab 4 server, one headless Chromium (SwiftShader WebGL).  For each dataset a notebook
makes ``w = Rot4DWidget(field)`` as the notebooks do (04: the Allen-Cahn simulation of
``rot4d_widget.sources.datasets.phase_separation``, ``w="time"``; 08: nibabel's test run
``functional.nii``, 4 x 4 x 8 mm voxels, TR 2 s) and waits until the page holds its copy of the
field.  Then, in every rendering: the kernel's picture at rest (``DIR/<dataset>-<rendering>-rest.png``),
and the page's own picture while "4" is held, taken 1 s into the hold
(``DIR/<dataset>-<rendering>-held.png``).  Prints, per picture, how long after the key the canvas
first changed, and how many pixels differ from the background (a blank canvas is an error).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from browser_latency import FIELD_CASES  # noqa: E402  (the latency benchmark's field cases)
from store_timeline import JupyterPage, lab_browser, write_notebook  # noqa: E402  (the same browser set-up)

DATASETS = {
    "allen-cahn": FIELD_CASES["allen-cahn"],
    "fmri": (
        "import os, nibabel\nfrom nibabel.testing import data_path\nfrom rot4d_widget import Field4D\n"
        "img = nibabel.load(os.path.join(data_path, 'functional.nii'))\n"
        "zooms = tuple(float(v) for v in img.header.get_zooms())\n"
        "field = Field4D(img.get_fdata(), axes='xyzw', name='BOLD signal', units='a.u.', space_units='mm',\n"
        "                w_units='s', extent=[(0.0, (n - 1) * h) for n, h in zip(img.shape, zooms)], levels=[4500.0])"
    ),
}
RENDERINGS = ("surface", "volume", "mip", "sections")
SEL = ".rot4d-canvas canvas"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="folder for the PNGs")
    ap.add_argument("--rev", default=None, help="draw a clean `git archive` of this revision")
    ap.add_argument("--datasets", default=",".join(DATASETS))
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    failures = []
    with lab_browser("rot4d-screens-", args.rev) as (server, context, _code):
        for name in args.datasets.split(","):
            nb = f"{name}.ipynb"
            write_notebook(server.root / nb, [f"{DATASETS[name]}\nfrom rot4d_widget import Rot4DWidget\n"
                                              "w = Rot4DWidget(field)\nw"])
            page = context.new_page()
            jp = JupyterPage(page, server, nb).open(timeout=180)
            jp.run_all(timeout=600)
            page.wait_for_selector(SEL, timeout=120_000)
            holds = jp.wait_for(lambda jp=jp: "page draws" in jp.kernel("print(w.readout.value)"), timeout=180)
            print(f"{name}: the page holds its copy: {bool(holds)}", flush=True)
            box = page.locator(SEL).bounding_box()
            page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, steps=2)
            jp.watch_pixels(SEL)
            for r in RENDERINGS:
                jp.kernel(f"w.rendering = {r!r}")
                jp.wait_quiet(1.0, timeout=60)
                rest = out / f"{name}-{r}-rest.png"
                page.locator(SEL).screenshot(path=str(rest))
                t0 = jp.page_now()
                page.keyboard.down("4")
                time.sleep(1.0)
                held = out / f"{name}-{r}-held.png"
                page.locator(SEL).screenshot(path=str(held))
                page.keyboard.up("4")
                changes = jp.pixel_changes(after_ms=t0)
                first = f"{changes[0] - t0:.0f} ms" if changes else "never"
                jp.wait_quiet(1.0, timeout=60)
                stats = jp.canvas_stats(SEL)
                drawn = stats and stats.get("count", 0) > 50
                count = stats.get("count") if stats else 0
                print(f"  {r}: first change after the key {first}; at rest {count} pixels not background; "
                      f"{held.name}, {rest.name}", flush=True)
                if not drawn or not changes:
                    failures.append(f"{name} {r}")
            jp.shutdown_kernel()
            page.close()
    if failures:
        print(f"blank or unturned: {', '.join(failures)}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
