"""Notebook 01 as a standalone page in Voila, offline (issue 12).

Voila (>= 0.5) runs every cell of a notebook in a kernel and shows only the outputs; the widgets'
JavaScript comes from the JupyterLab extensions installed in the environment (pythreejs's
``jupyter-threejs``, ``ipyevents``, ``anywidget``), served by Voila itself under
``/voila/labextensions/``.  Here every request to anything but 127.0.0.1/localhost is aborted by
the browser (HTTP and WebSocket): there is no CDN fallback to hide a missing extension.  Voila's
own template asks a CDN for Font Awesome's CSS (icons only); those requests are blocked like any
other and must not matter.

The test opens notebook 01, waits for the live widget's canvas to draw, hovers it, holds ``4`` for
a second and checks that the canvas's pixels and the readout changed, that the companion
(anywidget) ran -- its leave guard sits in the canvas element, and its shortcut guard marked the
keys as handled (``defaultPrevented``: Notebook 7's shortcut guard, harmless here) -- and that the
page raised no error.  A screenshot of the widget goes to the test artifacts.

Voila is started as a subprocess on a free port of 127.0.0.1 with a token, isolated Jupyter
config/data/runtime dirs, and a temp copy of the notebooks as its root.  It needs no
``--allow-root`` as root (it has no such check).  This module uses no ``jupyter_server`` fixture,
so it runs once, not once per JupyterLab / Notebook 7 parameter.
"""

from __future__ import annotations

import re
import secrets
import shutil
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request

import pytest

from browser_setup import ROOT, free_port, jupyter_env
from jupyter_page import _CANVAS_STATS
from test_widget_browser import HARMLESS_CONSOLE

NOTEBOOK = "01_pentachoron.ipynb"
LOCAL_HOSTS = {"127.0.0.1", "localhost", "[::1]", "::1"}
#: Console errors from Voila's page itself, not from the widget: the resources the blocking aborted
#: (net::ERR_FAILED), and Notebook 7's lab extension, which Voila also tries to load from the
#: environment's federated extensions and which needs a JupyterLab shell that Voila doesn't have.
VOILA_CONSOLE = ("Failed to load resource: net::ERR_FAILED", "/voila/labextensions/@jupyter-notebook/lab-extension/")
#: Script on the page: record keydown events at `window` in the capture phase (ipyevents stops them
#: at `document`, so none bubble back), after the companion's guard, which was added before, and
#: whether the page's default action was prevented by then.
_RECORD_KEYS = """
() => {
  window.__keys = [];
  window.addEventListener('keydown', (e) => window.__keys.push([e.code, e.defaultPrevented]), true);
}
"""


class VoilaServer:
    def __init__(self, workdir):
        self.port = free_port()
        self.token = secrets.token_hex(16)
        self.root = workdir / "root"
        self.root.mkdir(parents=True)
        home = workdir / "jupyter"
        self.env = jupyter_env(home, MPLBACKEND="Agg")
        self.log_path = workdir / "voila.log"
        self.log = open(self.log_path, "w")
        self.proc = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def render_url(self, name: str) -> str:
        return f"{self.url}/voila/render/{name}?token={self.token}"

    def start(self) -> "VoilaServer":
        cmd = [
            sys.executable, "-m", "voila", str(self.root), "--no-browser", f"--port={self.port}",
            "--Voila.ip=127.0.0.1", f"--token={self.token}", "--show_tracebacks=True",
        ]
        self.proc = subprocess.Popen(cmd, env=self.env, cwd=self.root, stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"voila exited with {self.proc.returncode}; see {self.log_path}")
            try:
                # any HTTP answer means the server is up (Voila has no /api/status)
                urllib.request.urlopen(f"{self.url}/voila/static/?token={self.token}", timeout=2)
                return self
            except urllib.error.HTTPError:
                return self
            except OSError:
                time.sleep(0.3)
        raise RuntimeError(f"voila did not answer within 120 s; see {self.log_path}")

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        self.log.close()


@pytest.fixture(scope="module")
def voila_server(tmp_path_factory):
    if subprocess.run([sys.executable, "-c", "import voila"], capture_output=True).returncode:
        pytest.fail("voila is not installed (it is in the test extra): pip install -e '.[test]'", pytrace=False)
    server = VoilaServer(tmp_path_factory.mktemp("voila"))
    shutil.copy(ROOT / "notebooks" / NOTEBOOK, server.root / NOTEBOOK)
    server.start()
    yield server
    server.stop()


def _is_local(url: str) -> bool:
    if url.startswith(("data:", "blob:", "about:")):
        return True
    return urllib.parse.urlsplit(url).hostname in LOCAL_HOSTS


@pytest.fixture
def offline_page(browser_context, page):
    """The page, with every request to a host other than 127.0.0.1/localhost aborted."""
    page.blocked = []
    page.served = []

    def route(r):
        if _is_local(r.request.url):
            page.served.append(r.request.url)
            r.continue_()
        else:
            page.blocked.append((r.request.resource_type, r.request.url))
            r.abort()

    browser_context.route("**/*", route)

    def refuse_ws(ws):
        page.blocked.append(("websocket", ws.url))
        ws.close()

    browser_context.route_web_socket(re.compile(r"^wss?://(?!(127\.0\.0\.1|localhost|\[::1\])[:/])"), refuse_ws)
    yield page


def _stats(page, sel):
    return page.evaluate(_CANVAS_STATS, [sel, None])


def _wait(predicate, timeout, interval=0.1):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value or time.monotonic() > deadline:
            return value
        time.sleep(interval)


def test_notebook_01_in_voila_offline_turns_with_keys(voila_server, offline_page, artifacts):
    page = offline_page
    t0 = time.monotonic()
    # Voila streams the page while the kernel runs the cells, one after the other, and shows the
    # outputs (#rendered_cells) once the last has run: then nothing but keys changes the view
    page.goto(voila_server.render_url(NOTEBOOK), timeout=300_000)
    page.wait_for_selector("#rendered_cells", state="visible", timeout=300_000)
    # the first live widget (cell "widget"): pythreejs's renderer div carries the scene's classes
    sel = ".rot4d-canvas canvas"
    page.wait_for_selector(sel, timeout=300_000)
    drawn = _wait(lambda: (s := _stats(page, sel)) and s["count"] > 50 and s, timeout=60)
    assert drawn, f"the canvas stayed empty: {_stats(page, sel)}"
    loaded = time.monotonic() - t0

    # what the page loaded: the widgets' JavaScript from Voila's own server, nothing from outside
    ext = sorted({u.split("/voila/labextensions/")[1].split("/static/")[0]
                  for u in page.served if "/voila/labextensions/" in u})
    for name in ("jupyter-threejs", "ipyevents", "anywidget"):
        assert name in ext, f"{name} not loaded from Voila's labextensions: {ext}"
    scripts = [u for kind, u in page.blocked if kind == "script"]
    assert not scripts, f"scripts wanted from outside: {scripts}"

    # the companion (anywidget) ran: its leave guard is in the canvas element
    assert _wait(lambda: page.evaluate(
        "(sel) => !!document.querySelector(sel).parentElement.querySelector('rot4d-leave-guard')", sel), 30), \
        "no <rot4d-leave-guard> in the canvas element: the companion did not run"

    widget = page.locator(sel).first
    widget.scroll_into_view_if_needed()
    readout = page.locator(".rot4d-readout").first
    # settled: the same picture twice, half a second apart
    before = _wait(lambda: (a := _stats(page, sel), time.sleep(0.5), b := _stats(page, sel))
                   and a["hash"] == b["hash"] and b, timeout=30)
    assert before, "the canvas kept changing before any key"
    page.evaluate(_RECORD_KEYS)

    box = widget.bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    time.sleep(0.3)
    page.keyboard.down("4")
    time.sleep(1.0)
    page.keyboard.up("4")

    after = _wait(lambda: (s := _stats(page, sel))["hash"] != before["hash"] and s, timeout=20)
    assert after, "holding 4 over the canvas did not change its pixels"
    assert after["count"] > 50, after
    # the readout follows at a few hertz while a key repeats, exactly at rest: wait for the count
    def turned_steps():
        m = re.search(r"R_xw\s*[x\u00d7]\s*(\d+)", readout.inner_text())
        return int(m.group(1)) if m and int(m.group(1)) >= 2 else None

    assert _wait(turned_steps, timeout=20), f"a held 4 should have turned several steps: {readout.inner_text()}"

    # the shortcut guard (for Notebook 7) marked the key as handled, and ipyevents still forwarded it
    keys = page.evaluate("() => window.__keys")
    assert keys and all(code == "Digit4" and prevented for code, prevented in keys), keys

    time.sleep(1.0)  # let a held key's last steps land before the picture
    page.screenshot(path=str(artifacts / "voila-01-pentachoron.png"))
    widget.screenshot(path=str(artifacts / "voila-01-canvas.png"))

    bad = [t for kind, t in page.console_messages if kind == "error"
           and not any(h in t for h in HARMLESS_CONSOLE + VOILA_CONSOLE)]
    assert not page.page_errors, page.page_errors
    assert not bad, bad
    print(f"Voila: notebook 01 drawn {loaded:.1f} s after opening; extensions {ext}; "
          f"blocked {page.blocked}")
