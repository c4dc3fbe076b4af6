"""Driving a notebook in JupyterLab 4 / Notebook 7 through ``window.jupyterapp``."""

from __future__ import annotations

import json
import time

import nbformat

_FIND_PANEL = """
() => {
  const app = window.jupyterapp;
  if (!app) return null;
  let w = app.shell.currentWidget;
  if (!(w && w.sessionContext)) {
    for (const x of app.shell.widgets('main')) { if (x.sessionContext) { w = x; break; } }
  }
  return w && w.sessionContext ? w : null;
}
"""

_KERNEL_EXEC = (
    """
async (code) => {
  const find = """
    + _FIND_PANEL
    + """;
  const panel = find();
  const kernel = panel.sessionContext.session.kernel;
  const future = kernel.requestExecute({code, store_history: false, silent: false});
  let out = ""; let err = null;
  future.onIOPub = (msg) => {
    const t = msg.header.msg_type;
    if (t === "stream") out += msg.content.text;
    else if (t === "execute_result") out += msg.content.data["text/plain"];
    else if (t === "error") err = msg.content.ename + ": " + msg.content.evalue;
  };
  await future.done;
  return {out, err};
}
"""
)

_CANVAS_STATS = """
([selector, bg]) => {
  const c = document.querySelector(selector);
  if (!c) return null;
  const w = c.width, h = c.height;
  const tmp = document.createElement('canvas'); tmp.width = w; tmp.height = h;
  const ctx = tmp.getContext('2d');
  ctx.drawImage(c, 0, 0);
  const d = ctx.getImageData(0, 0, w, h).data;
  if (!bg) bg = [d[0], d[1], d[2]];
  let x0 = w, y0 = h, x1 = -1, y1 = -1, n = 0, hash = 2166136261;
  for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
    const i = 4 * (y * w + x);
    hash = Math.imul(hash ^ (d[i] + 3 * d[i + 1] + 7 * d[i + 2]), 16777619) >>> 0;
    if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) {
      n++; if (x < x0) x0 = x; if (x > x1) x1 = x; if (y < y0) y0 = y; if (y > y1) y1 = y;
    }
  }
  const r = c.getBoundingClientRect();
  return {width: w, height: h, cssWidth: r.width, cssHeight: r.height, left: r.left, top: r.top,
          count: n, bbox: n ? [x0, y0, x1, y1] : null, hash};
}
"""


def write_notebook(path, cells: list[str]) -> None:
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(c) for c in cells]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, str(path))


class JupyterPage:
    """A page showing one notebook, with helpers to run it and talk to its kernel."""

    def __init__(self, page, server, name: str):
        self.page = page
        self.server = server
        self.name = name

    def open(self, timeout: float = 120.0) -> "JupyterPage":
        self.page.goto(self.server.notebook_url(self.name))
        self.page.wait_for_function(
            "() => { const f = " + _FIND_PANEL + "; const p = f();"
            " return p && p.sessionContext.session && p.sessionContext.session.kernel"
            " && p.sessionContext.session.kernel.connectionStatus === 'connected'"
            " && p.sessionContext.session.kernel.status === 'idle'; }",
            timeout=timeout * 1000,
        )
        self.page.evaluate(
            "() => { window.__executed = []; window.jupyterapp.commands.commandExecuted.connect("
            "(_, a) => window.__executed.push(a.id)); }"
        )
        return self

    def run_all(self, timeout: float = 120.0) -> None:
        self.page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
        self.wait_idle(timeout)

    def wait_idle(self, timeout: float = 120.0) -> None:
        # every code cell executed and the kernel idle
        self.page.wait_for_function(
            "() => { const f = " + _FIND_PANEL + "; const p = f(); if (!p) return false;"
            " const k = p.sessionContext.session.kernel; if (k.status !== 'idle') return false;"
            " const cells = p.content.widgets.filter(c => c.model.type === 'code');"
            " return cells.every(c => c.model.executionCount !== null && !c.promptNode?.textContent?.includes('*')); }",
            timeout=timeout * 1000,
        )

    def kernel(self, code: str, timeout: float = 60.0) -> str:
        res = self.page.evaluate(_KERNEL_EXEC, code)
        if res["err"]:
            raise AssertionError(f"kernel error running {code!r}: {res['err']}")
        return res["out"]

    def kernel_json(self, expr: str):
        return json.loads(self.kernel(f"import json as _j; print(_j.dumps({expr}))"))

    def shutdown_kernel(self) -> None:
        """Shut the notebook's kernel down (best effort: the page may already be going)."""
        try:
            self.page.evaluate("async () => { const f = " + _FIND_PANEL + "; await f().sessionContext.shutdown(); }")
        except Exception:
            pass

    def executed_commands(self) -> list[str]:
        return self.page.evaluate("() => window.__executed.slice()")

    def notebook_model(self) -> dict:
        return self.page.evaluate(
            "() => { const f = " + _FIND_PANEL + "; const p = f();"
            " return {cells: p.content.model.cells.length,"
            " types: Array.from({length: p.content.model.cells.length}, (_, i) => p.content.model.cells.get(i).type),"
            " sources: Array.from({length: p.content.model.cells.length}, (_, i) => p.content.model.cells.get(i).sharedModel.getSource())}; }"
        )

    def canvas_stats(self, selector: str, background=None) -> dict | None:
        """Pixel statistics of a canvas: size, bbox of non-background pixels, a hash.

        The background is the top-left pixel unless given as (r, g, b).
        """
        return self.page.evaluate(_CANVAS_STATS, [selector, list(background) if background else None])

    def last_canvas_change(self, selector: str, since: float, watch: float, interval: float = 0.05) -> float:
        """Watch a canvas until ``watch`` s after ``since`` (time.monotonic()).

        Returns the monotonic time of the last change of its pixels seen, or
        ``since`` if none: how long after ``since`` the view settled.
        """
        last, h = since, self.canvas_stats(selector)["hash"]
        while time.monotonic() - since < watch:
            s = self.canvas_stats(selector)["hash"]
            if s != h:
                last, h = time.monotonic(), s
            time.sleep(interval)
        return last

    def wait_for(self, predicate, timeout: float = 10.0, interval: float = 0.05):
        deadline = time.monotonic() + timeout
        while True:
            value = predicate()
            if value:
                return value
            if time.monotonic() > deadline:
                return value
            time.sleep(interval)
