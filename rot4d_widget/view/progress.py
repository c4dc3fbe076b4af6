"""Progress bars in a kernel: the one in a cell's output, and the one inside a widget.

`rot4d_widget.core.progress` counts and decides when to show; this module draws.  `WidgetBar` is
the bar a kernel shows in the cell's output (an ipywidgets ``IntProgress`` and a label "12/33,
4 s"), registered with the core on import (`rot4d_widget.core.progress.register_widget_bar`);
`ViewBar` is the bar a `Rot4DWidget` carries above its readout for its source's background work
(a field's read into memory, its coarse copy), attached to that work's `Progress`: the page shows
it while the work runs, whatever cell is running meanwhile, and hides it when the work is over.
"""

from __future__ import annotations

import threading

import ipywidgets
from IPython.display import display

from ..core.progress import register_widget_bar
from ..sources.protocol import prepare_in_background
from .keypad import close_quietly

__all__ = ["WidgetBar", "ViewBar"]


class WidgetBar:
    """An ``IntProgress`` with a label, displayed in the cell's output when made: hidden until first
    shown (a background job's bar is made in the caller's cell, before it is due)."""

    def __init__(self, total: int, description: str = ""):
        self.bar = ipywidgets.IntProgress(value=0, min=0, max=max(int(total), 1), description=description[:20])
        self.label = ipywidgets.Label()
        self.box = ipywidgets.HBox([self.bar, self.label], layout=ipywidgets.Layout(display="none"))
        display(self.box)

    def show(self, count: int, text: str) -> None:
        self.bar.value = count
        self.label.value = text
        self.box.layout.display = None

    def close(self, done: bool) -> None:
        self.bar.bar_style = "success" if done else ""


class ViewBar:
    """A widget's own progress bar (``box``: a label over an ``IntProgress``, CSS class
    ``rot4d-progress``), hidden but while a `Progress` it is attached to is showing: the label
    says what is being done ("reading T into memory") and how far ("12/33, 4 s")."""

    def __init__(self):
        self.bar = ipywidgets.IntProgress(value=0, min=0, max=1, layout=ipywidgets.Layout(width="100%"))
        self.label = ipywidgets.Label()
        self.box = ipywidgets.VBox([self.label, self.bar], layout=ipywidgets.Layout(display="none"))
        self.box.add_class("rot4d-progress")
        self._on_done = None  # called when the work followed is done (`follow`)

    @property
    def visible(self) -> bool:
        return self.box.layout.display != "none"

    def follow(self, source, on_done=None):
        """Start ``source``'s background work (`rot4d_widget.sources.protocol.prepare_in_background`: a
        field's read into memory, or its coarse copy) and show its progress here until it is over; a
        live widget does this for its source when it is made.  ``on_done()``: called, on a thread of
        its own (no lock of the count held), once the work is done -- the widget redraws, so the
        readout says what the read found (a block of NaN).  Returns the
        `rot4d_widget.core.progress.Progress`, or None when there is nothing to do."""
        self._on_done = on_done
        counter = prepare_in_background(source, progress=False)
        if counter is not None:
            counter.attach(self)
        return counter

    def show(self, description: str, count: int, total: int, text: str) -> None:
        with self.bar.hold_sync():
            self.bar.max = max(int(total), 1)
            self.bar.value = min(int(count), self.bar.max)
        self.label.value = f"{description}: {text}"
        self.box.layout.display = None

    def close(self, done: bool) -> None:
        self.box.layout.display = "none"
        if done and self._on_done is not None:
            threading.Thread(target=self._on_done, name="rot4d-read-done", daemon=True).start()

    @property
    def widgets(self) -> tuple:
        """The ipywidgets it is made of (each closed with its own layout and style: `close_widgets`)."""
        return self.box, self.bar, self.label

    def close_widgets(self) -> None:
        """Close the ipywidgets, their layouts and styles too (the widget closing); never raises."""
        for w in self.widgets:
            close_quietly(w)


register_widget_bar(WidgetBar)
