"""The page shows the widget's own progress bar while its field is read in the background (issue 35).

A lazily read field on a slow "disk" (every chunk read takes 40 ms: 256 chunks, ~10 s) is shown in
a notebook; the widget starts the background read itself.  While it runs, the bar above the
readout (``.rot4d-progress``) must be visible in the page with the read's own words and count, and
move on; when the read is over it is hidden and the field is in memory.  Before, a big store's
build showed no bar in the page (a kernel bar displayed from the build's thread went to whatever
output was current, if any).
"""

from __future__ import annotations

import re

from jupyter_page import JupyterPage, write_notebook

CELL = '''\
import time
import numpy as np
from rot4d_widget import Rot4DWidget, Field4D

class Slow:
    """A chunked 4-D array on a slow disk: each chunk read takes 40 ms."""

    def __init__(self, a, chunks):
        self.a, self.chunks, self.shape, self.ndim, self.dtype = a, chunks, a.shape, a.ndim, a.dtype

    def __getitem__(self, key):
        time.sleep(0.04)
        return self.a[key]

g = np.linspace(-1.0, 1.0, 48, dtype=np.float32)
a = (g[:, None, None, None] ** 2 + g[None, :, None, None] ** 2 + g[None, None, :, None] ** 2
     + 0.5 * g[None, None, None, :] ** 2).astype(np.float32)
field = Field4D(Slow(a, (12,) * 4), axes="xyzw", extent=[(-1.0, 1.0)] * 4, levels=[0.8], name="T")
w = Rot4DWidget(field)
w'''

_BAR = """
() => {
  const box = document.querySelector('.rot4d-progress');
  if (!box) return null;
  const shown = box.offsetParent !== null && getComputedStyle(box).display !== 'none';
  const fill = box.querySelector('.progress-bar');
  return {shown, text: box.innerText, width: fill ? fill.style.width : null};
}
"""


def test_the_page_shows_the_background_read_on_the_widget_s_bar(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "progress.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "progress.ipynb").open()
    jp.run_all(timeout=180)
    cls = jp.kernel("print(w.scene.canvas_class)").strip()
    page.wait_for_selector(f".{cls} canvas", timeout=60_000)
    seen = jp.wait_for(lambda: (b := page.evaluate(_BAR)) and b["shown"] and b, timeout=30)
    assert seen, f"the bar never showed in the page during the read: {page.evaluate(_BAR)}"
    page.locator(".rot4d-progress").scroll_into_view_if_needed()
    page.screenshot(path=str(artifacts / f"progress-{jupyter_server.kind}.png"))
    m = re.search(r"reading T into memory: (\d+)/(\d+)", seen["text"])
    assert m and 0 < int(m[1]) < int(m[2]), seen
    later = jp.wait_for(lambda: (b := page.evaluate(_BAR)) and b["shown"]
                        and (n := re.search(r": (\d+)/", b["text"])) and int(n[1]) > int(m[1]) and b, timeout=30)
    assert later, "the bar did not move on"
    gone = jp.wait_for(lambda: not page.evaluate(_BAR)["shown"], timeout=60)
    assert gone, "the bar stayed after the read"
    assert jp.kernel("print(field.resident is not None and field.coarse_ready)").strip() == "True"
