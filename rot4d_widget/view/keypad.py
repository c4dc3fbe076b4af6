"""The on-screen key pad: a button per bound action, for a mouse or a touch screen.

A click is one step; a button held down repeats exactly like a held key (the same
`rot4d_widget.view.keyhold.KeyRepeater`) and stops on release or on leaving it.  Built when
first shown, under the canvas.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

import ipywidgets as widgets
from ipyevents import Event
from ipywidgets.widgets.widget import _instances

from . import markup
from .keys import page_time

__all__ = ["KeyPad", "PAD_ROWS", "PAD_EVENTS", "close_quietly"]

log = logging.getLogger(__name__)

#: The key pad: (row title, ((key, shift), ...)); keys not bound in the keymap are left out.
PAD_ROWS = (
    ("simple", tuple((k, False) for k in "23468c")),
    ("inverse", tuple((k, True) for k in "23468c")),
    ("double", (("y", False), ("z", False), ("w", False), ("y", True), ("z", True), ("w", True))),
    ("\u03b1, c0", (("k", False), ("j", False), ("l", False), ("h", False))),
    ("step", (("+", False), ("-", False), ("r", False))),
)
PAD_EVENTS = ("mousedown", "mouseup", "mouseleave", "touchstart", "touchend", "touchcancel")


class KeyPad:
    """One widget's key pad: ``box`` (None until first shown) and its buttons' ``events``."""

    def __init__(self, canvas_box, state, scene, pump, keys, errors):
        self.canvas_box = canvas_box  # the pad goes under the canvas, in this box
        self.state, self.scene, self.pump, self.keys, self.errors = state, scene, pump, keys, errors
        self.box = None
        self.events = []

    def show(self, visible: bool) -> None:
        """Show (building it the first time) or hide the pad; hiding releases held keys."""
        if visible and self.box is None:
            self.box = self.build()
            self.canvas_box.children = (*self.canvas_box.children, self.box)
        if self.box is not None:
            if not visible:  # first: hiding must release them even if the layout's send fails
                self.keys.release_all()
            self.box.layout.display = None if visible else "none"

    def build(self):
        """Rows of buttons, one per bound action in `PAD_ROWS`; each button's presses feed the
        same repeater as keys (ipyevents mouse and touch events on the button).  If building
        fails halfway (a comm that raises), every widget made for it is closed again."""
        before = set(_instances)
        try:
            return self._make()
        except BaseException:
            made = [x for k, x in list(_instances.items()) if k not in before]
            self.events = [ev for ev in self.events if ev not in made]
            for x in made:
                close_quietly(x)
            raise

    def _make(self):
        keymap = self.state.keymap
        rows = []
        for title, row in PAD_ROWS:
            buttons = []
            for key, shift in row:
                found = keymap.resolve(key, shift)
                if found is None:
                    continue
                action, inverted = found
                b = widgets.Button(
                    description=action.label(inverted),
                    tooltip=f"{'Shift+' if shift else ''}{key}: {action.describe()}",
                    layout=widgets.Layout(width="auto", min_width="3.6em", height="2.2em", padding="0 0.3em"),
                )
                b.add_class("rot4d-pad-button")
                # for the page, which steps the pad's keys itself (page/turning.js): whose, which key
                b.add_class(f"{self.scene.canvas_class}-pad")
                b.add_class(f"rot4d-pad-key-{ord(key):x}" + ("-shift" if shift else ""))
                ev = Event(source=b, watched_events=list(PAD_EVENTS), prevent_default_action=True)
                ev.on_dom_event(lambda event, key=key, shift=shift: self.handle(key, shift, event))
                self.events.append(ev)
                buttons.append(b)
            if buttons:
                label = markup.html_widget(markup.keypad_label_html(title), layout=widgets.Layout(width="4.5em"))
                rows.append(widgets.HBox([label, *buttons], layout=widgets.Layout(flex_flow="row wrap")))
        box = widgets.VBox(rows, layout=widgets.Layout(margin="0.3em 0 0 0"))
        box.add_class("rot4d-keypad")
        return box

    def handle(self, key, shift, event) -> None:
        """A key pad button: mousedown / touchstart press its key, the rest release it. Never raises."""
        try:
            etype = event.get("type") if isinstance(event, Mapping) else None
            key_id = f"pad:{key}{'+shift' if shift else ''}"
            if etype in ("mousedown", "touchstart"):
                if etype == "mousedown" and event.get("button", 0) != 0:
                    return  # the main button only (a right click opens no repeat)
                found = self.state.keymap.resolve(key, shift)
                if found is None or self.keys.no_view():
                    return
                action, inverted = found
                with self.pump.lock:
                    if self.pump.closed or key_id in self.keys.held:
                        return  # a touch's emulated mousedown: one press only
                    self.keys.press(key_id, action, inverted, page_time(event))
            elif etype in ("mouseup", "mouseleave", "touchend", "touchcancel"):
                self.keys.release(key_id, page_time(event))
        except Exception as exc:  # shown, never lost, never raised into the kernel
            self.errors.report(exc)

    def close(self) -> None:
        """Close the buttons' Events first (their document listeners go before the buttons), then
        every widget of the pad; never raises."""
        for ev in self.events:
            close_quietly(ev)
        if self.box is not None:
            for row in self.box.children:
                for x in row.children:
                    close_quietly(x)
                close_quietly(row)
            close_quietly(self.box)


#: The widgets a widget makes for itself when it is made (its defaults): closed with it.
OWN_PARTS = ("layout", "style", "shadowMap")  # shadowMap: a pythreejs WebGLRenderer's own


def close_quietly(w) -> None:
    """Close a widget and the widgets it made for itself (`OWN_PARTS`: its Layout, Style, a renderer's
    WebGLShadowMap); never raises (close() must not stop halfway)."""
    subs = [getattr(w, name, None) for name in OWN_PARTS] if isinstance(w, widgets.Widget) else []
    try:
        w.close()
    except Exception:
        log.debug("closing %r failed", w, exc_info=True)
    for sub in subs:
        if isinstance(sub, widgets.Widget):
            try:
                sub.close()
            except Exception:
                log.debug("closing %r failed", sub, exc_info=True)
