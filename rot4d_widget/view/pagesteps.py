"""The kernel's side of the page's keys: exactly the steps the page makes, in the page's order.

The page steps its own copy of the state as a key is held (``page/keys.js``); the kernel, which
owns the truth, applies the same steps (`StepLog`'s schedule by the page's timestamps) in the
same order, as far as it has heard the page's clock, and never drops one.  When what it heard
changes steps it already applied -- a keyup that the page dispatched a moment after a heartbeat
stamped later, a page time estimated ahead of a page that stalled -- it rebuilds from its last
checkpoint: the state there, then every step again (`Applied.rebuilt`).  A recording gets what
happened: each step as applied, and for a rebuild the checkpoint's values (set exactly) followed
by the steps again, so a replay ends bit for bit where the view ended.

**State ids.**  The state the kernel holds is named by ``(epoch, upto)``: it has every page step
due at or before page time ``upto`` (ms), and ``epoch`` counts the changes that started in the
kernel (a trait, a slider, code, a replay, a loaded file, a source's own key).  The page takes
the kernel's state for an id and applies its own steps after ``upto`` on top (client-side
prediction with server reconciliation); a change from the kernel is placed at ``upto``.

A checkpoint is taken when no key is held (the state becomes the base) and before a change that
starts in the kernel (`sync_external` notices one by the state no longer being what the last
step made, and starts a new epoch from it).

Besides the state, a field's view settings are stepped the same way (issue 36: its rendering,
section planes and levels; ``view``, a `rot4d_widget.view.fieldkeys.FieldKeys`): their steps are
the kernel's own (recorded as those are), their snapshot part of the checkpoint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .steplog import PageStep, StepLog

__all__ = ["PageSteps", "Applied", "LastStep", "PREDICTED_KINDS", "HEARTBEAT_STALE"]

#: The state's own actions, which the page steps itself: rotations, alpha, c0, theta0, reset.
PREDICTED_KINDS = frozenset({"rotate", "alpha", "c0", "theta0", "reset"})

#: With a key held and no word from the page for this long (kernel seconds), the kernel goes on by
#: its own clock's estimate of the page's (a front end without the companion's heartbeats).
HEARTBEAT_STALE = 0.2
#: During a long hold, steps older than this (page ms) behind the time heard are done (`_roll`): no
#: event stamped that long before a heartbeat arrives after it (messages keep their order; only an
#: event dispatched a moment after a heartbeat does, by a few ms) ...
SETTLED_MS = 1000.0
#: ... once this many steps are kept since the checkpoint (three seconds at 30 Hz).
ROLL_STEPS = 90


class LastStep:
    """The readout's "last" row: the last step's label and how many times in a row it was made."""

    def __init__(self):
        self.label, self.count = None, 0

    def note(self, label: str) -> None:
        if label == self.label:
            self.count += 1
        else:
            self.label, self.count = label, 1

    def snapshot(self) -> tuple:
        return (self.label, self.count)

    def restore(self, snap: tuple) -> None:
        self.label, self.count = snap


@dataclass(frozen=True)
class Applied:
    """What one `PageSteps.advance` did: ``changed`` -- the state changed; ``rebuilt`` -- it was
    rebuilt from the checkpoint (steps already applied were taken back); ``actions`` -- the actions
    of the steps that changed it, in order."""

    changed: bool
    rebuilt: bool
    actions: tuple


class PageSteps:
    """One widget's page-timed steps (the lock of its pump held by every caller).

    Collaborators: ``state`` (`RotationState`, the authority), ``recorder`` (the widget's
    `rot4d_widget.keep.recorder.Recorder`), ``last`` (`LastStep`), ``clock`` (the pump's, seconds),
    ``view`` (the field's view settings, `FieldKeys`: ``steps(action)``, ``snapshot()``,
    ``restore(snap)``, ``apply(action, inverted)``).
    """

    def __init__(self, state, recorder, last: LastStep, *, hold_delay: float, tick_rate: float, clock, view):
        self.state = state
        self.view = view
        self.recorder = recorder
        self.last = last
        self.clock = clock
        self.log = StepLog(hold_delay, tick_rate)
        self.epoch = 0
        self.upto = -math.inf  # page ms: the state has every step due by then
        #: since the checkpoint: (step, it changed the state, the state and view, and last step after it)
        self._applied: list[tuple[PageStep, bool, tuple, tuple]] = []
        self._base = self._snapshot()
        self._base_last = last.snapshot()
        self._made = self._base  # the state as the last step left it (a change since: the kernel's)
        self._offset = -math.inf  # page ms minus kernel ms: at least this (the latest page time heard, sent)
        self._heartbeat_at = -math.inf  # kernel time of the last word from the page
        self._page_heard = -math.inf  # the latest page time the page itself said (not estimated)

    # -- what the page says -----------------------------------------------------------------
    def _heard_from_page(self, t_ms: float) -> None:
        now = self.clock()
        self._offset = max(self._offset, t_ms - 1000.0 * now)
        self._heartbeat_at = now
        self._page_heard = max(self._page_heard, t_ms)
        self.log.hear(t_ms)

    def press(self, kid, action, inverted: bool, t_ms: float, repeats: bool) -> bool:
        """Key ``kid`` down at page time ``t_ms``; False for a key held already (a repeat)."""
        self.sync_external()
        if not self.log.press(kid, action, inverted, t_ms, repeats):
            return False
        self._heard_from_page(t_ms)
        return True

    def release(self, kid, t_ms: float | None) -> bool:
        """Key ``kid`` up at page time ``t_ms`` (None: the kernel's estimate of the page's clock)."""
        t = self.page_now() if t_ms is None else t_ms
        if not self.log.release(kid, t):
            return False
        if t_ms is not None:
            self._heard_from_page(t_ms)
        return True

    def release_all(self, t_ms: float | None) -> list:
        """Every held key up at ``t_ms`` (None: the kernel's estimate); their ids."""
        t = self.page_now() if t_ms is None else t_ms
        kids = self.log.release_all(t)
        if kids and t_ms is not None:
            self._heard_from_page(t_ms)
        return kids

    def heartbeat(self, t_ms: float) -> None:
        """The companion: the page's clock has reached ``t_ms`` (sent with the page's steps)."""
        self._heard_from_page(t_ms)

    def page_now(self) -> float:
        """The kernel's estimate of the page's clock (ms): its own, moved by the largest difference
        seen (a message arrives after it was stamped, so the estimate is never ahead); the time
        heard if that is later."""
        est = 1000.0 * self.clock() + self._offset if math.isfinite(self._offset) else -math.inf
        return max(self.log.heard, est)

    def tick(self) -> None:
        """With a key held and the page silent for `HEARTBEAT_STALE`, go on by the estimate."""
        if self.log.held and self.clock() - self._heartbeat_at > HEARTBEAT_STALE:
            self.log.hear(self.page_now())

    @property
    def held(self) -> tuple:
        return self.log.held

    def held_key(self, kid):
        return self.log.held_key(kid)

    def held_since(self) -> list:
        """The page's keys the state holds as held, with their press times (`StepLog.held_since`)."""
        return self.log.held_since()

    @property
    def state_id(self) -> tuple:
        """``(epoch, upto)``: the state the kernel holds (module docs)."""
        return (self.epoch, self.upto)

    # -- applying -----------------------------------------------------------------------
    def _snapshot(self) -> tuple:
        return (self.state.snapshot(), self.view.snapshot())

    def sync_external(self) -> bool:
        """If the state changed since the last step (a trait, code, a replay, a source's key ...):
        a checkpoint there and a new epoch.  True if it had."""
        if _same(self._snapshot(), self._made):
            return False
        self._checkpoint(self.upto)
        self.epoch += 1
        return True

    def advance(self) -> Applied:
        """Apply the steps due by the time heard that are not applied yet (rebuilding from the
        checkpoint when those applied are no longer what the page made); at rest, a checkpoint."""
        self.sync_external()
        steps = self.log.steps()
        done = [a[0] for a in self._applied]
        rebuilt = done != steps[: len(done)]
        if rebuilt:
            self.state.restore_snapshot(self._base[0])
            self.view.restore(self._base[1])
            self.last.restore(self._base_last)
            self._record_restore()
            todo, self._applied = steps, []
        else:
            todo = steps[len(done):]
        if todo and todo[0].t <= self.upto and not rebuilt:
            self.epoch += 1  # a step older than the state last named (a late event): a new name
        actions = []
        for step in todo:
            if self.view.steps(step.action):  # a field's key: the kernel's own step, recorded there
                changed = self.view.apply(step.action, step.inverted)
            else:
                changed = self.state.apply(step.action, step.inverted)
                if changed:
                    self.recorder.record(None, False, step.action, step.inverted, t=self._stamp(step.t))
            if changed:
                self.last.note(step.action.label(step.inverted))
                actions.append(step.action)
            self._applied.append((step, changed, self._snapshot(), self.last.snapshot()))
        self.upto = max(self.upto, self.log.heard)
        self._made = self._snapshot()
        if not self.log.held and self.log.keys:
            self._checkpoint(self.upto)
        elif len(self._applied) > ROLL_STEPS:  # only steps the page said it made, long enough ago
            self._roll(min(self.upto, self._page_heard) - SETTLED_MS)
        return Applied(bool(actions) or rebuilt, rebuilt, tuple(actions))

    def _roll(self, t: float) -> None:
        """A checkpoint at page time ``t`` while keys are held (a long hold): the steps due by then
        are done -- the state after the last of them becomes the base -- so each step costs the same
        however long the hold, and a rebuild goes back only to ``t``."""
        done = [i for i, a in enumerate(self._applied) if a[0].t <= t]
        if not done:
            return
        _, _, self._base, self._base_last = self._applied[done[-1]]
        self._applied = self._applied[done[-1] + 1:]
        self.log.checkpoint(t)

    def _checkpoint(self, t: float) -> None:
        """Every step applied is done (they are all due by ``t``, the time last heard): the state now
        is the base a rebuild starts from."""
        self.log.checkpoint(t)
        self._applied = []
        self._base = self._made = self._snapshot()
        self._base_last = self.last.snapshot()

    def _record_restore(self) -> None:
        """A rebuild in the recording: the checkpoint's values, set exactly (the steps follow)."""
        matrix, theta0, alpha, c0 = self._base[0]
        for name, value in (("matrix", matrix), ("theta0", theta0), ("alpha", alpha), ("c0", c0)):
            self.recorder.record_set(name, value)

    def _stamp(self, t_ms: float) -> float:
        """A page time as the recording's time: when the kernel's clock read it (never later than now)."""
        if not math.isfinite(self._offset):
            return self.recorder.since_start(self.clock())
        return self.recorder.since_start(min(self.clock(), (t_ms - self._offset) / 1000.0))


def _same(a: tuple, b: tuple) -> bool:
    """Two snapshots ``(state's, view's)`` equal (the matrices by value)."""
    (sa, va), (sb, vb) = a, b
    return va == vb and sa[1:] == sb[1:] and (sa[0] is sb[0] or bool((sa[0] == sb[0]).all()))
