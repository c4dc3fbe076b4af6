"""Jupyter server extension: send kernel WebSocket frames without Nagle's delay.

jupyter_server does not set TCP_NODELAY on the kernel WebSockets.  Nagle's
algorithm then holds every frame of a burst after the first (the kernel's
"busy" status, then the widget's update) until the browser's delayed ACK, up
to 40 ms.  With at most three updates in flight by design (``MAX_IN_FLIGHT``
in rot4d_widget/view/pump.py), a held key's updates keep meeting that stall.
``benchmarks/browser_latency.py --nagle`` switches this extension off to measure it; the figures
are in docs/performance.md.

This module and the package's ``__init__`` import nothing heavy (no numpy,
scipy or widget library): every Jupyter server in the environment loads it at
start (tests/project/test_server_extension.py checks this in a fresh interpreter).

This extension wraps whatever kernel WebSocket connection class the server
is configured with (it does not replace it) so that the connection turns
Nagle off on its socket when it connects.  It is enabled by the file
``etc/jupyter/jupyter_server_config.d/rot4d_widget.json`` that the package
installs, and only affects a server running in the environment where
rot4d_widget is installed.  Disable it with
``jupyter server extension disable rot4d_widget._server``.
"""

from __future__ import annotations

__all__ = ["nodelay_connection_class"]

_MARK = "_rot4d_nodelay"


def nodelay_connection_class(base: type) -> type:
    """A subclass of the connection class ``base`` whose ``connect`` sets TCP_NODELAY."""
    if getattr(base, _MARK, False):
        return base

    class NoDelayKernelWebsocketConnection(base):
        def connect(self, *args, **kwargs):
            handler = getattr(self, "websocket_handler", None)
            try:
                handler.set_nodelay(True)
            except Exception:  # no stream yet or not a tornado handler: keep the default
                pass
            return super().connect(*args, **kwargs)

    NoDelayKernelWebsocketConnection.__name__ = f"NoDelay{base.__name__}"
    NoDelayKernelWebsocketConnection.__qualname__ = NoDelayKernelWebsocketConnection.__name__
    setattr(NoDelayKernelWebsocketConnection, _MARK, True)
    return NoDelayKernelWebsocketConnection


def _jupyter_server_extension_points():
    return [{"module": "rot4d_widget._server"}]


def _load_jupyter_server_extension(serverapp) -> None:
    settings = serverapp.web_app.settings
    base = settings.get("kernel_websocket_connection_class")
    if base is None:
        # jupyter_server: the extension's module imports nothing heavy (a server loads it at start)
        from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection

        base = ZMQChannelsWebsocketConnection
    settings["kernel_websocket_connection_class"] = nodelay_connection_class(base)
    serverapp.log.info("rot4d_widget: kernel WebSockets send without Nagle's delay (TCP_NODELAY)")
