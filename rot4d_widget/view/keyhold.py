"""Held keys: which steps are due when, on an injected clock (no threads, no widgets).

A key's first step happens on keydown (the caller does it); a key still down
``hold_delay`` seconds later repeats ``tick_rate`` times a second, like a
keyboard's auto-repeat but independent of it.  Several held keys step in
time order, then in the order they were pressed.  If the caller was late
(the kernel was busy), at most ``max_lag`` seconds of missed ticks are
replayed and the rest dropped, so a stall never turns into a burst.

Keys are identified by the caller's key id (the browser's ``code``), so the
keyup releases them whatever Shift did meanwhile.

**What a key did is judged by the page's timestamps.**  The kernel may get
round to a keyup late (busy with its first slices, a slow source, a loaded
machine) and its ticker repeats meanwhile.  So a press may carry the page's
time of the keydown and a release the page's time of the keyup (the
browser's ``event.timeStamp``, one clock for both); `release` then returns
the correction that makes the key's steps what a hold of that length gives
(`steps_for`: 1 if shorter than the hold delay, else
``2 + floor((t - hold_delay) * tick_rate)``): negative when the late keyup let
extra steps through (the caller takes them back), positive when the kernel
fell behind (the caller adds them, at most ``max_lag`` worth: a kernel behind
by more than that drops steps).  Only steps that changed something count
(`note_applied`), so a step refused at a bound is never taken back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["KeyRepeater", "steps_for", "HOLD_DELAY", "TICK_RATE", "MAX_LAG", "MAX_TICK_RATE"]

HOLD_DELAY = 0.25
TICK_RATE = 30.0
MAX_LAG = 0.25
MAX_TICK_RATE = 240.0


def positive_seconds(name: str, value) -> float:
    """A finite number > 0, or TypeError/ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
        raise TypeError(f"Expected `{name}` to be a positive number, got {type(value).__name__}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"Expected `{name}` to be a positive number, got {type(value).__name__}") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"Expected `{name}` to be a finite number > 0, got {v}")
    return v


def _finite_or_none(t):
    """``t`` as a finite float, or None (missing or malformed page times are ignored, never raised)."""
    if t is None or isinstance(t, bool):
        return None
    try:
        t = float(t)
    except (TypeError, ValueError, OverflowError):
        return None
    return t if math.isfinite(t) else None


@dataclass
class _Held:
    action: object
    inverted: bool
    order: int
    next_due: float
    page_down: float | None = None  # the page's time of the keydown (s), if known
    applied: int = 0  # steps of this key that changed the state (the first included)


def steps_for(duration: float, hold_delay: float, tick_rate: float) -> int:
    """Steps a hold of ``duration`` seconds makes: 1 below the hold delay, else 2 + the ticks after it.

    >>> steps_for(0.1, 0.25, 30), steps_for(0.25, 0.25, 30), steps_for(1.25, 0.25, 30)
    (1, 2, 32)
    """
    if duration < hold_delay:
        return 1
    return 2 + math.floor((duration - hold_delay) * tick_rate + 1e-9)


class KeyRepeater:
    """Held keys and their next tick.

    ``press(key_id, action, inverted, now)`` starts a hold (the first repeat
    is due at ``now + hold_delay``); ``release(key_id)`` and ``clear()`` end
    holds; ``due(now)`` returns the ``(action, inverted)`` steps due by
    ``now``, in order, and advances each key's next tick;
    ``next_deadline()`` is the clock time of the next tick (None when no key
    is held).
    """

    def __init__(self, hold_delay: float = HOLD_DELAY, tick_rate: float = TICK_RATE, max_lag: float = MAX_LAG):
        self.hold_delay = positive_seconds("hold_delay", hold_delay)
        self.tick_rate = positive_seconds("tick_rate", tick_rate)
        if self.tick_rate > MAX_TICK_RATE:
            raise ValueError(f"Expected `tick_rate` in (0, {MAX_TICK_RATE:g}] Hz, got {self.tick_rate}")
        self.period = 1.0 / self.tick_rate
        self.max_steps = max(1, int(math.ceil(positive_seconds("max_lag", max_lag) * self.tick_rate)))
        self._held: dict = {}
        self._order = 0

    def __len__(self) -> int:
        return len(self._held)

    @property
    def held_keys(self) -> tuple:
        """Ids of the keys held now, in the order pressed."""
        return tuple(k for k, _ in sorted(self._held.items(), key=lambda kv: kv[1].order))

    def press(self, key_id, action, inverted: bool, now: float, *, page_time=None, applied: bool = True) -> None:
        """Key ``key_id`` went down at ``now`` (its first step is the caller's); repeats start later.

        ``page_time``: the page's time of the keydown in seconds (None: unknown, no
        correction at release); ``applied``: the caller's first step changed the state."""
        self._held.pop(key_id, None)
        self._order += 1
        page = _finite_or_none(page_time)
        self._held[key_id] = _Held(action, bool(inverted), self._order, now + self.hold_delay, page, int(bool(applied)))

    def held(self, key_id):
        """``(action, inverted)`` of held key ``key_id``, or None."""
        h = self._held.get(key_id)
        return None if h is None else (h.action, h.inverted)

    def note_applied(self, key_id) -> None:
        """One repeat of ``key_id`` changed the state (it counts for the correction at release)."""
        h = self._held.get(key_id)
        if h is not None:
            h.applied += 1

    def release(self, key_id, page_time=None) -> int:
        """Key ``key_id`` went up; the correction in steps (0 when either page time is unknown).

        Negative: that many of the key's steps are too many (take them back); positive: that
        many are missing (at most ``max_lag`` worth)."""
        h = self._held.pop(key_id, None)
        page = _finite_or_none(page_time)
        if h is None or h.page_down is None or page is None or page < h.page_down:
            return 0
        want = steps_for(page - h.page_down, self.hold_delay, self.tick_rate)
        return min(want - h.applied, self.max_steps)

    def release_all(self, page_time=None) -> list:
        """Every key goes up at ``page_time``: ``[(action, inverted, correction), ...]`` in press order."""
        out = []
        for key_id in self.held_keys:
            h = self._held[key_id]
            out.append((h.action, h.inverted, self.release(key_id, page_time)))
        return out

    def clear(self) -> None:
        self._held.clear()

    def due(self, now: float) -> list:
        """The steps due by ``now`` (time order, then press order); at most ``max_lag`` worth per key."""
        return [(a, inv) for _, a, inv in self.due_keys(now)]

    def due_keys(self, now: float) -> list:
        """`due` with each step's key id: ``[(key_id, action, inverted), ...]``."""
        held = self._held
        if not held:
            return []
        steps = []
        limit = self.max_steps * len(held)
        while len(steps) < limit:
            key_id, h = min(held.items(), key=lambda kv: (kv[1].next_due, kv[1].order))
            if h.next_due > now:
                return steps
            steps.append((key_id, h.action, h.inverted))
            h.next_due += self.period
        self.drop_missed(now)  # the caller was late: drop what is older than max_lag
        return steps

    def drop_missed(self, now: float) -> None:
        """Ticks due by ``now`` that were not run are dropped: the next is one period after ``now``.

        The ticker calls it after a tick that overran, so a slow tick never makes a backlog."""
        for h in self._held.values():
            if h.next_due <= now:
                h.next_due = now + self.period

    def next_deadline(self):
        return min((h.next_due for h in self._held.values()), default=None)
