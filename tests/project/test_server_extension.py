"""The server extension that turns Nagle's algorithm off on kernel WebSockets."""

import importlib
import json
import pathlib
import subprocess
import sys
import types

import pytest

from rot4d_widget._server import _load_jupyter_server_extension, nodelay_connection_class

ROOT = pathlib.Path(__file__).resolve().parents[2]


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


# --- starting a server must stay cheap: the extension imports the package's __init__ ---

HEAVY = ("numpy", "scipy", "ipywidgets", "pythreejs")


def _modules_after(statement: str) -> set:
    """Which of HEAVY a fresh interpreter has imported after running ``statement``."""
    code = f"import sys\n{statement}\nprint(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    return set(out.stdout.split())


def test_loading_the_extension_imports_no_numpy_scipy_or_widgets():
    """Every Jupyter server in the environment imports rot4d_widget._server at start (0.55-0.72 s
    when the package's __init__ imported the numpy core eagerly)."""
    assert _modules_after("import rot4d_widget._server") == set()
    assert _modules_after("import rot4d_widget; dir(rot4d_widget); rot4d_widget.__all__") == set()


def test_the_check_above_can_fail():
    """The same probe sees numpy as soon as a public name of the core is used."""
    assert "numpy" in _modules_after("from rot4d_widget import polytope")
    assert "ipywidgets" not in _modules_after("from rot4d_widget import polytope")


def test_public_names_resolve_lazily_from_their_modules():
    import rot4d_widget

    assert set(rot4d_widget.__all__) <= set(dir(rot4d_widget))
    for name in rot4d_widget.__all__:
        module = importlib.import_module(f"rot4d_widget.{rot4d_widget._LAZY[name]}")
        assert getattr(rot4d_widget, name) is getattr(module, name), name
    from rot4d_widget import Polytope, polytope
    from rot4d_widget.geometry.slicing import polytope_slice

    assert isinstance(polytope("5-cell"), Polytope) and polytope_slice.TOLERANCE > 0
    with pytest.raises(AttributeError, match="no attribute 'nonesuch'"):
        rot4d_widget.nonesuch


@pytest.mark.parametrize("old", ["fields", "slicing", "widget", "readout"])
def test_the_module_paths_from_before_the_wings_are_gone(old):
    """No import hook and no submodule attributes before 1.0 (issue 38): a module is imported by
    its path in its wing (CHANGELOG lists where each went)."""
    import rot4d_widget

    assert old not in rot4d_widget.__all__ and old not in dir(rot4d_widget)
    with pytest.raises(AttributeError, match=f"no attribute '{old}'"):
        getattr(rot4d_widget, old)
    with pytest.raises(ModuleNotFoundError, match=f"rot4d_widget.{old}"):
        importlib.import_module(f"rot4d_widget.{old}")


def test_a_table_entry_for_a_missing_module_breaks_nothing(monkeypatch):
    """Names are added to the table while their modules are being written (issue 7)."""
    import rot4d_widget

    monkeypatch.setitem(rot4d_widget._LAZY, "Future", "not_written_yet")
    assert not hasattr(rot4d_widget, "Future")
    with pytest.raises(AttributeError, match="no module rot4d_widget.not_written_yet"):
        rot4d_widget.Future
