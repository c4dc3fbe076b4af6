"""The widget draws in a real JupyterLab 4 and Notebook 7 page."""

import pathlib

from jupyter_page import JupyterPage, write_notebook


def test_widget_draws(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "smoke.ipynb", [
        "from rot4d_widget import Rot4DWidget\nw = Rot4DWidget('5-cell')\nw",
    ])
    jp = JupyterPage(page, jupyter_server, "smoke.ipynb").open()
    jp.run_all()
    cls = jp.kernel("print(w.scene.canvas_class)").strip()
    page.wait_for_selector(f".{cls} canvas", timeout=60_000)
    stats = jp.wait_for(lambda: (s := jp.canvas_stats(f".{cls} canvas")) and s["count"] > 100 and s, timeout=30)
    page.screenshot(path=str(artifacts / f"smoke-{jupyter_server.kind}.png"))
    assert stats and stats["count"] > 100, stats
    # the package's server extension is active: kernel WebSockets without Nagle's delay
    jupyter_server.log.flush()
    assert "TCP_NODELAY" in pathlib.Path(jupyter_server.log.name).read_text()
