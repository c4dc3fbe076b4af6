"""The server extension that turns Nagle's algorithm off on kernel WebSockets."""

import json
import pathlib
import sys
import types

from rot4d_widget._server import _load_jupyter_server_extension, nodelay_connection_class


class FakeHandler:
    def __init__(self):
        self.nodelay = None

    def set_nodelay(self, value):
        self.nodelay = value


class BaseConnection:
    calls: list = []

    def __init__(self, handler):
        self.websocket_handler = handler

    def connect(self):
        BaseConnection.calls.append(self.websocket_handler.nodelay if hasattr(self.websocket_handler, "nodelay") else None)
        return "connected"


def test_connect_sets_nodelay_then_connects_as_before():
    cls = nodelay_connection_class(BaseConnection)
    handler = FakeHandler()
    assert issubclass(cls, BaseConnection)
    assert cls(handler).connect() == "connected"
    # Nagle was off before the base class connected
    assert handler.nodelay is True and BaseConnection.calls[-1] is True


def test_wrapping_is_idempotent_and_survives_a_handler_without_stream():
    cls = nodelay_connection_class(BaseConnection)
    assert nodelay_connection_class(cls) is cls

    class Broken:
        def set_nodelay(self, value):
            raise AttributeError("no stream")

    assert cls(Broken()).connect() == "connected"


def test_loader_wraps_the_configured_class():
    logged = []
    app = types.SimpleNamespace(
        web_app=types.SimpleNamespace(settings={"kernel_websocket_connection_class": BaseConnection}),
        log=types.SimpleNamespace(info=logged.append),
    )
    _load_jupyter_server_extension(app)
    cls = app.web_app.settings["kernel_websocket_connection_class"]
    assert cls is not BaseConnection and issubclass(cls, BaseConnection)
    assert logged and "TCP_NODELAY" in logged[0]


def test_the_install_enables_the_extension():
    path = pathlib.Path(sys.prefix) / "etc" / "jupyter" / "jupyter_server_config.d" / "rot4d_widget.json"
    assert path.is_file(), f"{path} not installed: pip install -e . should put it there"
    assert json.loads(path.read_text()) == {"ServerApp": {"jpserver_extensions": {"rot4d_widget._server": True}}}
