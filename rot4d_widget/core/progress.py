"""A progress bar for long work, shown only once the work has taken more than a second.

    bar = progress(total, "rendering frames")
    for item in work:
        ...
        bar.update()      # one more done (update(n): n more)
    bar.close()

or ``with progress(total, "...") as bar:``.  Where it shows:

* in a Jupyter kernel with a front end (IPython's ``get_ipython()`` has a ``kernel``): the bar
  the view registered (`register_widget_bar`: `rot4d_widget.view.progress`, an ipywidgets
  ``IntProgress`` and a label "12 / 33, 4 s", displayed in the cell's output); the package
  registers it as soon as any of its names is used in a kernel (``rot4d_widget.__getattr__``),
  so a field's coarse copy shows a bar in a notebook that never made a widget;
* elsewhere, when stderr is a terminal: one text line on stderr, rewritten in place
  ("rendering frames  12/33 [#####     ] 4 s"), ended by a new line on `Progress.close`;
* otherwise (a pipe, a log file, a CI run): nothing.

Nothing appears before ``delay`` seconds (default 1) have passed since `progress` was called, so
quick work stays silent.  Work done on another thread (a field's background read) creates its
`Progress` in the caller's thread with ``reserve=True``: the kernel's bar is then placed in the
caller's cell output at once, hidden until it is due, rather than wherever output goes when the
thread first draws.  ``attach(view)`` shows the same count on another display too (the widget's
own bar in the page: `rot4d_widget.view.progress.ViewBar`), whatever the mode.
`Progress.update` may be called from any thread (a background job); it costs a clock reading
and, at most every 0.1 s, a redraw.  This module is in the core: it
imports no widget library; the widget bar is the view's (`register_widget_bar`).
"""

from __future__ import annotations

import sys
import threading
import time

from .validate import int_in_range

__all__ = ["Progress", "progress", "in_kernel", "register_widget_bar"]

#: ``factory(total, description)`` -> an object with ``show(count, text)`` and ``close(done)``:
#: the bar a kernel shows (registered by the view); None: no bar in a kernel.
_widget_bar = None


def register_widget_bar(factory) -> None:
    """Make ``factory(total, description)`` the bar shown in a kernel (the view registers one)."""
    global _widget_bar
    if factory is not None and not callable(factory):
        raise TypeError(f"Expected a callable (total, description) -> bar, got {type(factory).__name__}")
    _widget_bar = factory

#: Seconds of work before a bar appears.
DELAY = 1.0
#: Seconds between redraws of a text line.
_REDRAW = 0.1


def in_kernel() -> bool:
    """True when running in an IPython kernel that has a front end to show widgets in."""
    ip_mod = sys.modules.get("IPython")
    if ip_mod is None:
        return False
    try:
        ip = ip_mod.get_ipython()
    except Exception:  # an IPython too old or half imported
        return False
    return getattr(ip, "kernel", None) is not None


class Progress:
    """Counts done items out of ``total`` and shows it (see the module docstring).

    ``update(n=1)`` adds ``n`` done items; ``close()`` ends the display (a bar left full at the
    end, a text line ended); ``count`` is the number done so far.  ``mode`` is ``"widget"``,
    ``"text"`` or ``"none"`` (None: chosen from where the code runs); ``file`` the text stream
    (default ``sys.stderr``; text is written only if it is a terminal unless ``mode="text"``
    is asked for); ``clock`` the time source (``time.monotonic``); ``reserve``: in widget mode,
    make the kernel's bar now (placed in the caller's output, hidden until due).  ``attach`` adds
    a view; ``closed`` says the work is over.
    """

    def __init__(self, total: int, description: str = "", *, delay: float = DELAY, mode: str | None = None,
                 file=None, clock=time.monotonic, reserve: bool = False):
        total = int_in_range(total, "total", 0)
        if mode not in (None, "widget", "text", "none"):
            raise ValueError(f"Expected `mode` to be 'widget', 'text', 'none' or None, got {mode!r}")
        self.total = total
        self.description = str(description)
        self.count = 0
        self._delay = float(delay)
        self._clock = clock
        self._t0 = clock()
        self._file = sys.stderr if file is None else file
        if mode is None:
            if in_kernel():
                mode = "widget" if _widget_bar is not None else "none"
            else:
                isatty = getattr(self._file, "isatty", None)
                mode = "text" if isatty is not None and isatty() else "none"
        self.mode = mode
        self._lock = threading.Lock()
        self._shown = False
        self._closed = False
        self._last = -1.0
        self._bar = self._label = None
        #: other displays of the count: objects with ``show(description, count, total, text)`` and
        #: ``close(done)`` (`attach`)
        self._views = []
        self._reserved = bool(reserve) and self.mode == "widget" and _widget_bar is not None
        if self._reserved:
            self._bar = _widget_bar(self.total, self.description)

    # -- the public API ----------------------------------------------------------------------
    def update(self, n: int = 1) -> None:
        """``n`` more items done; shows or redraws the bar when due."""
        with self._lock:
            if self._closed:
                return
            self.count = min(self.total, self.count + int(n)) if self.total else self.count + int(n)
            now = self._clock()
            if (self.mode == "none" and not self._views) or now - self._t0 < self._delay:
                return
            if self._shown and now - self._last < _REDRAW and self.count < self.total:
                return
            self._draw(now)

    def close(self) -> None:
        """End the display; a bar shown stays, showing the final count."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            done = self.count >= self.total
            if self._shown:
                self._draw(self._clock())
                if self.mode == "text":
                    self._file.write("\n")
                    self._file.flush()
            if self._bar is not None and (self._shown or self._reserved):
                self._bar.close(done)
            for view in self._views:
                view.close(done)

    def attach(self, view) -> None:
        """Show the count on ``view`` too -- an object with ``show(description, count, total, text)``
        and ``close(done)`` -- under the same rules (after ``delay``, at most every 0.1 s), drawn at
        once when the bar is already showing, closed with it; nothing when the work is over."""
        for name in ("show", "close"):
            if not callable(getattr(view, name, None)):
                raise TypeError(f"Expected a view with show(description, count, total, text) and close(done), "
                                f"got {type(view).__name__} without {name!r}")
        with self._lock:
            if self._closed:
                return
            self._views.append(view)
            if self._shown:
                view.show(self.description, self.count, self.total, self._text(self._clock()))

    @property
    def closed(self) -> bool:
        """True once `close` was called: the work is over (done or given up)."""
        return self._closed

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- drawing -----------------------------------------------------------------------------
    def _text(self, now: float) -> str:
        return f"{self.count}/{self.total}, {now - self._t0:.0f} s"

    def _draw(self, now: float) -> None:
        self._last = now
        self._shown = True
        text = self._text(now)
        for view in self._views:
            view.show(self.description, self.count, self.total, text)
        if self.mode == "none":
            return
        if self.mode == "widget":
            if self._bar is None:
                if _widget_bar is None:
                    return
                self._bar = _widget_bar(self.total, self.description)
            self._bar.show(self.count, text)
        else:
            width = 24
            full = int(width * self.count / self.total) if self.total else width
            line = f"\r{self.description}  [{'#' * full}{' ' * (width - full)}] {text}"
            self._file.write(line)
            self._file.flush()


def progress(total: int, description: str = "", **options) -> Progress:
    """A `Progress` for ``total`` items (``options``: ``delay``, ``mode``, ``file``, ``clock``, ``reserve``)."""
    return Progress(total, description, **options)
