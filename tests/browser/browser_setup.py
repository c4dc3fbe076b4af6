"""The browser tests' building blocks, shared with the browser benchmarks (benchmarks/browser_*.py):
where Chromium is found (or installed) and a JupyterLab 4 / Notebook 7 server on 127.0.0.1 in a
temp dir with its own config.  No pytest here: conftest.py makes the fixtures from these.
"""

from __future__ import annotations

import json
import os
import pathlib
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.request

ROOT = pathlib.Path(__file__).resolve().parents[2]
ARTIFACTS = ROOT / "test-artifacts"

CHROMIUM_FLAGS = [
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--enable-precise-memory-info",
]
INSTALL_HINT = (
    "The browser tests need Chromium. Install Debian's package (`sudo apt-get install chromium`), "
    "or Playwright's browser (`python -m playwright install chromium`), or set ROT4D_CHROMIUM to a "
    "Chromium/Chrome executable."
)


def installed_chromium() -> str | None:
    candidates = [os.environ.get("ROT4D_CHROMIUM"), "/usr/bin/chromium", "/usr/bin/chromium-browser",
                  shutil.which("chromium"), shutil.which("chromium-browser"), shutil.which("google-chrome")]
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    return None


def apt_install_chromium() -> str | None:
    if not (hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get")):
        return None
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(["apt-get", "update", "-qq"], env=env, check=False, capture_output=True, timeout=600)
    r = subprocess.run(["apt-get", "install", "-y", "-qq", "chromium"], env=env, check=False,
                       capture_output=True, text=True, timeout=900)
    if r.returncode != 0:
        print(r.stdout[-2000:], r.stderr[-2000:], file=sys.stderr)
    return installed_chromium()


def playwright_chromium() -> str | None:
    try:
        from playwright.sync_api import sync_playwright

        with sync_playwright() as p:
            path = p.chromium.executable_path
        return path if path and os.path.isfile(path) else None
    except Exception:
        return None


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def jupyter_env(home: pathlib.Path, **extra) -> dict:
    """The environment of a server of our own: its Jupyter and IPython dirs under ``home``."""
    return dict(os.environ, JUPYTER_CONFIG_DIR=str(home / "config"), JUPYTER_DATA_DIR=str(home / "data"),
                JUPYTER_RUNTIME_DIR=str(home / "runtime"), IPYTHONDIR=str(home / "ipython"),
                JUPYTER_PLATFORM_DIRS="1", PYTHONUNBUFFERED="1", **extra)


class JupyterServer:
    """A JupyterLab or Notebook 7 server in a temp dir with its own config."""

    def __init__(self, kind: str, workdir: pathlib.Path):
        self.kind = kind
        self.port = free_port()
        self.token = secrets.token_hex(16)
        self.root = workdir / "root"
        self.root.mkdir(parents=True)
        home = workdir / "jupyter"
        self.env = jupyter_env(home)
        # outputs scrolled off-screen stay rendered; no news/announcements pop-ups
        settings = home / "config" / "lab" / "user-settings" / "@jupyterlab"
        (settings / "notebook-extension").mkdir(parents=True)
        (settings / "notebook-extension" / "tracker.jupyterlab-settings").write_text(
            json.dumps({"windowingMode": "none"})
        )
        (settings / "apputils-extension").mkdir(parents=True)
        (settings / "apputils-extension" / "notification.jupyterlab-settings").write_text(
            json.dumps({"fetchNews": "false", "checkForUpdates": False})
        )
        self.log = open(workdir / f"{kind}-server.log", "w")
        self.proc = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def start(self) -> "JupyterServer":
        app = "lab" if self.kind == "lab" else "notebook"
        cmd = [
            sys.executable, "-m", "jupyter", app, "--no-browser", "--allow-root",
            "--ip=127.0.0.1", f"--port={self.port}", f"--IdentityProvider.token={self.token}",
            f"--ServerApp.root_dir={self.root}", "--expose-app-in-browser",
            "--ServerApp.disable_check_xsrf=False", "--LabApp.news_url=",
        ]
        self.proc = subprocess.Popen(cmd, env=self.env, stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"jupyter {app} exited with {self.proc.returncode}; see {self.log.name}")
            try:
                with urllib.request.urlopen(f"{self.url}/api/status?token={self.token}", timeout=2) as r:
                    if r.status == 200:
                        return self
            except OSError:
                time.sleep(0.3)
        raise RuntimeError(f"jupyter {app} did not answer within 120 s; see {self.log.name}")

    def notebook_url(self, name: str) -> str:
        if self.kind == "lab":
            return f"{self.url}/lab/tree/{name}?token={self.token}&reset"
        return f"{self.url}/notebooks/{name}?token={self.token}"

    def _api(self, method: str, path: str):
        req = urllib.request.Request(f"{self.url}/api/{path}", method=method,
                                     headers={"Authorization": f"token {self.token}"})
        with urllib.request.urlopen(req, timeout=30) as r:
            body = r.read()
        return json.loads(body) if body else None

    def kernels(self) -> list:
        """The ids of the kernels running on this server."""
        return [k["id"] for k in self._api("GET", "kernels")]

    def shutdown_kernels(self) -> int:
        """Shut down every session and kernel (a closed page leaves its kernel running, widgets,
        tickers and all, and the server buffers what it sends): how many kernels there were."""
        n = len(self.kernels())
        for s in self._api("GET", "sessions"):
            self._api("DELETE", f"sessions/{s['id']}")
        for k in self.kernels():
            self._api("DELETE", f"kernels/{k}")
        return n

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        self.log.close()


class DelayProxy:
    """A TCP proxy on 127.0.0.1 that holds every chunk of bytes for half of ``rtt_ms`` in each
    direction, keeping their order: the page then sees the kernel as a remote user does (Binder,
    JupyterHub: 50-300 ms away).  Open the page through ``port``; the server sees the same Host
    and Origin, so its token and WebSocket checks pass.  ``rtt_ms`` may change between
    measurements (`set_rtt`).  Runs an asyncio loop in a thread of its own."""

    def __init__(self, target_port: int, rtt_ms: float = 0.0):
        import asyncio
        import threading

        self.target_port = target_port
        self.rtt_ms = float(rtt_ms)
        self.port = free_port()
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, name="delay-proxy", daemon=True)
        self._server = None
        self._thread.start()
        if not self._ready.wait(10):
            raise RuntimeError("the delay proxy did not start")

    def set_rtt(self, rtt_ms: float) -> None:
        self.rtt_ms = float(rtt_ms)

    def _run(self):
        import asyncio

        asyncio.set_event_loop(self._loop)

        async def pipe(reader, writer):
            queue: asyncio.Queue = asyncio.Queue()

            async def read():
                while True:
                    data = await reader.read(65536)
                    await queue.put((time.monotonic() + self.rtt_ms / 2000.0, data))
                    if not data:
                        return

            async def write():
                while True:
                    due, data = await queue.get()
                    wait = due - time.monotonic()
                    if wait > 0:
                        await asyncio.sleep(wait)
                    if not data:
                        writer.close()
                        return
                    writer.write(data)
                    await writer.drain()

            try:
                await asyncio.gather(read(), write())
            except (ConnectionError, OSError):
                writer.close()

        async def handle(client_reader, client_writer):
            try:
                server_reader, server_writer = await asyncio.open_connection("127.0.0.1", self.target_port)
            except OSError:
                client_writer.close()
                return
            for w in (client_writer, server_writer):
                sock = w.get_extra_info("socket")
                if sock is not None:
                    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            await asyncio.gather(pipe(client_reader, server_writer), pipe(server_reader, client_writer),
                                 return_exceptions=True)

        async def start():
            self._server = await asyncio.start_server(handle, "127.0.0.1", self.port)
            self._ready.set()

        self._loop.run_until_complete(start())
        self._loop.run_forever()

    def stop(self) -> None:
        import asyncio

        async def close():
            if self._server is not None:
                self._server.close()
            tasks = [t for t in asyncio.all_tasks(self._loop) if t is not asyncio.current_task()]
            for t in tasks:
                t.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            self._loop.stop()

        asyncio.run_coroutine_threadsafe(close(), self._loop)
        self._thread.join(timeout=5)


class RemoteServer:
    """A `JupyterServer` seen through a `DelayProxy`: the same server, its URLs on the proxy's port."""

    def __init__(self, server: JupyterServer, rtt_ms: float):
        self.server = server
        self.proxy = DelayProxy(server.port, rtt_ms)
        self.rtt_ms = rtt_ms

    def __getattr__(self, name):
        return getattr(self.server, name)

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.proxy.port}"

    def notebook_url(self, name: str) -> str:
        return self.server.notebook_url(name).replace(self.server.url, self.url, 1)

    def stop(self) -> None:
        self.proxy.stop()
