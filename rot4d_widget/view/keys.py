"""The key path: an ipyevents dict (or a key pad button) -> keymap -> steps -> the pump.

`KeyPath` handles the canvas's key events.  The state's own keys pressed in the page (with the
page's timestamp) take the page's schedule: `rot4d_widget.view.pagesteps.PageSteps` applies
exactly the steps the page makes, in the page's order, as far as the kernel has heard the page's
clock (the page predicts them; the kernel decides).  Every other key -- a source's own, the
view's, the stack's, a key from code or without a page time -- is the kernel's: one step now,
repeats while held by `rot4d_widget.view.keyhold.KeyRepeater`, corrected to the page's
timestamps at release.  A step is recorded and marks the picture dirty.  Nothing here raises into
the event loop: errors go to the widget's ``errors`` area.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

from ..core.keymap import REPEATING_KINDS, RESERVED_KINDS, SHIFT_KINDS, Action, Keymap
from ..sources.protocol import note_matrix
from . import markup
from .fieldkeys import FieldKeys, level_actions
from .pagestate import page_config
from .pagesteps import HEARTBEAT_STALE, PREDICTED_KINDS, LastStep, PageSteps

__all__ = ["KeyPath", "key_id", "page_edge", "page_time", "source_actions", "help_groups"]


class KeyPath:
    """Keys and key pad buttons of one widget, from the event to the pump (the pump's lock held
    where it says so)."""

    def __init__(self, traits, showing, state, repeater, custom, pump, scene, companion, help_panel, errors):
        self.showing, self.state, self.repeater, self.pump, self.errors = showing, state, repeater, pump, errors
        self.scene, self.companion, self.help_panel = scene, companion, help_panel
        #: a source's own keys: ``{action name: (run, repeats)}`` (`source_actions`)
        self.custom = custom
        self.was_displayed = False  # a view of the canvas was counted once
        self.last = LastStep()  # the readout's "last" row
        self.traits = traits  # the widget's traits (the field view's keys step ``rendering``, ``sections``)
        self.painter = self.sync = self.keeper = self.shots = self.renderings = self.stacking = None
        self.page = None  # the page's keys (`PageSteps`), once `connect`ed

    def connect(self, painter, sync, keeper, shots, renderings, stacking) -> None:
        """The units a key's step reaches (each action kind its own), and from now on the page's keys
        by their timestamps (`PageSteps`, recorded by the keeper's recorder)."""
        self.painter, self.sync, self.keeper, self.shots = painter, sync, keeper, shots
        self.renderings, self.stacking = renderings, stacking
        rep = self.repeater
        view = FieldKeys(self.traits, self.showing, renderings, keeper, sync, self.apply_step)
        self.page = PageSteps(self.state, keeper.recorder, self.last, hold_delay=rep.hold_delay,
                              tick_rate=rep.tick_rate, clock=self.pump.clock, view=view)

    @property
    def help_visible(self) -> bool:
        """The key table (key ?) is shown."""
        return self.help_panel.layout.display != "none"

    @help_visible.setter
    def help_visible(self, value: bool) -> None:
        self.help_panel.layout.display = None if value else "none"

    @property
    def held(self) -> tuple:
        """Every key held now: the page's (`PageSteps`) and the kernel's (the repeater)."""
        return self.page.held + self.repeater.held_keys

    # -- events ----------------------------------------------------------------------------
    def handle_event(self, event) -> None:
        """ipyevents callback: never raises."""
        try:
            if not isinstance(event, Mapping):
                return
            etype = event.get("type", event.get("event"))
            if etype == "keydown":
                self.key_down(event)
            elif etype == "keyup":
                kid = key_id(event)
                if kid is not None:
                    self.release(kid, page_time(event))
            elif etype == "mouseleave":
                self.release_all(page_time(event))
        except Exception as exc:  # shown, never lost, never raised into the kernel
            self.errors.report(exc)

    def key_down(self, event: Mapping) -> None:
        if event.get("repeat") is True:
            return  # browser auto-repeat: the ticker repeats, not the browser
        if self.no_view():
            return  # a listener leaked by a destroyed view (ipyevents): act on nothing
        found = self.state.keymap.lookup(event)
        kid = key_id(event)
        if found is None or kid is None:
            return
        action, inverted = found
        with self.pump.lock:
            if self.pump.closed or self.repeater.held(kid) is not None or self.page.held_key(kid) is not None:
                # a keydown of a key held (no keyup between: a browser or an OS that repeats
                # without the repeat flag) is a repeat, not a new press
                return
            self.press(kid, action, inverted, page_time(event))

    def press(self, kid, action: Action, inverted: bool, when=None) -> None:
        """Key (or key pad button) ``kid`` went down: one step now, repeats while held (lock held).

        ``when``: the page's time of the keydown (s), against which the keyup's corrects the
        number of steps (`rot4d_widget.view.keyhold`)."""
        if action.kind == "help":
            self.help_visible = not self.help_visible
            return
        if (action.kind in PREDICTED_KINDS or self.page.view.steps(action)) and when is not None:  # the page's
            repeats = action.kind in REPEATING_KINDS or (action.kind == "custom" and self.custom[action.name][1])
            self.page.press(kid, action, inverted, 1000.0 * when, repeats)
            self.advance()
            self.pump.flush()
            return
        self.advance()  # the page's steps so far come before this one
        now = self.pump.clock()
        changed = self.step(action, inverted)
        if action.kind in REPEATING_KINDS or (action.kind == "custom" and self.custom[action.name][1]):
            self.repeater.press(kid, action, inverted, now, page_time=when, applied=changed)
        self.pump.flush(now)

    def release(self, kid, when=None) -> None:
        """Key (or key pad button) ``kid`` went up at the page's ``when`` (s): no more repeats,
        its steps corrected to what the page says the hold was; at rest, settle."""
        with self.pump.lock:
            if self.page.release(kid, None if when is None else 1000.0 * when):
                self.advance()
            held = self.repeater.held(kid)
            correction = self.repeater.release(kid, when)
            if held is not None:
                self.correct(*held, correction)
            self.settle()

    def release_all(self, when=None) -> None:
        """Every held key up (mouseleave, focus lost, no view left)."""
        with self.pump.lock:
            if self.page.release_all(None if when is None else 1000.0 * when):
                self.advance()
            for action, inverted, correction in self.repeater.release_all(when):
                self.correct(action, inverted, correction)
            self.settle()

    def heartbeat(self, t_ms, edges=()) -> None:
        """Companion: the page's clock has reached ``t_ms`` (it sends it with each step it makes and
        each key event), with the page's key events the kernel has not acknowledged (``edges``,
        `page_edge`): applied first, each once whichever way it came (`StepLog`), so the time heard
        never passes an event the kernel has not had -- ipyevents' way can be held up by a busy
        kernel while this one is not.  Never raises."""
        try:
            if isinstance(t_ms, bool) or not isinstance(t_ms, (int, float)) or not math.isfinite(t_ms):
                return
            with self.pump.lock:
                if self.pump.closed:
                    return
                released = False
                heard = (page_edge(e, self.state.keymap) for e in (edges if isinstance(edges, (list, tuple)) else ()))
                for edge in sorted(filter(None, heard), key=lambda e: e[2]):
                    kid, down, t, found = edge
                    if not down:
                        released = self.page.release(kid, t) or released
                    # (whatever view count the kernel last heard: the page steps only keys over a
                    # canvas of this widget it shows, and the count comes on the canvas's own comm,
                    # which may be handled later -- no step the page has shown is dropped)
                    elif found is not None and found[0].kind in PREDICTED_KINDS and self.repeater.held(kid) is None:
                        self.page.press(kid, found[0], found[1], t, found[0].kind in REPEATING_KINDS)
                self.page.heartbeat(float(t_ms))
                self.advance()
                if released:
                    self.settle()
                self.pump.flush()
        except Exception as exc:
            self.errors.report(exc)

    def advance(self) -> None:
        """The page's steps heard of and not applied yet (lock held): applied, recorded, the picture
        dirty and the traits synced once."""
        applied = self.page.advance()
        if applied.changed:
            self.pump.mark_dirty()
            if any(a.kind == "custom" for a in applied.actions):  # a field's levels (the source changed)
                self.sync.source_traits()
            self.sync.state_traits()
            # the page learns the kernel answers; the picture of this state is owed (the pump sends it)
            self.painter.send_state("pending", throttle=bool(self.page.held))
        else:
            self.painter.send_id(throttle=bool(self.page.held))

    def settle(self) -> None:
        """At rest (no key held): bring the readout up to date and the rows into the turned frame,
        and send a picture still owed (one whose send failed)."""
        if self.pump.closed or self.held:
            return
        if self.painter.readout_stale or not self.painter.settled:
            self.pump.mark_dirty()
        self.pump.flush()

    def correct(self, action: Action, inverted: bool, correction: int) -> None:
        """Take back (``correction`` < 0) or add (> 0) steps of a released key (lock held).

        A late keyup lets the ticker repeat a key the user had already released; the page's
        timestamps say how many steps the hold made, and this makes the state agree.  Each
        step taken back is the opposite step, recorded like any other."""
        if correction < 0:  # however many (a keyup 80 s late): the traits are synced once
            opposite = _opposite(action, inverted)
            undone = sum(self.apply_step(*opposite) for _ in range(-correction))
            if undone:
                last = self.last
                if last.label == action.label(inverted):
                    last.count = max(last.count - undone, 1)
                self.after_steps(action)
        clock = self.pump.clock
        start = clock()
        for _ in range(max(correction, 0)):  # missing steps: within one tick's time, like a tick
            if clock() - start > self.repeater.period:
                break
            self.step(action, inverted)

    def focus_lost(self, reason=None, t_ms=None) -> None:
        """Companion: the page or window lost focus at page time ``t_ms`` (None: not said); no keyup
        will come: every key up then."""
        try:
            ok = isinstance(t_ms, (int, float)) and not isinstance(t_ms, bool) and math.isfinite(t_ms)
            self.release_all(t_ms / 1000.0 if ok else None)
        except Exception as exc:
            self.errors.report(exc)

    def view_count(self, n) -> None:
        """Scene: the canvas has ``n`` views; none left: every key up (no keyup will come)."""
        try:
            if n > 0:
                self.was_displayed = True
            else:
                self.release_all()
        except Exception as exc:
            self.errors.report(exc)

    def no_view(self) -> bool:
        """True when the canvas was displayed and every view of it is gone.

        Front ends that do not count views leave the count at 0 and never set
        ``was_displayed``: their keys are always accepted.
        """
        return self.was_displayed and self.scene.view_count == 0

    def use_keymap(self, keymap, source) -> None:
        """Bind ``keymap`` plus ``source``'s own keys (its actions runnable), and show them in the help."""
        actions = source_actions(source)
        if actions:
            keymap = keymap.extended({k: a for k, (a, _, _) in actions.items()})
        self.custom.update({a.name: (run, repeat) for a, run, repeat in actions.values()})
        self.state.keymap = keymap
        markup.show(self.help_panel, markup.help_html(help_groups(keymap), self.repeater.hold_delay,
                                                   self.repeater.tick_rate))
        self.send_config()

    def send_config(self) -> None:
        """The key table and rules the page steps its copy of the state by (`pagestate.page_config`)."""
        rep = self.repeater
        predicted = PREDICTED_KINDS | self.page.view.kinds()
        levels = level_actions(self.showing.source)
        actions = {name: {"rule": "levels", "sign": sign, "repeat": bool(self.custom[name][1])}
                   for name, sign in levels.items() if name in self.custom}
        config = page_config(self.state.keymap, hold_delay=rep.hold_delay, tick_rate=rep.tick_rate,
                             max_lag=rep.max_steps * rep.period, predicted=predicted, predicted_actions=actions)
        if config != self.companion.config:
            self.companion.config = config

    # -- steps -----------------------------------------------------------------------------
    def tick(self, now: float) -> None:
        """Pump callback: the held keys' steps due by ``now``; a tick that overran (slow
        observers, a loaded machine) drops the ticks it missed instead of bursting."""
        rep = self.repeater
        clock = self.pump.clock
        if self.page.held:  # the page silent for a while: its steps by the kernel's estimate
            self.page.tick()
            self.advance()
        for kid, action, inverted in rep.due_keys(now):
            if self.step(action, inverted):
                rep.note_applied(kid)
            if clock() - now > rep.period:
                break  # over budget: the rest of this catch-up is dropped, the lock let go
        after = clock()
        if after - now > rep.period:
            rep.drop_missed(after)

    def deadline(self):
        """When `tick` next wants to run: the repeater's next tick, or with a key of the page held,
        when the page will have been silent too long (`HEARTBEAT_STALE`)."""
        d = self.repeater.next_deadline()
        if self.page.held:
            soon = self.pump.clock() + HEARTBEAT_STALE
            d = soon if d is None else min(d, soon)
        return d

    def step(self, action: Action, inverted: bool) -> bool:
        """One step of ``action`` (the kernel's): applied, recorded, counted in the readout, traits synced."""
        changed = self.apply_step(action, inverted)
        if changed:
            self.last.note(action.label(inverted))
            self.after_steps(action)
        return changed

    def apply_step(self, action: Action, inverted: bool) -> bool:
        """Apply and record one step (no trait sync: `after_steps` does it once); True if it changed."""
        if action.kind == "custom":
            run = self.custom.get(action.name)
            if run is None:
                return False
            with self.showing.lock:
                note_matrix(self.showing.source, self.state.matrix)  # n: a default spacing spread along today's w
                result = run[0](-1 if inverted else 1)
            if result is False:  # refused (at a bound): nothing changed, nothing recorded
                return False
            self.showing.changed()
            self.keeper.recorder.record(None, False, action, inverted)
            self.keeper.note_settings()
            return True
        if action.kind == "screenshot":
            self.shots.key_p()
            return False
        if action.kind in ("rendering", "section"):  # the view's field keys (`renderings`)
            return self.renderings.step(action, inverted)
        if action.kind == "slices" and not self.stacking.is_stack:
            # n on a single slice: the first added slice makes the view a stack of two (recorded
            # as the source setting it is; the stack's own keys are steps from here on)
            if (-1 if inverted else 1) * action.sign <= 0:
                return False
            self.stacking.wrap(2)
            self.keeper.recorder.record_source("slices", 2)
            return True
        changed = self.state.apply(action, inverted)
        if changed:
            self.keeper.recorder.record(None, False, action, inverted)
        return changed

    def after_steps(self, action: Action) -> None:
        """After steps of ``action`` changed something: redraw, and the traits say what it is."""
        self.pump.mark_dirty()
        if action.kind in ("custom", "slices"):
            self.sync.source_traits()
        self.sync.state_traits()


def _opposite(action: Action, inverted: bool):
    """``(action, inverted)`` of the step that undoes one step of ``action``."""
    if action.kind in SHIFT_KINDS or action.kind == "custom":
        return action, not inverted
    return dataclasses.replace(action, sign=-action.sign), inverted


def page_time(event) -> float | None:
    """The page's time of an ipyevents event in seconds (its ``timeStamp``, ms), or None."""
    t = event.get("timeStamp") if isinstance(event, Mapping) else None
    if isinstance(t, bool) or not isinstance(t, (int, float)):
        return None
    try:
        t = float(t)  # an int past float's range (10**400) is no page time either
    except OverflowError:
        return None
    return t / 1000.0 if math.isfinite(t) else None


def page_edge(edge, keymap=None):
    """One key event as the companion repeats it -- ``{"kid", "down", "t"}`` and for a press what
    finds its action: ``"key"``, ``"code"``, ``"shift"`` of a key, or ``"pad": true`` and the pad
    button's key and shift -- as ``(kid, down, t_ms, found)``; None if malformed.  ``found`` is the
    keymap's ``(action, inverted)`` (None: not bound, or no keymap given)."""
    if not isinstance(edge, Mapping):
        return None
    kid, down, t = edge.get("kid"), edge.get("down"), edge.get("t")
    if not isinstance(kid, str) or not 0 < len(kid) <= 64 or not isinstance(down, bool) \
            or isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        return None
    found = None
    if down and keymap is not None:
        key, shift = edge.get("key"), edge.get("shift") is True
        if edge.get("pad") is True:
            if isinstance(key, str) and key and kid == f"pad:{key}{'+shift' if shift else ''}":
                found = keymap.resolve(key, shift)
        else:
            event = {"key": key, "code": edge.get("code"), "shiftKey": shift}
            if key_id(event) == kid:
                found = keymap.lookup(event)
    return kid, down, float(t), found


def key_id(event: Mapping):
    """A held key's identity: its ``code`` (physical key), else its lower-cased ``key``."""
    code = event.get("code")
    if isinstance(code, str) and code:
        return code
    key = event.get("key")
    if isinstance(key, str) and key:
        return "key:" + key.lower()
    return None


def source_actions(source) -> dict:
    """``{key: (Action, run, repeat)}`` for the source's optional ``actions`` mapping."""
    actions = source.actions
    if not actions:
        return {}
    if not isinstance(actions, Mapping):
        raise TypeError(f"Expected `source.actions` to be a mapping of key -> SourceAction, "
                        f"got {type(actions).__name__}")
    out = {}
    for key, sa in actions.items():
        for attr in ("name", "description", "run"):
            if not hasattr(sa, attr):
                raise TypeError(f"Expected source action {key!r} to have `{attr}` (see rot4d_widget.SourceAction)")
        if not callable(sa.run):
            raise TypeError(f"Expected source action {key!r}.run to be callable")
        action = Action("custom", name=str(sa.name), text=str(sa.description), sign=1)
        out[key] = (action, sa.run, bool(getattr(sa, "repeat", True)))
    return out


def help_groups(keymap: Keymap) -> list:
    """The key table, one row per action; reserved keys that do nothing here yet in one honest row."""
    rows, reserved = [], []
    for keys, label, text in keymap.help_groups():
        acts = [keymap[k] for k in keys.split() if k in keymap]
        kinds = {a.kind for a in acts}
        adds_slice = kinds == {"slices"} and all(a.sign > 0 for a in acts)  # n: makes the view a stack
        if kinds and kinds <= RESERVED_KINDS and not adds_slice and kinds != {"screenshot"}:
            reserved.append(keys)
        else:
            rows.append((keys, label, text))
    if reserved:
        rows.append((" ".join(reserved), "reserved",
                     "iso levels (fields), fewer slices and spacing (parallel slices): not active in this view"))
    return rows
