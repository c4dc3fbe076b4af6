"""A held key's steps by the page's clock: the schedule both the page and the kernel follow.

A key pressed at page time ``down`` (ms, the browser event's ``timeStamp``) makes its first step
then; held, its k-th repeat (k >= 1) is due at ``down + hold + (k - 1) * period`` (``hold`` the
hold delay, ``period`` 1000 / tick rate, both in ms); released at page time ``up``, its steps are
those due at or before ``up``.  Several keys step in time order, a tie in the order pressed.  The
page (``page/keys.js``) computes the same numbers with the same IEEE operations in the same order,
so both sides agree on every step and its order, whoever is late.

The kernel knows how far the page's clock has gone by what it has heard from it: every key event
is stamped, and while a key is held the companion sends the page's time with every step it makes
(`hear`).  Messages from the page arrive in the order they left, so when the kernel has heard
page time ``h`` it has every event stamped before ``h`` (an event dispatched a moment after the
heartbeat that followed its stamp is the exception: `StepLog.steps` then differs from what was
applied before, and the caller rebuilds from its checkpoint).

A key's events can come twice, by two ways: ipyevents forwards them, and the companion repeats
every key event the kernel has not acknowledged with each heartbeat -- the two travel on separate
comms, which the kernel may handle on separate threads (JupyterLab 4.4+ sends widget messages on a
subshell, ipykernel routes a comm's messages to the thread it last sent from), so the heartbeat can
outrun the ipyevents event it follows.  A key's events come in time order by either way, so a press
no later than the key's last press heard, or a release no later than its last release heard, is one
heard already (`StepLog.press` and `release` return False).  Presses and releases are compared with
their own kind: a release stamped a moment before its own press (a page whose clock is coarse or
jittered) is still that press's release -- a tap -- never taken for an old one, so no key sticks.

`StepLog` is pure bookkeeping: no state, no threads, no widgets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["StepLog", "PageStep", "step_time", "SAME_MS", "MAX_EDGES"]

#: Two page times of one event as both ways deliver it: ipyevents' timeStamp goes through seconds
#: on its way (``t / 1000 * 1000``), a few ulps from the companion's.
SAME_MS = 1e-6
#: The keys whose last event is remembered (a key's latest event time); the oldest of keys not held
#: are forgotten beyond this.
MAX_EDGES = 512


def step_time(down: float, k: int, hold_ms: float, period_ms: float) -> float:
    """Page time (ms) of a key's k-th step: the first at ``down``, then ``down + hold + (k-1) period``.
    Written as the page writes it (page/keys.js ``stepTime``): the same operations, the same bits."""
    return down if k == 0 else down + hold_ms + (k - 1) * period_ms


@dataclass(frozen=True)
class PageStep:
    """One step of a key: ``t`` its page time (ms), ``order`` its key's press order, ``kid`` the key,
    ``k`` the step's index (0: the press itself), what it does (``action``, ``inverted``)."""

    t: float
    order: int
    kid: str
    k: int
    action: object
    inverted: bool

    @property
    def id(self) -> tuple:
        """What orders steps (and names one): page time, then the order the keys were pressed in."""
        return (self.t, self.order)


@dataclass
class _Key:
    kid: str
    action: object
    inverted: bool
    down: float
    order: int
    repeats: bool
    up: float | None = None
    after: float = -math.inf  # its steps at or before this page time are in the checkpoint


class StepLog:
    """The keys pressed since the last checkpoint and the page time heard; `steps` lists their steps.

    ``hold_delay`` (s) and ``tick_rate`` (Hz) as the widget's.  Times are page milliseconds.  A
    checkpoint (`checkpoint`) takes every step up to a page time as done: the caller keeps the state
    they made, and `steps` lists only later ones.
    """

    def __init__(self, hold_delay: float, tick_rate: float):
        self.hold_ms = hold_delay * 1000.0
        self.period_ms = 1000.0 / tick_rate
        self.keys: dict[str, _Key] = {}  # every key with steps after the checkpoint, held or released
        self.heard = -math.inf  # the latest page time the kernel has heard of
        self.checked = -math.inf  # the page time of the last checkpoint
        self._order = 0
        self._edges: dict[str, list] = {}  # kid -> [page time of its last press, of its last release] heard

    def _heard_already(self, kid: str, t: float, press: bool) -> bool:
        """An event of ``kid`` at ``t`` heard already: a press no later than the key's last press, a
        release no later than its last release (module docs)."""
        last = self._edges.get(kid)
        return last is not None and t <= last[0 if press else 1] + SAME_MS

    def _note_edge(self, kid: str, t: float, press: bool) -> None:
        last = self._edges.pop(kid, [-math.inf, -math.inf])
        last[0 if press else 1] = max(t, last[0 if press else 1])
        self._edges[kid] = last  # the newest last
        if len(self._edges) > MAX_EDGES:
            for old in [k for k in self._edges if self.held_key(k) is None][: len(self._edges) - MAX_EDGES]:
                del self._edges[old]

    # -- events --------------------------------------------------------------------------
    def press(self, kid: str, action, inverted: bool, t: float, repeats: bool) -> bool:
        """Key ``kid`` went down at page time ``t``; False (nothing changes) while it is held already
        (a second keydown without a keyup: a repeat) and for a press heard already (module docs).
        ``repeats``: it steps while held."""
        held = self.keys.get(kid)
        if (held is not None and held.up is None) or self._heard_already(kid, t, True):
            return False
        if held is not None:  # pressed again before a checkpoint: the old press keeps its steps
            self.keys[f"{kid}#{held.order}"] = self.keys.pop(kid)
        self._order += 1
        self.keys[kid] = _Key(kid, action, bool(inverted), float(t), self._order, bool(repeats))
        self._note_edge(kid, float(t), True)
        self.hear(t)
        return True

    def release(self, kid: str, t: float) -> bool:
        """Key ``kid`` went up at page time ``t`` (at least its press); False if it was not held or the
        release was heard already (module docs)."""
        key = self.keys.get(kid)
        if key is None or key.up is not None or self._heard_already(kid, t, False):
            return False
        key.up = max(float(t), key.down)
        self._note_edge(kid, float(t), False)
        self.hear(t)
        return True

    def release_all(self, t: float) -> list:
        """Every held key up at ``t`` (the pointer left, the page lost focus); their ids."""
        return [kid for kid in list(self.keys) if self.release(kid, t)]

    def hear(self, t: float) -> None:
        """The page's clock has reached ``t`` (ms)."""
        if t > self.heard:
            self.heard = float(t)

    @property
    def held(self) -> tuple:
        """Keys down now, in the order pressed."""
        return tuple(k.kid for k in sorted(self.keys.values(), key=lambda k: k.order) if k.up is None)

    def held_since(self) -> list:
        """``[[kid, page time pressed], ...]`` of the keys down now, in the order pressed: what the
        page checks a state of the kernel against (a key it released is not in it)."""
        return [[k.kid, k.down] for k in sorted(self.keys.values(), key=lambda k: k.order) if k.up is None]

    def held_key(self, kid):
        """``(action, inverted)`` of held key ``kid``, or None."""
        key = self.keys.get(kid)
        return None if key is None or key.up is not None else (key.action, key.inverted)

    # -- the schedule -----------------------------------------------------------------------
    def _times(self, key: _Key, upto: float):
        end = upto if key.up is None else min(upto, key.up)
        k = 0
        while True:
            t = step_time(key.down, k, self.hold_ms, self.period_ms)
            if t > end or (k > 0 and not key.repeats):
                return
            if t > key.after:
                yield k, t
            k += 1

    def steps(self, upto: float | None = None) -> list:
        """The steps after the checkpoint due at or before ``upto`` (default: the time heard), in
        order (`PageStep.id`)."""
        upto = self.heard if upto is None else upto
        out = [PageStep(t, key.order, key.kid, k, key.action, key.inverted)
               for key in self.keys.values() for k, t in self._times(key, upto)]
        out.sort(key=lambda s: s.id)
        return out

    def checkpoint(self, t: float) -> None:
        """Every step at or before page time ``t`` is done (the caller keeps the state they made):
        keys released by then go, held ones step on from there."""
        t = float(t)
        self.checked = max(self.checked, t)
        for kid, key in list(self.keys.items()):
            if key.up is not None and key.up <= t:
                del self.keys[kid]
            else:
                key.after = max(key.after, t)
