"""`Rot4DWidget`: turn a 4-D polytope with single key strokes, watch its w = c0 slice.

The only module that imports ipyevents.  A key travels one way:

    ipyevents dict -> ``keymap.lookup`` -> ``state.apply`` -> (flow control)
    -> ``slice_polytope`` -> ``scene.show`` (new float32 arrays) + readout

Timing (module constants, overridable per widget):

``HOLD_DELAY = 0.25`` s
    A key's first step happens on keydown, at once.  If it is still down
    ``HOLD_DELAY`` later the action repeats, like a keyboard's auto-repeat
    (whose delay is 250-500 ms), so a tap is always exactly one step.
``TICK_RATE = 30`` Hz
    Repeats while held: one step (theta0 for rotations, the alpha / c0 step
    for j/k/l/h) per tick.  30 Hz is the auto-repeat rate of real keyboards;
    with the default theta0 = pi/64 a held key turns 84 deg/s.  The state
    advances at this rate whatever the page draws (measured in headless
    Chromium with software WebGL: ~13 pictures/s for the 5-cell, ~8 for the
    600- and 120-cell; each shows the latest state).  Ticks come from a
    thread, not from browser auto-repeat (``repeat: true`` keydowns are
    ignored) and not from asyncio (whose background tasks stall on ipykernel
    7).  If the kernel was busy, missed ticks are replayed up to ``MAX_LAG``
    (0.25 s) worth and the rest dropped, so a stall never turns into a burst.
``ACK_TIMEOUT = 0.5`` s
    Flow control.  At most one scene update is in flight: after
    ``scene.show`` the widget waits for the companion's "drawn"
    acknowledgement (sent by the page after a frame containing the update was
    rendered) before it computes the next update -- from the latest state,
    so nothing queues and the view settles at once when a key is released.
    Without an answer (no view: scripting, nbval; a hidden tab) the latest
    state is sent anyway ``ACK_TIMEOUT`` after the previous update.  Measured
    acknowledgement round trips (software WebGL, 600x500 canvas): 50-100 ms
    for the 5-cell, 100-190 ms for the 600- and 120-cell, so 0.5 s does not
    fire while a live view keeps up, yet a view that stops answering still
    gets two pictures a second.  Acknowledgements name the update
    (``scene.update_id``): with several views the first one counts, late or
    stale ones are ignored.

Held keys are identified by ``code`` (so the keyup releases them whatever
Shift did meanwhile) and step in the order they were pressed.  Rotation stops
on keyup, on mouseleave, and when the companion reports that the page or
window lost focus (a keyup after that never arrives).  Rotations, j/k and l/h
repeat; the step-angle keys (+/-), reset (r) and help (?) act once per press.

A widget whose canvas views are all gone (the cell was re-run) ignores key
events: ipyevents leaves its document key listener behind when a view is
destroyed while hovered, and those keys must not turn an invisible widget.
The widget learns the number of views from ipywidgets' ``_view_count``
(requested on the renderer); front ends that do not keep it are never
filtered.

Every handler runs under one lock, whether it is called by the kernel's comm
handlers (keys, acknowledgements) or the ticker thread.  Exceptions raised
while handling a key are shown in the widget's ``errors`` output area (and
stop held keys); they never escape into the event loop.  Malformed event dicts
are ignored.
"""

from __future__ import annotations

import html
import logging
import math
import threading
import time
import traceback
from collections.abc import Mapping

import ipywidgets as widgets
import numpy as np
from ipyevents import Event

from .keymap import DEFAULT_KEYMAP, Keymap
from .polytopes import polytope as _get_polytope
from .slicing import slice_polytope
from .state import DEFAULT_THETA0, RotationState

__all__ = ["Rot4DWidget", "HOLD_DELAY", "TICK_RATE", "ACK_TIMEOUT", "MAX_LAG", "C0_STEP_FRACTION"]

log = logging.getLogger(__name__)

HOLD_DELAY = 0.25
TICK_RATE = 30.0
ACK_TIMEOUT = 0.5
MAX_LAG = 0.25
MAX_TICK_RATE = 240.0
#: The l/h step as a fraction of the polytope's circumradius.
C0_STEP_FRACTION = 1.0 / 64.0
#: How many error reports the ``errors`` area keeps.
MAX_ERRORS_SHOWN = 5

#: Child objects, in the order close() closes them (the Event first).
_PARTS = ("events", "companion", "scene", "readout", "help_panel", "errors", "_canvas_box", "_side_box")
#: Compact tables (Jupyter's rendered-HTML CSS pads cells generously).  Sent
#: once, with the help panel (a <style> applies while its container is hidden),
#: so the readout sent with every update stays small.
_STYLE = (
    "<style>.rot4d-side table{border-collapse:collapse;margin:0}"
    ".rot4d-side .rot4d-readout td,.rot4d-side .rot4d-help td"
    "{padding:1px 0.5em 1px 0;line-height:1.3;text-align:left;vertical-align:top}"
    ".rot4d-side .rot4d-readout table{font-family:monospace}"
    ".rot4d-side .rot4d-help{font-size:90%}</style>"
)
_REPEATING_KINDS = frozenset({"rotate", "alpha", "c0"})
_WATCHED_EVENTS = ["keydown", "keyup", "mouseleave"]
_POLYGON_NAMES = {
    3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon",
    7: "heptagon", 8: "octagon", 9: "nonagon", 10: "decagon",
}


def _positive_finite(name: str, value) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a positive number, got {type(value).__name__}")
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"Expected `{name}` to be a finite number > 0, got {value}")
    return value


def _scene_classes():
    """Import the rendering path lazily (pythreejs is heavy), once."""
    from .companion import Companion
    from .scene import Scene

    return Scene, Companion


class _Held:
    __slots__ = ("action", "inverted", "order", "next_due")

    def __init__(self, action, inverted, order, next_due):
        self.action = action
        self.inverted = inverted
        self.order = order
        self.next_due = next_due


class Rot4DWidget(widgets.HBox):
    """A keyboard-driven view of the slice w = c0 of a rotating 4-D polytope.

    Move the mouse over the canvas and press the paper's keys (2 3 4 6 8 c:
    simple rotations, y z w: double rotations, Shift: inverse; k/j: alpha,
    l/h: c0; ? shows the key table).  Hold a key to keep turning.

    Parameters
    ----------
    polytope : str or Polytope
        ``"5-cell"`` (default), ``"8-cell"``, ``"16-cell"``, ``"24-cell"``,
        ``"600-cell"``, ``"120-cell"`` (or an alias), or any `Polytope`.
    theta0, alpha, c0 :
        Initial step angle (radians, in (0, pi]), double-rotation angle alpha
        (default: the paper's ratio, ``beta = theta0 - alpha``) and slice level,
        as in `RotationState`.
    keymap : Keymap
        Key bindings (default: the paper's tables plus r, +/-, ?).
    c0_step : float, optional
        The l/h step; default ``circumradius * C0_STEP_FRACTION`` (1/64).
    width, height, ball_radius, bar_radius, face_opacity, background, cell_colors :
        Passed to the `Scene` when given (``None``: the scene's default).
    hold_delay, tick_rate, ack_timeout : float
        Seconds before a held key repeats; repeats per second while held;
        seconds to wait for a "drawn" acknowledgement (see the module docs).
    clock : callable, optional
        Returns the time in seconds (default `time.monotonic`); for tests.
    autotick : bool
        Run the ticker thread (default).  Tests pass False and call
        ``_service()`` with a fake clock.
    **scene_options :
        Further keyword arguments for `Scene`.

    Attributes
    ----------
    state : RotationState
    polytope : Polytope
    scene, companion : the pythreejs scene and the front-end companion
    readout, help_panel : ipywidgets.HTML
    errors : ipywidgets.Output -- exceptions raised by key handling
    events : ipyevents.Event watching the canvas
    """

    def __init__(
        self,
        polytope="5-cell",
        theta0: float = DEFAULT_THETA0,
        alpha: float | None = None,
        c0: float = 0.0,
        *,
        keymap: Keymap = DEFAULT_KEYMAP,
        c0_step: float | None = None,
        width=None,
        height=None,
        ball_radius=None,
        bar_radius=None,
        face_opacity=None,
        background=None,
        cell_colors=None,
        hold_delay: float = HOLD_DELAY,
        tick_rate: float = TICK_RATE,
        ack_timeout: float = ACK_TIMEOUT,
        clock=None,
        autotick: bool = True,
        **scene_options,
    ):
        # -- validate before any widget exists (the Scene checks its own options
        #    before it builds anything) -----------------------------------------
        poly = _get_polytope(polytope)
        self.hold_delay = _positive_finite("hold_delay", hold_delay)
        self.tick_rate = _positive_finite("tick_rate", tick_rate)
        if self.tick_rate > MAX_TICK_RATE:
            raise ValueError(f"Expected `tick_rate` in (0, {MAX_TICK_RATE:g}] Hz, got {self.tick_rate}")
        self.ack_timeout = _positive_finite("ack_timeout", ack_timeout)
        if clock is not None and not callable(clock):
            raise TypeError(f"Expected `clock` to be a callable returning seconds, got {type(clock).__name__}")
        if c0_step is None:
            c0_step = poly.circumradius * C0_STEP_FRACTION
        state = RotationState(theta0, alpha, c0, keymap=keymap, c0_step=c0_step)
        options = dict(
            width=width, height=height, ball_radius=ball_radius, bar_radius=bar_radius,
            face_opacity=face_opacity, background=background, cell_colors=cell_colors,
        )
        options = {k: v for k, v in options.items() if v is not None}
        options.update(scene_options)

        self.polytope = poly
        self.state = state
        self._clock = clock if clock is not None else time.monotonic
        self._period = 1.0 / self.tick_rate
        self._max_steps = max(1, int(math.ceil(MAX_LAG * self.tick_rate)))

        # -- flow-control and key state (guarded by _lock) -------------------
        self._lock = threading.RLock()
        self._wakeup = threading.Condition(self._lock)
        self._held: dict[str, _Held] = {}
        self._order = 0
        self._dirty = False
        self._in_flight = None  # scene.update_id of the update awaiting "drawn"
        self._sent_at = -math.inf
        self._shown = None  # (matrix, c0, eye) the scene shows
        self._slice_cache = None  # (matrix, c0, Slice)
        self._last_label = None
        self._last_count = 0
        self._closed = False
        self._thread = None
        self._autotick = bool(autotick)
        self.n_updates = 0  # scene updates sent
        self.n_acks = 0  # acknowledged in time
        self.n_timeouts = 0  # sent after ACK_TIMEOUT without an acknowledgement
        self.last_update_bytes = 0

        # -- widgets ---------------------------------------------------------
        Scene, Companion = _scene_classes()
        built = []
        try:
            self.scene = Scene(poly, **options)
            built.append(self.scene)
            self.companion = Companion(self.scene)
            built.append(self.companion)
            self.readout = widgets.HTML()
            self.help_panel = widgets.HTML(
                _help_html(keymap, self.hold_delay, self.tick_rate), layout=widgets.Layout(display="none")
            )
            self.errors = widgets.Output()
            built += [self.readout, self.help_panel, self.errors]
            self.events = Event(
                source=self.scene.renderer,
                watched_events=list(_WATCHED_EVENTS),
                prevent_default_action=True,
                ignore_modifier_key_events=True,
            )
            built.append(self.events)
            # the canvas keeps its size; the side panel wraps below it when narrow
            self._canvas_box = widgets.VBox(
                [self.scene.renderer, self.companion], layout=widgets.Layout(flex="0 0 auto")
            )
            self._side_box = widgets.VBox(
                [self.readout, self.help_panel, self.errors],
                layout=widgets.Layout(flex="1 1 16em", min_width="16em", padding="0 0 0 1em"),
            )
            self._side_box.add_class("rot4d-side")
            built += [self._canvas_box, self._side_box]
        except BaseException:
            for w in reversed(built):
                try:
                    w.close()
                except Exception:
                    pass
            raise
        super().__init__(
            [self._canvas_box, self._side_box],
            layout=widgets.Layout(flex_flow="row wrap", align_items="flex-start"),
        )

        self.events.on_dom_event(self._handle_event)
        self.companion.on_drawn(self._handle_drawn)
        self.companion.on_focus_lost(self._handle_focus_lost)
        # Count the canvas's views (ipywidgets' _view_count, kept by the front end).
        # A view destroyed while hovered leaves ipyevents' document key listener
        # behind, so a widget whose every view is gone still receives keys: it
        # must act on nothing.  See _has_no_view.
        self._was_displayed = False
        renderer = self.scene.renderer
        renderer.observe(self._view_count_changed, names="_view_count")
        if renderer._view_count is None:
            renderer._view_count = 0
        # The faces are ordered for the eye (back faces first): when a mouse orbit
        # ends and the camera's new position reaches the kernel, re-send them.
        self.scene.camera.observe(self._camera_moved, names="position")

        # The initial picture is part of the models' state: not "in flight".
        with self._lock:
            self._render(self._clock(), expect_ack=False)

    # ------------------------------------------------------------------ API
    @property
    def slice(self):
        """The `Slice` of the current state (what the view shows, or is about to)."""
        with self._lock:
            return self._current_slice()

    @property
    def held_keys(self) -> tuple:
        """``code`` s of the keys held now, in the order they were pressed."""
        with self._lock:
            return tuple(self._held)

    @property
    def in_flight(self) -> bool:
        """True while an update waits for the page's "drawn" acknowledgement."""
        with self._lock:
            return self._in_flight is not None

    @property
    def help_visible(self) -> bool:
        return self.help_panel.layout.display != "none"

    @help_visible.setter
    def help_visible(self, value: bool) -> None:
        self.help_panel.layout.display = None if value else "none"

    def press(self, key: str, shift: bool = False) -> bool:
        """One step of the action bound to ``key`` (as `RotationState.press`), then redraw.

        ``"C"`` or ``("c", shift=True)`` is R_zw inverted; ``"?"`` toggles the
        help.  Returns False (and sends nothing) for an unbound key.  The
        redraw obeys the flow control: if an update is in flight the latest
        state is sent when it is acknowledged (or after ``ack_timeout``).
        """
        found = self.state.keymap.resolve(key, shift)
        if found is None:
            return False
        action, inverted = found
        with self._lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            if action.kind == "help":
                self.help_visible = not self.help_visible
                return True
            changed = self._step(action, inverted)
            self._flush(self._clock())
            self._wake()
            return changed

    def refresh(self) -> None:
        """Redraw after changing `state` directly (``w.state.matrix = m``); obeys the flow control."""
        with self._lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            self._dirty = True
            self._flush(self._clock())
            self._wake()

    def release_keys(self) -> None:
        """Forget every held key (what mouseleave and focus loss do)."""
        with self._lock:
            self._held.clear()

    def close(self) -> None:
        """Stop the ticker thread, drop the listeners, close every child widget."""
        if "_lock" not in self.__dict__:  # construction failed before any child existed
            return
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._held.clear()
            self._wakeup.notify_all()
            thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        parts = [getattr(self, name, None) for name in _PARTS]
        events, companion = parts[0], parts[1]
        try:
            if events is not None:
                events.on_dom_event(self._handle_event, remove=True)
            if companion is not None:
                companion.on_drawn(self._handle_drawn, remove=True)
                companion.on_focus_lost(self._handle_focus_lost, remove=True)
            scene = getattr(self, "scene", None)
            if scene is not None and "_was_displayed" in self.__dict__:
                scene.renderer.unobserve(self._view_count_changed, names="_view_count")
                scene.camera.unobserve(self._camera_moved, names="position")
        finally:
            # The Event first, so its document listeners go before the canvas does.
            for w in parts:
                if w is not None:
                    _close_quietly(w)
            layout, style = getattr(self, "layout", None), getattr(self, "style", None)
            super().close()
            for w in (layout, style):
                if w is not None:
                    _close_quietly(w)

    def __repr__(self) -> str:
        return (
            f"Rot4DWidget({self.polytope.name!r}, theta0={self.state.theta0:.6g}, "
            f"alpha={self.state.alpha:.6g}, c0={self.state.c0:.6g}"
            f"{', closed' if self._closed else ''})"
        )

    # ---------------------------------------------------- front-end handlers
    def _handle_event(self, event) -> None:
        """ipyevents callback: never raises."""
        try:
            if not isinstance(event, Mapping):
                return
            etype = event.get("type", event.get("event"))
            if etype == "keydown":
                self._key_down(event)
            elif etype == "keyup":
                self._key_up(event)
            elif etype == "mouseleave":
                self.release_keys()
        except Exception as exc:  # shown, never lost, never raised into the kernel
            self._report_error(exc)

    def _handle_drawn(self, seq=None) -> None:
        """Companion: the page rendered a frame containing update ``seq`` (``scene.update_id``)."""
        try:
            if isinstance(seq, bool) or not isinstance(seq, (int, type(None))):
                return
            with self._lock:
                if self._closed or self._in_flight is None:
                    return  # late, duplicate (another view) or after a timeout
                if seq is not None and seq != self._in_flight:
                    return
                self._in_flight = None
                self.n_acks += 1
                self._flush(self._clock())
                self._wake()
        except Exception as exc:
            self._report_error(exc)

    def _handle_focus_lost(self, *args, **kwargs) -> None:
        try:
            self.release_keys()
        except Exception as exc:
            self._report_error(exc)

    def _camera_moved(self, change=None) -> None:
        """The camera moved (OrbitControls): send the faces in the order for the new eye."""
        try:
            with self._lock:
                if self._closed:
                    return
                self._dirty = True  # _render sees the new eye and re-sends; flow control as usual
                self._flush(self._clock())
        except Exception as exc:
            self._report_error(exc)

    # -------------------------------------------------------------- keys
    def _view_count_changed(self, change) -> None:
        try:
            n = change["new"]
            if isinstance(n, int) and n > 0:
                self._was_displayed = True
            elif n == 0:
                self.release_keys()  # no view left: no keyup will come
        except Exception as exc:
            self._report_error(exc)

    def _has_no_view(self) -> bool:
        """True when the canvas was displayed and every view of it is gone.

        Front ends that do not keep ``_view_count`` leave it at 0 and never
        set ``_was_displayed``: their keys are always accepted.
        """
        return self._was_displayed and self.scene.renderer._view_count == 0

    def _key_down(self, event: Mapping) -> None:
        if event.get("repeat") is True:
            return  # browser auto-repeat: the ticker repeats, not the browser
        if self._has_no_view():
            return  # a listener leaked by a destroyed view (ipyevents): act on nothing
        found = self.state.keymap.lookup(event)
        if found is None:
            return
        key_id = _key_id(event)
        if key_id is None:
            return
        action, inverted = found
        with self._lock:
            if self._closed:
                return
            if action.kind == "help":
                self.help_visible = not self.help_visible
                return
            now = self._clock()
            self._held.pop(key_id, None)
            try:
                self._step(action, inverted)
                if action.kind in _REPEATING_KINDS:
                    self._order += 1
                    self._held[key_id] = _Held(action, inverted, self._order, now + self.hold_delay)
                self._flush(now)
            finally:
                self._wake()

    def _key_up(self, event: Mapping) -> None:
        key_id = _key_id(event)
        if key_id is None:
            return
        with self._lock:
            self._held.pop(key_id, None)

    # ---------------------------------------------------------- time + flow
    def _service(self, now: float | None = None):
        """Apply the ticks due by ``now``, honour the ack timeout, send if allowed.

        Returns the clock time at which it wants to run next, or None.  Called
        by the ticker thread, or by tests with a fake clock.
        """
        with self._lock:
            if self._closed:
                return None
            if now is None:
                now = self._clock()
            try:
                self._advance(now)
                self._flush(now)
            except Exception as exc:
                self._held.clear()
                self._dirty = False
                self._report_error(exc)
            return self._next_deadline()

    def _advance(self, now: float) -> None:
        """Step every held key whose next tick is due, in time order then press order."""
        held = self._held
        if not held:
            return
        steps = 0
        limit = self._max_steps * len(held)
        while steps < limit:
            h = min(held.values(), key=lambda h: (h.next_due, h.order))
            if h.next_due > now:
                return
            self._step(h.action, h.inverted)
            h.next_due += self._period
            steps += 1
        for h in held.values():  # the kernel was stalled: drop what is older than MAX_LAG
            if h.next_due <= now:
                h.next_due = now + self._period

    def _flush(self, now: float) -> None:
        """Send the latest state unless an update is in flight (and not timed out)."""
        if not self._dirty:
            return
        if self._in_flight is not None:
            if now - self._sent_at < self.ack_timeout:
                return
            self._in_flight = None
            self.n_timeouts += 1
        self._render(now, expect_ack=True)

    def _render(self, now: float, *, expect_ack: bool) -> None:
        self._dirty = False
        st = self.state
        m, c0 = st.matrix, st.c0
        scene = self.scene
        eye = scene.eye  # the faces' order depends on it
        shown = self._shown
        if shown is None or not (c0 == shown[1] and eye == shown[2] and np.array_equal(m, shown[0])):
            s = self._current_slice()
            nbytes = scene.show(s)
            self._shown = (m, c0, eye)
            if nbytes:  # 0: the picture did not change, nothing sent, no ack will come
                self.last_update_bytes = nbytes
                self.n_updates += 1
                if expect_ack:
                    self._in_flight = scene.update_id
                    self._sent_at = now
        self.readout.value = self._readout_html()

    def _current_slice(self):
        st = self.state
        m, c0 = st.matrix, st.c0
        cache = self._slice_cache
        if cache is not None and cache[0] is m and cache[1] == c0:
            return cache[2]
        s = slice_polytope(self.polytope, m, c0)
        self._slice_cache = (m, c0, s)
        return s

    def _step(self, action, inverted) -> bool:
        changed = self.state.apply(action, inverted)
        if changed:
            self._dirty = True
            label = action.label(inverted)
            if label == self._last_label:
                self._last_count += 1
            else:
                self._last_label, self._last_count = label, 1
        return changed

    def _next_deadline(self):
        deadlines = [h.next_due for h in self._held.values()]
        if self._dirty and self._in_flight is not None:
            deadlines.append(self._sent_at + self.ack_timeout)
        return min(deadlines) if deadlines else None

    def _wake(self) -> None:
        """Start the ticker thread if needed and let it recompute its deadline."""
        if not self._autotick or self._closed:
            return
        if self._next_deadline() is None and self._thread is None:
            return
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name=f"rot4d-ticker-{id(self):x}", daemon=True)
            self._thread.start()
        self._wakeup.notify_all()

    def _run(self) -> None:
        with self._lock:
            while not self._closed:
                deadline = self._service()
                if self._closed:
                    break
                if deadline is None:
                    self._wakeup.wait()
                else:
                    timeout = deadline - self._clock()
                    if timeout > 0:
                        self._wakeup.wait(timeout)

    # -------------------------------------------------------------- display
    def _readout_html(self) -> str:
        st = self.state
        s = self._current_slice()
        if self._last_label is None:
            last = "\u2014"
        else:
            last = html.escape(self._last_label) + (f" \u00d7{self._last_count}" if self._last_count > 1 else "")
        rows = [
            ("\u03b80", f"{st.theta0:.5f} rad ({math.degrees(st.theta0):.3f}\u00b0)"),
            ("\u03b1", f"{st.alpha:.5f} rad"),
            ("\u03b2", f"{st.beta:.5f} rad"),
            ("c0", f"{st.c0:.4f}"),
            ("last", last),
            ("slice", _census_text(s)),
            ("volume", f"{s.volume:.4f}"),
        ]
        body = "".join(
            f"<tr><td>{k}</td><td>{v}</td></tr>" for k, v in rows
        )
        return (
            f"<div class='rot4d-readout'><b>{html.escape(self.polytope.name)}</b>"
            f"<table>{body}</table>"
            "<small>mouse over the view; ? for keys</small></div>"
        )

    def _report_error(self, exc: BaseException) -> None:
        """Show an exception in the ``errors`` area (and the log); never raises."""
        try:
            text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
            log.error("Rot4DWidget: error while handling a key\n%s", text)
            with self._lock:
                self._held.clear()
            item = {"output_type": "stream", "name": "stderr", "text": text}
            self.errors.outputs = tuple(self.errors.outputs[-(MAX_ERRORS_SHOWN - 1):]) + (item,)
        except Exception:
            log.exception("Rot4DWidget: could not report an error")


# ------------------------------------------------------------------ helpers
def _close_quietly(w) -> None:
    """Close a widget and its own Layout / Style widgets; never raises (close() must not stop halfway)."""
    subs = [getattr(w, name, None) for name in ("layout", "style")] if isinstance(w, widgets.Widget) else []
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


def _key_id(event: Mapping):
    """A held key's identity: its ``code`` (physical key), else its lower-cased ``key``."""
    code = event.get("code")
    if isinstance(code, str) and code:
        return code
    key = event.get("key")
    if isinstance(key, str) and key:
        return "key:" + key.lower()
    return None


def _census_text(s) -> str:
    if s.dim < 0:
        return "empty (w = c0 misses it)"
    census = s.face_census()
    if not census:
        return f"touches it ({'vertex' if s.dim == 0 else 'edge' if s.dim == 1 else 'face'})"
    parts = []
    for n, count in sorted(census.items()):
        name = _POLYGON_NAMES.get(n, f"{n}-gon")
        parts.append(f"{count} {name}{'' if count == 1 else 's'}")
    return ", ".join(parts)


def _help_html(keymap: Keymap, hold_delay: float, tick_rate: float) -> str:
    groups: dict = {}
    for key, label, description in keymap.help_rows():
        groups.setdefault((label, description), []).append(key)
    rows = []
    for (label, description), keys in groups.items():
        shown = " ".join(f"<kbd>{html.escape(k)}</kbd>" for k in keys)
        rows.append(
            f"<tr><td>{shown}</td><td>{html.escape(label)}</td><td>{html.escape(description)}</td></tr>"
        )
    return (
        _STYLE + "<div class='rot4d-help'><table style='margin:0.5em 0'>" + "".join(rows) + "</table>"
        f"<small>Shift inverts a rotation. Hold a key: it repeats after {hold_delay * 1000:.0f} ms, "
        f"{tick_rate:g} steps/s.</small></div>"
    )
