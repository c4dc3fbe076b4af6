"""Real-browser fixtures: a JupyterLab 4 / Notebook 7 server on 127.0.0.1 and headless Chromium.

The browser is provided here, by the test command itself: an installed
Chromium is used; where none is installed and we run as root with apt
(CI, the project's machines) Debian's ``chromium`` is installed; otherwise
Playwright's own download is used if present.  With none of these the tests
FAIL with a message naming what to install: they never skip silently.

Recipe (../shared/notes/jupyter-stack.md): Playwright for Python driving the
Chromium binary with SwiftShader WebGL; the server gets a token, isolated
config/data/runtime dirs and ``--expose-app-in-browser`` so the page has
``window.jupyterapp`` (run cells, record commands, talk to the kernel).
"""

from __future__ import annotations

import os
import pathlib
import shutil

import pytest
from browser_setup import (  # the building blocks, shared with benchmarks/browser_*.py
    ARTIFACTS,
    CHROMIUM_FLAGS,
    INSTALL_HINT,
    ROOT,
    JupyterServer,
    RemoteServer,
    apt_install_chromium,
    installed_chromium,
    playwright_chromium,
)


def pytest_collection_modifyitems(config, items):
    for item in items:
        if "tests/browser/" in str(item.fspath).replace(os.sep, "/"):
            item.add_marker(pytest.mark.browser)


@pytest.fixture(scope="session")
def chromium_path() -> str:
    path = installed_chromium() or apt_install_chromium() or playwright_chromium()
    if not path:
        pytest.fail(INSTALL_HINT, pytrace=False)
    return path


@pytest.fixture(scope="session", params=["lab", "notebook"])
def jupyter_server(request, tmp_path_factory):
    server = JupyterServer(request.param, tmp_path_factory.mktemp(f"jupyter-{request.param}"))
    for nb in (ROOT / "notebooks").glob("*.ipynb"):
        shutil.copy(nb, server.root / nb.name)
    server.start()
    yield server
    server.stop()


#: The round trip of the remote subset (tests marked ``remote``): a kernel on Binder or JupyterHub
REMOTE_RTT_MS = float(os.environ.get("ROT4D_RTT_MS", "120"))


@pytest.fixture(scope="session")
def remote_server(jupyter_server):
    """The same server seen through a proxy delaying every byte by half of `REMOTE_RTT_MS` each way."""
    remote = RemoteServer(jupyter_server, REMOTE_RTT_MS)
    yield remote
    remote.stop()


@pytest.fixture(scope="session")
def playwright_instance():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        yield p


@pytest.fixture
def browser_context(playwright_instance, chromium_path, tmp_path):
    ctx = playwright_instance.chromium.launch_persistent_context(
        str(tmp_path / "chromium-profile"),
        executable_path=chromium_path,
        headless=True,
        args=CHROMIUM_FLAGS,
        viewport={"width": 1400, "height": 1000},
    )
    yield ctx
    ctx.close()


@pytest.fixture
def page(browser_context):
    pg = browser_context.pages[0] if browser_context.pages else browser_context.new_page()
    pg.console_messages = []
    pg.page_errors = []
    pg.on("console", lambda m: pg.console_messages.append((m.type, m.text)))
    # with the first lines of its stack: which plugin or widget threw is what a failure needs to say
    pg.on("pageerror", lambda e: pg.page_errors.append(f"{e}\n{(getattr(e, 'stack', None) or '')[:600]}"))
    yield pg


@pytest.fixture(autouse=True)
def _fresh_kernels(request):
    """After each test on a server (its page closed), shut its kernels down: each test starts from
    a fresh kernel, and none left running (a notebook's widgets, a ticker) loads the tests after."""
    yield
    if "jupyter_server" in request.fixturenames:
        request.getfixturevalue("jupyter_server").shutdown_kernels()


@pytest.fixture(scope="session")
def artifacts() -> pathlib.Path:
    ARTIFACTS.mkdir(exist_ok=True)
    return ARTIFACTS
