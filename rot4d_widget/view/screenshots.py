"""The screenshot protocol: ask the page for a PNG of the view, take the answer when it comes.

The kernel handles the page's answer only after the running cell ends, so nothing waits: a
request gets an id, the companion asks every view, the first answer counts.  Unanswered
requests are dropped after `SCREENSHOT_TIMEOUT` and beyond `MAX_PENDING_SCREENSHOTS`.  Key p
writes a numbered file (``rot4d-001.png`` ...) in the current directory, never overwriting and
never through a link.
"""

from __future__ import annotations

import os
import stat
import warnings

__all__ = ["Screenshots", "SCREENSHOT_TIMEOUT", "MAX_PENDING_SCREENSHOTS", "png_size_text"]

#: Screenshot requests no view answered are dropped after this many seconds ...
SCREENSHOT_TIMEOUT = 10.0
#: ... and at most this many wait at once (the oldest is dropped).
MAX_PENDING_SCREENSHOTS = 8

#: Key p's request: a numbered file in the current directory, named when the picture arrives.
KEY_P = object()


class Screenshots:
    """One widget's screenshot requests (the pump's lock held by the callers that say so)."""

    def __init__(self, pump, scene, companion, errors):
        self.pump, self.scene, self.companion, self.errors = pump, scene, companion, errors
        self.painter = self.keys = None  # `connect`
        #: The PNG of the view the page sent last (`Rot4DWidget.screenshot`, key p), or None.
        self.last = None
        self.pending = {}  # request id -> (path, callback, time asked): asked, not answered yet
        self.seq = 0
        self.shot_number = 1  # key p's next file number (rot4d-001.png ...)
        self.owed = []  # requests to send once the picture of the latest state has left

    def connect(self, painter, keys) -> None:
        """The painter (whose readout says what became of a request) and the keys (none held: a
        request goes to the page at once)."""
        self.painter, self.keys = painter, keys

    def ask(self, path, callback, warn=False):
        """Ask every view for a PNG (lock held); the request id, or None when no view is shown."""
        # asked in any case: a front end that does not count views (count 0) may still answer;
        # unanswered requests are dropped after SCREENSHOT_TIMEOUT and beyond
        # MAX_PENDING_SCREENSHOTS, so none piles up whatever is pressed
        now = self.pump.clock()
        for old in [k for k, v in self.pending.items() if now - v[2] > SCREENSHOT_TIMEOUT]:
            del self.pending[old]  # nobody answered: dropped
        while len(self.pending) >= MAX_PENDING_SCREENSHOTS:
            del self.pending[next(iter(self.pending))]
        self.seq += 1
        rid = self.seq
        self.pending[rid] = (path, callback, now)
        if self.pump.dirty or self.keys.held:
            self.owed.append(rid)  # asked of the page after the picture of the latest state (`send_owed`)
        else:
            self.companion.request_screenshot(rid)
        if self.scene.view_count == 0:  # kept, bounded by the timeout and the cap above
            text = "no view is displayed to answer: no screenshot (display the widget first)"
            self.painter.set_note(text)
            if warn:  # from code: say it where the code runs (key p: the readout says it)
                warnings.warn(f"Rot4DWidget.screenshot: {text}", stacklevel=3)
            return None
        shown = "rot4d-NNN.png" if path is KEY_P else path
        self.painter.set_note(f"screenshot asked{' for ' + str(shown) if shown is not None else ''}\u2026")
        return rid

    def send_owed(self) -> None:
        """After the picture of the latest state left (the pump's send, no key held): the requests
        asked meanwhile go to the page now, after that picture, so it shows the state they asked
        of (the page also waits until its own steps and the kernel's state agree)."""
        if self.owed and not self.pump.dirty and not self.keys.held:
            owed, self.owed = self.owed, []
            for rid in owed:
                if rid in self.pending:
                    self.companion.request_screenshot(rid)

    def key_p(self) -> None:
        """Key p: a numbered PNG in the current directory (rot4d-001.png, ...), never overwriting
        and never through a link; the number is chosen when the picture arrives."""
        self.ask(KEY_P, None)

    def answer(self, rid, png, error) -> None:
        """A view answered request ``rid`` (the first answer counts; later views' are dropped).
        Never raises (it runs in the companion's message handler): a note that cannot be shown
        (its send failed) or a callback's error goes to the widget's errors area.  The file is
        written with the pump's lock free (a slow disk never holds up keys)."""
        try:
            with self.pump.lock:
                asked = self.pending.pop(rid, None)
                if asked is None or self.pump.closed:
                    return
                if png is not None:
                    self.last = png
            path, callback, _ = asked
            note = self._saved(path, png, error)
            with self.pump.lock:
                if not self.pump.closed:
                    self.painter.set_note(note)
        except Exception as exc:
            self.errors.report(exc)
            return
        if callback is not None and png is not None:
            try:
                callback(png)
            except Exception as exc:  # shown like any callback error, never lost
                self.errors.report(exc)

    def _saved(self, path, png, error) -> str:
        """Write the answer where it was asked to go; the readout's note on what became of it."""
        if png is None:
            return f"screenshot failed: {error}"
        if path is None:
            return f"kept as last_screenshot ({png_size_text(png)})"
        try:
            if path is KEY_P:
                path, self.shot_number = write_numbered_png(png, self.shot_number)
            else:
                path = write_png(path, png)
        except OSError as exc:
            return f"screenshot not saved: {exc}"
        return f"saved {path} ({png_size_text(png)})"


#: O_NONBLOCK: opening a FIFO for writing with no reader fails at once (ENXIO) instead of waiting
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_PNG_FLAGS = os.O_WRONLY | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0) | _NONBLOCK


def write_png(path, png: bytes) -> str:
    """Write ``png`` to ``path`` (replacing a regular file), never through a link at that name and
    never into anything but a regular file (a FIFO, a device: OSError, without waiting)."""
    name = os.fspath(path)
    if os.path.islink(name):
        raise OSError(f"{name} is a link: a screenshot is never written through one")
    if os.path.exists(name) and not os.path.isfile(name):
        raise OSError(f"{name} is not a regular file: a screenshot is written only into one")
    fd = os.open(name, _PNG_FLAGS, 0o666)
    with os.fdopen(fd, "wb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # it became something else since
            raise OSError(f"{name} is not a regular file: a screenshot is written only into one")
        if _NONBLOCK:
            os.set_blocking(fd, True)
        f.truncate(0)
        f.write(png)
    return name


def write_numbered_png(png: bytes, start: int) -> tuple:
    """Key p: write ``png`` as the first free ``rot4d-NNN.png`` (N >= ``start``) in the current
    directory, never overwriting anything, not even a dangling link.  Returns (name, next N)."""
    for n in range(max(int(start), 1), max(int(start), 1) + 100000):
        name = f"rot4d-{n:03d}.png"
        if os.path.lexists(name):
            continue
        try:
            fd = os.open(name, _PNG_FLAGS | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        with os.fdopen(fd, "wb") as f:
            f.write(png)
        return name, n + 1
    raise OSError("no free rot4d-NNN.png name in the current directory")


def png_size_text(png: bytes) -> str:
    """'600 x 500 px' from a PNG's header (IHDR), or its byte count if it has none."""
    if len(png) >= 24 and png[12:16] == b"IHDR":
        return f"{int.from_bytes(png[16:20], 'big')} \u00d7 {int.from_bytes(png[20:24], 'big')} px"
    return f"{len(png)} bytes"
