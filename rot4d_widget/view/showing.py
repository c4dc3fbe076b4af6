"""`Showing`: the source a widget shows, and the one way to change it.

Every unit of the view that slices, samples or changes the source shares one `Showing`: the source
(a single view's, or the stack made around it when `slices` is set), the scale it is drawn at, the
lock that ``source.slice`` and every change of the source take (never the pump's lock inside it),
and a version that goes up on every change -- the painter's caches and a slice computed outside
the pump's lock compare it, so a picture of a source that changed meanwhile is never shown.
"""

from __future__ import annotations

import threading

from ..sources.protocol import w_frame

__all__ = ["Showing", "C0_LIMIT_SIZES", "fit_c0_range"]

#: The l / h keys keep |c0| within this many times the source's size (`RotationState.c0_limit`).
C0_LIMIT_SIZES = 2.0


def fit_c0_range(state, source) -> None:
    """The l / h range of ``state`` from ``source``'s w frame: twice its size about its centre."""
    origin, per = w_frame(source)
    state.c0_origin = origin
    state.c0_limit = C0_LIMIT_SIZES * float(source.size) * per


class Showing:
    """The shown source, its display scale, its lock and its version."""

    def __init__(self, source, scale: float):
        self.source = source
        self.scale = float(scale)
        self.lock = threading.RLock()
        self.version = 0

    def changed(self) -> None:
        """The source's settings or data changed: what was computed from it is stale."""
        self.version += 1

    def replace(self, source) -> None:
        """Show ``source`` from now on (a single view made a stack)."""
        with self.lock:
            self.source = source
        self.version += 1

    def still(self, source, version: int) -> bool:
        """True while ``source`` at ``version`` is what is shown (a slice made from it may be shown)."""
        return self.version == version and self.source is source
