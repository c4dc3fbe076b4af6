"""`Companion`: the front-end JavaScript the widget needs, as an invisible anywidget.

Display it next to the scene's renderer (e.g. in the same box).  Its module is the page's code,
``rot4d_widget/view/page/*.js`` joined by `rot4d_widget.view.bundle` (no build step), for
JupyterLab 4 and Notebook 7 alike.  The kernel side here hears the page and calls back: "drawn"
after a frame that shows an update (`on_drawn`, `last_draw_time`: the pump's acknowledgement),
the page's clock (`on_clock`), one-time transfers held (`on_holds`), focus lost
(`on_focus_lost`) and screenshots (`request_screenshot`, `on_screenshot`).  The page also applies
what travels with each update, draws the projection, keeps Notebook 7's shortcuts off keys over
the canvas and removes ipyevents' listener when a hovered canvas is destroyed; its listeners go
when the view goes.  How and why: docs/design.md, "The page predicts, the kernel decides" (The
companion).
"""

from __future__ import annotations

import base64
import binascii
import math

import anywidget
from ipywidgets import CallbackDispatcher, Layout
from traitlets import Dict, List, Unicode

from .bundle import page_module
from .pagecut import PageCut
from .pagefield import PageField
from .transfer import Transfers

__all__ = ["Companion", "MAX_CLOCK_EDGES"]

#: The page's key events one heartbeat carries at most (the page keeps as many unacknowledged).
MAX_CLOCK_EDGES = 256


class Companion(anywidget.AnyWidget):
    """Invisible front-end helper for one `Scene`.

    ``Companion(scene)`` reads ``scene.buffer_model_id``,
    ``scene.scene_model_id``, ``scene.canvas_class``, ``scene.geometry_model_ids``,
    ``scene.mesh_model_ids`` and ``scene.texture_model_ids``; they can also be given as keyword
    arguments.
    """

    _esm = page_module()

    buffer_model_id = Unicode("").tag(sync=True)
    scene_model_id = Unicode("").tag(sync=True)
    canvas_class = Unicode("").tag(sync=True)
    geometry_model_ids = List(Unicode()).tag(sync=True)
    mesh_model_ids = List(Unicode()).tag(sync=True)
    texture_model_ids = List(Unicode()).tag(sync=True)
    #: the projection's edges mesh, crossings mesh and Scene (empty: no projection shown)
    projection_model_ids = List(Unicode()).tag(sync=True)
    #: the projection canvas's CSS class (its key guards and its test hook)
    projection_class = Unicode("").tag(sync=True)
    #: what the page needs to step its own copy of the state (`pagestate.page_config`): the key
    #: table, the bounds, the hold delay and tick rate, the kinds it steps
    config = Dict().tag(sync=True)
    #: the kernel's state and its id (`pagestate.state_message` under "state", "epoch", "upto": the
    #: page time in ms up to which it holds the page's steps, None before any; "picture": the id of
    #: the scene update that shows it, None when the picture shown does, "pending" when one is owed;
    #: "keys": the page's keys it holds as held, ``[kid, page time pressed]``): the page adopts it and
    #: applies its later steps on top -- unless its own key events say the state is not what they
    #: make (a release the kernel has not heard yet) -- and a screenshot waits until they agree
    kernel_state = Dict().tag(sync=True)
    #: the one-time transfers the kernel offers, name -> key (`transfer.Transfers`): a page that does
    #: not hold one asks for it
    page_data = Dict().tag(sync=True)
    #: how the page draws its own pictures of a polytope it cuts (`pagecut.PageCut`): the scale, the
    #: group colours packed as the row buffer holds them, one colour for all faces or None
    draw_config = Dict().tag(sync=True)
    #: how the page draws its own pictures of a field it holds (`fieldview.field_config`): the field's
    #: box and frame, the layout of the slices, the rendering's fixed settings and colours
    field_config = Dict().tag(sync=True)

    def __init__(self, scene=None, **kwargs):
        if scene is not None:
            try:
                kwargs.setdefault("buffer_model_id", scene.buffer_model_id)
                kwargs.setdefault("scene_model_id", scene.scene_model_id)
                kwargs.setdefault("canvas_class", scene.canvas_class)
                kwargs.setdefault("geometry_model_ids", list(scene.geometry_model_ids))
                kwargs.setdefault("mesh_model_ids", list(scene.mesh_model_ids))
                kwargs.setdefault("texture_model_ids", list(getattr(scene, "texture_model_ids", ())))
            except AttributeError:
                raise TypeError(f"Expected `scene` to be a rot4d_widget Scene, got {type(scene).__name__}") from None
        kwargs.setdefault("layout", Layout(display="none", width="0px", height="0px"))
        super().__init__(**kwargs)
        self._drawn_handlers = CallbackDispatcher()
        self._focus_handlers = CallbackDispatcher()
        self._screenshot_handlers = CallbackDispatcher()
        self._clock_handlers = CallbackDispatcher()
        self._holds_handlers = CallbackDispatcher()
        self.transfers = Transfers(self)
        self.page_cut = PageCut(self)
        self.page_field = PageField(self)
        self.last_drawn = None  # the last "drawn" id a page sent, awaited or not
        self.last_draw_time = None  # its seconds from the update's arrival to that "drawn", if said
        self.on_msg(self._handle_message)

    def request_screenshot(self, request_id: int) -> None:
        """Ask every displayed view for a PNG of its canvas; the answers reach `on_screenshot`."""
        self.send({"event": "screenshot", "id": int(request_id)})

    def on_screenshot(self, callback, remove=False):
        """Call ``callback(request_id, png_bytes_or_None, error_or_None)`` as a view answers."""
        self._screenshot_handlers.register_callback(callback, remove=remove)

    def on_drawn(self, callback, remove=False):
        """Call ``callback(update_id)`` when the page has drawn that update."""
        self._drawn_handlers.register_callback(callback, remove=remove)

    def on_clock(self, callback, remove=False):
        """Call ``callback(t_ms, edges)`` with the page's clock (ms, the key events' timeStamp clock)
        as the page sends it with the steps it makes while a key is held and with each key event,
        and the page's key events the kernel has not acknowledged (as the page sent them, at most
        `MAX_CLOCK_EDGES`: `rot4d_widget.view.keys.KeyPath.heartbeat` checks each)."""
        self._clock_handlers.register_callback(callback, remove=remove)

    def on_holds(self, callback, remove=False):
        """Call ``callback(name)`` when a page says it holds the one-time transfer ``name``."""
        self._holds_handlers.register_callback(callback, remove=remove)

    def on_focus_lost(self, callback, remove=False):
        """Call ``callback(reason, t_ms)`` (``"blur"`` or ``"hidden"``; the page's time, or None) when
        the page loses focus."""
        self._focus_handlers.register_callback(callback, remove=remove)

    def _handle_message(self, _widget, content, _buffers=None):
        if not isinstance(content, dict):
            return
        event = content.get("event")
        if event == "drawn":
            seq = content.get("seq")
            if isinstance(seq, int) and not isinstance(seq, bool):
                ms = content.get("draw_ms")
                ok = isinstance(ms, (int, float)) and not isinstance(ms, bool) and 0 <= ms < math.inf
                self.last_drawn, self.last_draw_time = seq, float(ms) / 1e3 if ok else None
                self._drawn_handlers(seq)
        elif event == "screenshot":
            rid = content.get("id")
            if not isinstance(rid, int) or isinstance(rid, bool):
                return
            png, error = _png_from_data_url(content.get("png")), content.get("error")
            if png is None and not error:
                error = "the page sent no PNG"
            self._screenshot_handlers(rid, png, None if png is not None else str(error))
        elif event == "focus_lost":
            reason, t = content.get("reason"), content.get("t")
            ok = isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t)
            self._focus_handlers(reason if isinstance(reason, str) else "", float(t) if ok else None)
        elif event in ("want", "holds", "got"):
            name, key = content.get("name"), content.get("key")
            if isinstance(name, str) and isinstance(key, str):
                if event == "want":
                    self.transfers.want(name, key)
                elif event == "got":
                    self.transfers.got(name, key, content.get("part"))
                else:
                    self.page_cut.holds(name, key)
                    self.page_field.holds(name, key)
                    self._holds_handlers(name)
        elif event == "clock":
            t, edges = content.get("t"), content.get("edges")
            if isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t):
                self._clock_handlers(float(t), edges[:MAX_CLOCK_EDGES] if isinstance(edges, list) else [])


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png_from_data_url(url):
    """The bytes of a ``data:image/png;base64,...`` URL, or None if it is not one."""
    prefix = "data:image/png;base64,"
    if not isinstance(url, str) or not url.startswith(prefix):
        return None
    try:
        data = base64.b64decode(url[len(prefix):], validate=True)
    except (ValueError, binascii.Error):
        return None
    return data if data.startswith(_PNG_SIGNATURE) else None
