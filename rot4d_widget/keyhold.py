"""Held keys: which steps are due when, on an injected clock (no threads, no widgets).

A key's first step happens on keydown (the caller does it); a key still down
``hold_delay`` seconds later repeats ``tick_rate`` times a second, like a
keyboard's auto-repeat but independent of it.  Several held keys step in
time order, then in the order they were pressed.  If the caller was late
(the kernel was busy), at most ``max_lag`` seconds of missed ticks are
replayed and the rest dropped, so a stall never turns into a burst.

Keys are identified by the caller's key id (the browser's ``code``), so the
keyup releases them whatever Shift did meanwhile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["KeyRepeater", "HOLD_DELAY", "TICK_RATE", "MAX_LAG", "MAX_TICK_RATE"]

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


@dataclass
class _Held:
    action: object
    inverted: bool
    order: int
    next_due: float


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

    def press(self, key_id, action, inverted: bool, now: float) -> None:
        """Key ``key_id`` went down at ``now`` (its first step is the caller's); repeats start later."""
        self._held.pop(key_id, None)
        self._order += 1
        self._held[key_id] = _Held(action, bool(inverted), self._order, now + self.hold_delay)

    def release(self, key_id) -> None:
        self._held.pop(key_id, None)

    def clear(self) -> None:
        self._held.clear()

    def due(self, now: float) -> list:
        """The steps due by ``now`` (time order, then press order); at most ``max_lag`` worth per key."""
        held = self._held
        if not held:
            return []
        steps = []
        limit = self.max_steps * len(held)
        while len(steps) < limit:
            h = min(held.values(), key=lambda h: (h.next_due, h.order))
            if h.next_due > now:
                return steps
            steps.append((h.action, h.inverted))
            h.next_due += self.period
        for h in held.values():  # the caller was late: drop what is older than max_lag
            if h.next_due <= now:
                h.next_due = now + self.period
        return steps

    def next_deadline(self):
        return min((h.next_due for h in self._held.values()), default=None)
