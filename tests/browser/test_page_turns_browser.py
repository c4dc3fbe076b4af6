"""The page steps its own copy of the state and the kernel ends where the page is (issue 34),
in JupyterLab 4 and Notebook 7.

Keys held over the view step the page's copy at once (its test hook on the canvas element,
``rot4dPage()``); the kernel applies exactly those steps, in the page's order, by the page's
timestamps and heartbeats.  Two keys held together -- on a kernel made slow on purpose (a
source whose slice sleeps, and a heartbeat handler held up) -- end equal on both sides, and the
page's state does not jump at the release: the state the page shows after every key is up is
the one it showed on the last frame before (it adopts the kernel's, which is the same); a
screenshot asked at the release is of the final state; the recording made while the page
predicted replays bit for bit to where the view ended.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from jupyter_page import _FIND_PANEL, JupyterPage, write_notebook
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

CELLS = [
    '''\
import time
import numpy as np
from rot4d_widget import Rot4DWidget, polytope


class Slow:
    """The 24-cell, sliced slowly (a loaded kernel): every picture takes 0.4 s."""

    def __init__(self):
        from rot4d_widget.sources.protocol import PolytopeSource
        self._inner = PolytopeSource(polytope("24-cell"))
        self.size, self.n_groups, self.name = self._inner.size, self._inner.n_groups, "slow 24-cell"

    def slice(self, matrix, c0):
        time.sleep(0.4)
        return self._inner.slice(matrix, c0)

    def describe(self):
        return {"kind": "slow"}


w = Rot4DWidget("24-cell", width=360, height=300)
w''',
    "s = Rot4DWidget(Slow(), width=360, height=300)\ns",
]


def _page(jp, sel):
    return jp.page.evaluate(f"() => document.querySelector({sel.rsplit(' canvas', 1)[0]!r}).rot4dPage()")


def _kernel(jp, var):
    return jp.kernel_json(f"dict(m={var}.state.matrix.reshape(-1).tolist(), theta0={var}.state.theta0, "
                          f"alpha={var}.state.alpha, c0={var}.state.c0, sid=list({var}._keys.page.state_id), "
                          f"held=list({var}.held_keys))")


def _settled(jp, var, sel):
    k = _kernel(jp, var)
    p = _page(jp, sel)
    return not k["held"] and p and not p["held"] and p["pending"] == 0 and p["upto"] == k["sid"][1]


@pytest.mark.parametrize("var", ["w", "s"])
def test_two_keys_held_together_end_equal_on_page_and_kernel_with_no_jump(jupyter_server, page, var):
    _two_keys(jupyter_server, page, var)


@pytest.mark.remote
@pytest.mark.parametrize("var", ["w", "s"])
def test_two_keys_held_together_on_a_remote_kernel(remote_server, page, var):
    """The same through a proxy delaying every byte (a kernel `REMOTE_RTT_MS` away)."""
    _two_keys(remote_server, page, var)
    t = time.monotonic()
    JupyterPage(page, remote_server, "page_turns.ipynb").kernel("pass")
    assert time.monotonic() - t >= remote_server.rtt_ms / 1000  # the proxy does hold the bytes


def _two_keys(jupyter_server, page, var):
    write_notebook(jupyter_server.root / "page_turns.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "page_turns.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, var)
    jp.page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    start = _page(jp, sel)
    assert start is not None, "the page has no copy of the state"
    jp.page.keyboard.down("4")
    time.sleep(0.6)
    moved = _page(jp, sel)
    assert moved["matrix"] != start["matrix"]  # the page stepped at once, whatever the kernel does
    jp.page.keyboard.down("c")
    time.sleep(0.5)
    jp.page.keyboard.up("4")
    time.sleep(0.3)
    jp.page.keyboard.up("c")
    before = _page(jp, sel)  # the page's state right after the release (its steps all made)
    # a screenshot asked at once waits until page and kernel agree: the picture of the final state
    tag = f"{var}-{getattr(jupyter_server, 'rtt_ms', 0):g}"  # the local and remote runs share the server's folder
    shots = [jupyter_server.root / f"{n}-{tag}.png" for n in ("first", "second")]
    for p in shots:
        p.unlink(missing_ok=True)
    jp.kernel(f"{var}.screenshot({shots[0].name!r})")
    assert jp.wait_for(lambda: _settled(jp, var, sel), timeout=60), (_page(jp, sel), _kernel(jp, var))
    after, kernel = _page(jp, sel), _kernel(jp, var)
    np.testing.assert_allclose(after["matrix"], kernel["m"], rtol=0, atol=1e-12)
    assert (after["theta0"], after["alpha"], after["c0"]) == (kernel["theta0"], kernel["alpha"], kernel["c0"])
    np.testing.assert_allclose(before["matrix"], after["matrix"], rtol=0, atol=1e-12)  # no jump at release
    time.sleep(1.0)
    jp.kernel(f"{var}.screenshot({shots[1].name!r})")
    assert jp.wait_for(lambda: all(p.exists() and p.stat().st_size for p in shots), timeout=30)
    from PIL import Image

    a, b = (np.asarray(Image.open(p).convert("RGB"), dtype=int) for p in shots)
    assert a.shape == b.shape and np.abs(a - b).max() <= 2, "the first screenshot was not of the final state"
    # a replay of the recording made while the page predicted ends where the view ended, bit for bit
    same = jp.kernel_json(f"bool((({var}.recording.replay().matrix == {var}.state.matrix)).all())")
    assert same, "the recording does not replay to the view's state"
    steps = jp.kernel(f"print(sum(1 for e in {var}.recording.events if getattr(e, 'key', 0) is None))")
    assert int(steps.strip()) > 10  # both keys repeated


#: Start a cell that keeps the kernel's main thread busy for ``s`` seconds, without waiting for it.
_BUSY = "(s) => { const panel = (" + _FIND_PANEL + ")(); " \
        "panel.sessionContext.session.kernel.requestExecute({code: `import time; time.sleep(${s})`, " \
        "store_history: false}); return true; }"


def test_a_key_released_while_a_cell_runs_stops_where_the_page_released_it(jupyter_server, page):
    """A cell keeps the kernel busy as the key comes up: ipyevents' keyup waits for the cell (its
    comm's messages go to the main thread), the companion's heartbeats do not (JupyterLab sends
    widget messages on a subshell).  The heartbeats carry the page's key events, so the kernel stops
    the key when the page did; the page shows no step past its release meanwhile, and the kernel
    ends on the page's state with the page's steps recorded."""
    write_notebook(jupyter_server.root / "page_busy.ipynb", CELLS[:1])
    jp = JupyterPage(page, jupyter_server, "page_busy.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, "w")
    jp.page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    assert _page(jp, sel) is not None, "the page has no copy of the state"
    jp.page.keyboard.down("4")
    time.sleep(1.0)
    jp.page.evaluate(_BUSY, 2.0)
    time.sleep(0.3)
    jp.page.keyboard.up("4")
    time.sleep(0.1)
    released = _page(jp, sel)
    seen = []
    for _ in range(12):  # while the cell runs: the page shows its release, nothing past it
        time.sleep(0.1)
        seen.append(_page(jp, sel)["matrix"])
    assert not released["held"]
    for m in seen:
        np.testing.assert_allclose(m, released["matrix"], rtol=0, atol=1e-12)
    assert jp.wait_for(lambda: _settled(jp, "w", sel), timeout=60), (_page(jp, sel), _kernel(jp, "w"))
    kernel, after = _kernel(jp, "w"), _page(jp, sel)
    np.testing.assert_allclose(kernel["m"], released["matrix"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(after["matrix"], released["matrix"], rtol=0, atol=1e-12)
    assert jp.kernel_json("bool(((w.recording.replay().matrix == w.state.matrix)).all())")
