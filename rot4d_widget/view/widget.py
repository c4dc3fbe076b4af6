"""`Rot4DWidget`: turn a 4-D object with single key strokes, watch its w = c0 slice.

The only module that imports ipyevents.  A key travels one way::

    ipyevents dict -> keymap.lookup -> state.apply -> (pump: flow control)
    -> source.slice -> buffers -> scene.show (one new float32 array) + readout

The widget wires small units together and owns the public API and traits:

* `rot4d_widget.view.keyhold.KeyRepeater` -- which steps held keys make when
  (hold delay, tick rate, no burst after a stall);
* `rot4d_widget.view.pump.UpdatePump` -- one update in flight, the "drawn"
  acknowledgement, the timeout, the ticker thread, the lock;
* `rot4d_widget.view.readout` -- the readout and help HTML;
* `rot4d_widget.view.scene.Scene` -- everything pythreejs.

Rotation stops on keyup, on mouseleave, and when the companion reports that
the page or window lost focus (a keyup after that never arrives).  A widget
whose canvas views are all gone (the cell was re-run) ignores key events:
ipyevents leaves its document key listener behind when a view is destroyed
while hovered, and those keys must not turn an invisible widget.  Exceptions
raised while handling a key are shown in the widget's ``errors`` area (and
stop held keys); they never escape into the event loop.

Parameters are traits (`theta0`, `alpha`, `c0`, read-only `orientation`, and
the display options), kept in step with `state`: ``ipywidgets.link`` and
``observe`` work both ways.  Observers of those traits run in the kernel's
ticker thread while a key is held (up to ``tick_rate`` times a second): keep
them short.  The traits live in the kernel only (use ``link``, not
``jslink``).
"""

from __future__ import annotations

import dataclasses
import html
import inspect
import logging
import math
import os
import threading
import traceback
import warnings
from collections.abc import Mapping

import ipywidgets as widgets
import numpy as np
import traitlets
from ipyevents import Event

from ..core import look
from . import progress as _progress  # noqa: F401 - registers the kernel's progress bar with the core
from . import readout as ro
from .keyhold import HOLD_DELAY, TICK_RATE, KeyRepeater, positive_seconds
from ..core.keymap import DEFAULT_KEYMAP, RESERVED_KINDS, REPEATING_KINDS, Action, Keymap
from .pump import ACK_TIMEOUT, MAX_IN_FLIGHT, UpdatePump
from ..sources.protocol import BadSlice, as_source, check_slice, data_w_text, w_frame
from ..core.state import DEFAULT_THETA0, RotationState, _check_alpha_beta, _finite, _theta0, without_source_keys

__all__ = ["Rot4DWidget", "HOLD_DELAY", "TICK_RATE", "ACK_TIMEOUT", "MAX_IN_FLIGHT", "C0_STEP_FRACTION", "READOUT_PERIOD"]

log = logging.getLogger(__name__)

#: The l/h step as a fraction of the source's size (circumradius).
C0_STEP_FRACTION = 1.0 / 64.0
#: While keys repeat, the readout (an HTML relayout on the page) changes at most this often (s);
#: it is exact again as soon as no key is held.
READOUT_PERIOD = 0.25
#: How many error reports the ``errors`` area keeps.
MAX_ERRORS_SHOWN = 5
#: Screenshot requests no view answered are dropped after this many seconds ...
SCREENSHOT_TIMEOUT = 10.0
#: ... and at most this many wait at once (the oldest is dropped).
MAX_PENDING_SCREENSHOTS = 8
#: The l / h keys keep |c0| within this many times the source's size (`RotationState.c0_limit`).
C0_LIMIT_SIZES = 2.0

_WATCHED_EVENTS = ["keydown", "keyup", "mouseleave"]
_DISPLAY_TRAITS = ("ball_radius", "bar_radius", "face_opacity", "background", "show_balls", "show_bars", "show_faces")
_STATE_TRAITS = ("theta0", "alpha", "c0")


class _Value(traitlets.Any):
    """A trait whose value the widget validates itself (None included), with errors naming what is allowed."""

    allow_none = False


def _scene_classes():
    """Import the rendering path lazily (pythreejs is heavy), once."""
    from .companion import Companion
    from .scene import Scene

    return Scene, Companion


class Rot4DWidget(widgets.HBox):
    """A keyboard-driven view of the slice w = c0 of a rotating 4-D object.

    Move the mouse over the canvas and press the paper's keys (2 3 4 6 8 c:
    simple rotations, y z w: double rotations, Shift: inverse; k/j: alpha,
    l/h: c0; ? shows the key table).  Hold a key to keep turning.

    Parameters
    ----------
    source : str, Polytope or Source
        A polytope name (``"5-cell"`` default, ``"8-cell"``, ``"16-cell"``,
        ``"24-cell"``, ``"600-cell"``, ``"120-cell"`` or an alias), a
        `Polytope`, or any object following the source protocol
        (`rot4d_widget.sources.protocol`).
    theta0, alpha, c0 :
        Initial step angle (radians, in (0, pi]), double-rotation angle alpha
        (default: the paper's ratio, ``beta = theta0 - alpha``) and slice level
        c0 in the source's w units (a field's data w: seconds for a time in
        seconds; `rot4d_widget.sources.protocol.w_frame`), as in `RotationState`; default
        the source's centre (0 for a polytope, the middle time for a field).
    keymap : Keymap
        Key bindings (default: the paper's tables plus r, +/-, ?).
    c0_step : float, optional
        The l/h step, in c0's units; default 1/64 (`C0_STEP_FRACTION`) of the
        source's size, in its w units (``size * per_unit / 64``).
    width, height : int
        Canvas size in pixels (default 600 x 500).
    ball_radius, bar_radius : float, optional
        In displayed units (every source is drawn with circumradius
        `rot4d_widget.core.look.REFERENCE_RADIUS`).  Default from the source's edge
        length (polytopes) or its first slice.
    face_opacity : float in [0, 1]
    background : colour ('#rrggbb', '#rgb' or three floats in [0, 1])
    show_balls, show_bars, show_faces : bool
    color_by : "group" (each triangle the colour of its group: a polytope's
        4-D cell) or one colour for every face (e.g. ``"#9fb6cd"``)
    group_colors : sequence of colours, one per group, optional
    antialias : bool
        WebGL multisampling (default False).
    slices, spacing, arrangement : int, float, str, optional
        Parallel slices at w = c0 + (k - (N - 1)/2) * spacing (4-D tomography,
        `rot4d_widget.sources.tomography.StackSource`), placed "oval" (on a parabola, the slice at
        c0 nearest the eye), "grid" or "stack"; keys n / b and g / f change N and the
        spacing (default 2 * size / N).  Also traits: setting `slices` (or pressing n) on a
        single view turns it into parallel slices (oval, default spacing).
    levels : float or sequence of floats, optional
        Iso levels of a field source (`Field4D`); also the `levels` trait, and keys
        o / i move them.  Several are drawn as nested translucent surfaces.
    keypad : bool
        An on-screen key pad under the canvas (default False; also the `keypad` trait): a
        button per action (simple and double rotations and their inverses, alpha, c0, the
        step, reset) for a mouse or a touch screen.  A click is one step; a button held
        down repeats exactly like a held key and stops on release or on leaving it.
    hold_delay, tick_rate, ack_timeout : float
        Seconds before a held key repeats; repeats per second while held;
        seconds to wait for a "drawn" acknowledgement.

    Attributes
    ----------
    state : RotationState
    source : the source shown; ``polytope`` is its Polytope (or None)
    slice : what the view shows (the source's slice of the current state)
    stats : counters of the update pump (updates, acks, timeouts)
    readout, help_panel : ipywidgets.HTML
    errors : ipywidgets.Output -- exceptions raised by key handling
    """

    theta0 = _Value(DEFAULT_THETA0, help="step angle of every rotation key, radians in (0, pi]")
    alpha = _Value(0.0, help="double-rotation angle alpha (beta = theta0 - alpha), radians")
    c0 = _Value(0.0, help="level of the slicing hyperplane w = c0, in the source's w units (a field's data w)")
    orientation = traitlets.Any(read_only=True, help="(4, 4) rotation matrix, read-only")
    ball_radius = _Value(0.07)
    bar_radius = _Value(0.028)
    face_opacity = _Value(look.FACE_OPACITY)
    background = _Value(look.BACKGROUND)
    show_balls = _Value(True)
    show_bars = _Value(True)
    show_faces = _Value(True)
    color_by = _Value("group", help='"group" or one colour for every face')
    keypad = traitlets.Bool(False, help="show the on-screen key pad (buttons for every action)")
    levels = _Value(None, help="iso levels of a field source (tuple of floats); None for sources without levels")
    levels.allow_none = True
    inside = _Value(None, help='which side of a field\'s iso level its surface encloses: "above" or "below"; None '
                                'for sources without one')
    inside.allow_none = True
    caps = _Value(None, help="a field's surface closed on the data box's faces (True) or open (False); None for "
                             "sources without one")
    caps.allow_none = True
    slices = _Value(None, help="parallel slices shown (int 1...64); None for a single view until set (or n pressed)")
    slices.allow_none = True
    spacing = _Value(None, help="distance between parallel slices, in the source's units")
    spacing.allow_none = True
    arrangement = _Value(None, help='"oval", "grid" or "stack": where the parallel slices are placed')
    arrangement.allow_none = True

    def __init__(
        self,
        source="5-cell",
        theta0: float = DEFAULT_THETA0,
        alpha: float | None = None,
        c0: float | None = None,
        *,
        keymap: Keymap = DEFAULT_KEYMAP,
        c0_step: float | None = None,
        width: int = 600,
        height: int = 500,
        ball_radius: float | None = None,
        bar_radius: float | None = None,
        face_opacity: float = look.FACE_OPACITY,
        background=look.BACKGROUND,
        show_balls: bool = True,
        show_bars: bool = True,
        show_faces: bool = True,
        color_by="group",
        group_colors=None,
        levels=None,
        slices=None,
        spacing=None,
        arrangement="oval",
        antialias: bool = False,
        keypad: bool = False,
        hold_delay: float = HOLD_DELAY,
        tick_rate: float = TICK_RATE,
        ack_timeout: float = ACK_TIMEOUT,
        _clock=None,
        _autotick: bool = True,
    ):
        # -- validate before any widget exists --------------------------------
        if not isinstance(keypad, bool):
            raise TypeError(f"Expected `keypad` to be a bool, got {type(keypad).__name__}")
        src = as_source(source)
        if levels is not None:
            if not hasattr(src, "levels"):
                raise TypeError(f"`levels` applies to sources with iso levels (a Field4D), not {_title(src)}")
            src.levels = levels
        if slices is not None:  # parallel slices (4-D tomography): a source that wraps the source
            from ..sources.tomography import StackSource

            src = StackSource(src, slices=slices, spacing=spacing, arrangement=arrangement)
        elif spacing is not None:
            raise TypeError("`spacing` applies to parallel slices: give `slices=N` too")
        repeater = KeyRepeater(hold_delay, tick_rate)
        ack_timeout = positive_seconds("ack_timeout", ack_timeout)
        if _clock is not None and not callable(_clock):
            raise TypeError(f"Expected `_clock` to be a callable returning seconds, got {type(_clock).__name__}")
        if not isinstance(keymap, Keymap):
            raise TypeError(f"Expected `keymap` to be a rot4d_widget.Keymap, got {type(keymap).__name__}")
        actions = _source_actions(src)
        if actions:
            keymap = keymap.extended({k: a for k, (a, _, _) in actions.items()})
        origin, per = w_frame(src)
        if c0_step is None:
            c0_step = float(src.size) * C0_STEP_FRACTION * per
        state = RotationState(theta0, alpha, origin if c0 is None else c0, keymap=keymap, c0_step=c0_step,
                              c0_limit=C0_LIMIT_SIZES * float(src.size) * per, c0_origin=origin)
        color_by = _check_color_by(color_by)
        scale = look.REFERENCE_RADIUS / float(src.size)
        if ball_radius is None:
            ball_radius = _default_ball_radius(src, scale, state)
        if bar_radius is None:
            # a field's bars only outline its data's box: thin
            bar_radius = look.default_bar_radius(ball_radius) * (0.35 if _takes_coarse(src) else 1.0)

        self.source = src
        self.state = state
        self._repeater = repeater
        self._custom = {a.name: (run, repeat) for a, run, repeat in actions.values()}
        self._scale = scale
        self._slice_cache = None  # (matrix, c0, version, coarse, data)
        # sources whose slice(matrix, c0, coarse=...) has a cheaper coarse version (fields):
        # coarse while keys repeat, full at rest; their rows are turned, not re-sliced, at rest
        self._coarse_ok = _takes_coarse(src)
        self._source_version = 0
        self._shown = None  # what the scene shows: (matrix, c0, eye, version, color_by, coarse)
        self._rows_key = None  # the state its rows were computed for (the view may be turned from it)
        self._rows_data = None  # the slice those rows show
        self._last_label = None
        self._last_count = 0
        self._readout_at = -math.inf  # when the readout was last computed
        self._readout_stale = False  # the readout lags the state (keys were repeating)
        self._closed = False
        self._was_displayed = False
        self._syncing = False
        self._note = None  # one line for the readout: what a screenshot did
        self._pad = None  # the key pad's box, built when first shown
        self._pad_events = []
        self._screenshots = {}  # request id -> (path, callback, time asked): asked, not answered yet
        self._screenshot_seq = 0
        self._shot_number = 1  # key p's next file number (rot4d-001.png ...)
        self._source_lock = threading.RLock()  # source.slice and source changes (never the pump lock inside)
        self._update_errors = ()  # error reports of failed updates: cleared by the next good one
        #: The PNG of the view the page sent last (`screenshot`, key p), or None.
        self.last_screenshot = None
        self._pump = UpdatePump(
            self._send, tick=self._tick, deadline=repeater.next_deadline, clock=_clock,
            ack_timeout=ack_timeout, autotick=_autotick, on_error=self._report_error,
            name=f"rot4d-ticker-{id(self):x}",
        )
        from ..keep.recording import Recorder

        # every applied action and parameter set, time-stamped (bounded; see `recording`)
        self._recorder = Recorder(state, clock=self._pump.clock, source_settings=_source_settings(src))

        # -- widgets ------------------------------------------------------------
        Scene, Companion = _scene_classes()
        from .buffers import estimate_capacity

        Scene.check_display(dict(
            ball_radius=ball_radius, bar_radius=bar_radius, face_opacity=face_opacity, background=background,
            show_balls=show_balls, show_bars=show_bars, show_faces=show_faces,
        ))

        built = []
        try:
            self.scene = Scene(
                scale=scale, n_groups=int(src.n_groups), capacity=estimate_capacity(src),
                width=width, height=height, ball_radius=ball_radius, bar_radius=bar_radius,
                face_opacity=face_opacity, background=background, show_balls=show_balls,
                show_bars=show_bars, show_faces=show_faces, group_colors=group_colors, antialias=antialias,
            )
            built.append(self.scene)
            self.companion = Companion(self.scene)
            built.append(self.companion)
            self.readout = widgets.HTML()
            self.help_panel = widgets.HTML(
                ro.help_html(_help_groups(keymap), repeater.hold_delay, repeater.tick_rate),
                layout=widgets.Layout(display="none"),
            )
            self.errors = widgets.Output()
            built += [self.readout, self.help_panel, self.errors]
            self.events = Event(
                source=self.scene.canvas,
                watched_events=list(_WATCHED_EVENTS),
                prevent_default_action=True,
                ignore_modifier_key_events=True,
            )
            built.append(self.events)
            # the canvas keeps its size; the side panel wraps below it when narrow
            self._canvas_box = widgets.VBox([self.scene.canvas, self.companion], layout=widgets.Layout(flex="0 0 auto"))
            self._side_box = widgets.VBox(
                [self.readout, self.help_panel, self.errors],
                layout=widgets.Layout(flex="1 1 16em", min_width="16em", padding="0 0 0 1em"),
            )
            self._side_box.add_class("rot4d-side")
            built += [self._canvas_box, self._side_box]
        except BaseException:
            for w in reversed(built):
                _close_quietly(w)
            raise
        display = self.scene.display
        super().__init__(
            [self._canvas_box, self._side_box],
            layout=widgets.Layout(flex_flow="row wrap", align_items="flex-start"),
            **display,
            color_by=color_by,
        )
        try:
            self._wire(keypad)
        except BaseException:
            self.close()  # a source failing here must not leave the widget models behind
            raise

    def _wire(self, keypad) -> None:
        """Connect the parts and send the initial picture (the last step of construction)."""
        self._sync_traits()
        self._sync_levels()
        self._sync_stack()

        self.events.on_dom_event(self._handle_event)
        self.companion.on_drawn(self._handle_drawn)
        self.companion.on_focus_lost(self._handle_focus_lost)
        self.companion.on_screenshot(self._on_screenshot)
        self.scene.on_view_count(self._on_view_count)
        self.scene.on_eye_moved(self._eye_moved)
        self.observe(self._on_state_trait, names=list(_STATE_TRAITS))
        self.observe(self._on_display_trait, names=list(_DISPLAY_TRAITS))
        self.observe(self._on_color_by, names="color_by")
        self.observe(self._on_levels, names="levels")
        self.observe(self._on_field_setting, names=["inside", "caps"])
        self.observe(self._on_stack_trait, names=["slices", "spacing", "arrangement"])
        self.observe(self._on_keypad, names="keypad")
        self.keypad = keypad

        # The initial picture is part of the models' state: not "in flight".
        self._pump.send_now(expect_ack=False)
        # A big field's coarse copy (for held keys) is built in the background from now on, with
        # a progress bar; its first picture above read only the chunks the cut touches.  Only with
        # the ticker running (a live widget): scripts and tests stay deterministic.
        prepare = getattr(self._level_source, "prepare_coarse", None)
        if prepare is not None and self._pump.autotick:
            prepare(progress=True)

    # ------------------------------------------------------------------ API
    @property
    def polytope(self):
        """The `Polytope` shown, or None when the source is not a polytope."""
        return getattr(self.source, "polytope", None)

    @property
    def slice(self):
        """The source's slice of the current state (what the view shows, or is about to)."""
        with self._pump.lock:
            return self._current_slice()

    @property
    def stats(self):
        """Counters of the update pump (`rot4d_widget.view.pump.PumpStats`): ``updates`` sent, ``acks``
        and the updates they ``acknowledged``, ``timeouts``."""
        return self._pump.stats

    @property
    def held_keys(self) -> tuple:
        """The keys (browser ``code``s) held now, in the order pressed."""
        return self._repeater.held_keys

    @property
    def hold_delay(self) -> float:
        return self._repeater.hold_delay

    @property
    def tick_rate(self) -> float:
        return self._repeater.tick_rate

    @property
    def ack_timeout(self) -> float:
        return self._pump.ack_timeout

    @property
    def in_flight(self) -> bool:
        """True while an update awaits the page's "drawn" acknowledgement."""
        return self._pump.in_flight is not None

    @property
    def help_visible(self) -> bool:
        return self.help_panel.layout.display != "none"

    @help_visible.setter
    def help_visible(self, value: bool) -> None:
        self.help_panel.layout.display = None if value else "none"

    def press(self, key: str, shift: bool = False) -> bool:
        """Press ``key`` once from code (one step; no hold); redraws. False if unbound or no change."""
        found = self.state.keymap.resolve(key, shift)
        if found is None:
            return False
        action, inverted = found
        with self._pump.lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            if action.kind == "help":
                self.help_visible = not self.help_visible
                return True
            changed = self._step(action, inverted)
            self._pump.flush()
            return changed

    def screenshot(self, path=None, callback=None):
        """Ask the page for a PNG of the view as shown; returns at once (the request id, or None).

        The kernel handles the page's answer only after the running cell ends, so nothing
        here waits: when the PNG arrives it is written to ``path`` (str or path-like; None:
        not written), handed to ``callback(png_bytes)`` and kept as `last_screenshot`
        (bytes).  The readout says what happened, also when no view is displayed to answer
        (then None is returned).  Key p does the same with a numbered file in the current
        directory (next to the notebook).
        """
        if path is not None:
            import os

            if not isinstance(path, (str, os.PathLike)):
                raise TypeError(f"Expected `path` to be a str, a path-like or None, got {type(path).__name__}")
        if callback is not None and not callable(callback):
            raise TypeError(f"Expected `callback` to be callable or None, got {type(callback).__name__}")
        with self._pump.lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            return self._ask_screenshot(path, callback, warn=True)

    def _ask_screenshot(self, path, callback, warn=False):
        # asked in any case: a front end that does not count views (count 0) may still answer;
        # unanswered requests are dropped after SCREENSHOT_TIMEOUT and beyond
        # MAX_PENDING_SCREENSHOTS, so none piles up whatever is pressed
        now = self._pump.clock()
        for old in [k for k, v in self._screenshots.items() if now - v[2] > SCREENSHOT_TIMEOUT]:
            del self._screenshots[old]  # nobody answered: dropped
        while len(self._screenshots) >= MAX_PENDING_SCREENSHOTS:
            del self._screenshots[next(iter(self._screenshots))]
        self._screenshot_seq += 1
        rid = self._screenshot_seq
        self._screenshots[rid] = (path, callback, now)
        self.companion.request_screenshot(rid)
        if self.scene.view_count == 0:  # kept, bounded by the timeout and the cap above
            text = "no view is displayed to answer: no screenshot (display the widget first)"
            self._set_note(text)
            if warn:  # from code: say it where the code runs (key p: the readout says it)
                warnings.warn(f"Rot4DWidget.screenshot: {text}", stacklevel=3)
            return None
        shown = "rot4d-NNN.png" if path is _KEY_P else path
        self._set_note(f"screenshot asked{' for ' + str(shown) if shown is not None else ''}\u2026")
        return rid

    def _on_screenshot(self, rid, png, error) -> None:
        """A view answered request ``rid`` (the first answer counts; later views' are dropped)."""
        with self._pump.lock:
            asked = self._screenshots.pop(rid, None)
            if asked is None or self._closed:
                return
            path, callback, _ = asked
            if png is None:
                self._set_note(f"screenshot failed: {error}")
                return
            self.last_screenshot = png
            where = "kept as last_screenshot"
            if path is not None:
                try:
                    if path is _KEY_P:
                        path, self._shot_number = _write_numbered_png(png, self._shot_number)
                    else:
                        path = _write_png(path, png)
                except OSError as exc:
                    self._set_note(f"screenshot not saved: {exc}")
                    return
                where = f"saved {path}"
            self._set_note(f"{where} ({_png_size_text(png)})")
        if callback is not None:
            try:
                callback(png)
            except Exception as exc:  # shown like any callback error, never lost
                self._report_error(exc)

    def _screenshot_key(self) -> None:
        """Key p: a numbered PNG in the current directory (rot4d-001.png, ...), never overwriting
        and never through a link; the number is chosen when the picture arrives."""
        self._ask_screenshot(_KEY_P, None)

    # ------------------------------------------------------------ key pad
    def _on_keypad(self, change) -> None:
        if change["new"] and self._pad is None:
            self._pad = self._build_keypad()
            self._canvas_box.children = (*self._canvas_box.children, self._pad)
        if self._pad is not None:
            self._pad.layout.display = None if change["new"] else "none"
            if not change["new"]:
                self.release_keys()

    def _build_keypad(self):
        """Rows of buttons, one per bound action in `_PAD_ROWS`; each button's presses feed the
        same repeater as keys (ipyevents mouse and touch events on the button).  If building
        fails halfway (a comm that raises), every widget made for it is closed again."""
        from ipywidgets.widgets.widget import _instances

        before = set(_instances)
        try:
            return self._make_keypad()
        except BaseException:
            made = [w for k, w in list(_instances.items()) if k not in before]
            self._pad_events = [ev for ev in self._pad_events if ev not in made]
            for w in made:
                _close_quietly(w)
            raise

    def _make_keypad(self):
        rows = []
        for title, row in _PAD_ROWS:
            buttons = []
            for key, shift in row:
                found = self.state.keymap.resolve(key, shift)
                if found is None:
                    continue
                action, inverted = found
                b = widgets.Button(
                    description=action.label(inverted),
                    tooltip=f"{'Shift+' if shift else ''}{key}: {action.describe()}",
                    layout=widgets.Layout(width="auto", min_width="3.6em", height="2.2em", padding="0 0.3em"),
                )
                b.add_class("rot4d-pad-button")
                ev = Event(source=b, watched_events=list(_PAD_EVENTS), prevent_default_action=True)
                ev.on_dom_event(lambda event, key=key, shift=shift: self._handle_pad_event(key, shift, event))
                self._pad_events.append(ev)
                buttons.append(b)
            if buttons:
                label = widgets.HTML(f"<small>{html.escape(title)}</small>", layout=widgets.Layout(width="4.5em"))
                rows.append(widgets.HBox([label, *buttons], layout=widgets.Layout(flex_flow="row wrap")))
        box = widgets.VBox(rows, layout=widgets.Layout(margin="0.3em 0 0 0"))
        box.add_class("rot4d-keypad")
        return box

    def _handle_pad_event(self, key, shift, event) -> None:
        """A key pad button: mousedown / touchstart press its key, the rest release it. Never raises."""
        try:
            etype = event.get("type") if isinstance(event, Mapping) else None
            key_id = f"pad:{key}{'+shift' if shift else ''}"
            if etype in ("mousedown", "touchstart"):
                if etype == "mousedown" and event.get("button", 0) != 0:
                    return  # the main button only (a right click opens no repeat)
                found = self.state.keymap.resolve(key, shift)
                if found is None or self._has_no_view():
                    return
                action, inverted = found
                with self._pump.lock:
                    if self._closed or key_id in self._repeater.held_keys:
                        return  # a touch's emulated mousedown: one press only
                    self._press(key_id, action, inverted, _page_time(event))
            elif etype in ("mouseup", "mouseleave", "touchend", "touchcancel"):
                self._release(key_id, _page_time(event))
        except Exception as exc:  # shown, never lost, never raised into the kernel
            self._report_error(exc)

    def _set_note(self, text: str) -> None:
        self._note = text
        self.readout.value = self._readout_html()

    def refresh(self) -> None:
        """Redraw after changing `state` or the source directly; obeys the flow control."""
        with self._pump.lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            self._source_version += 1
            st = self.state
            _fit_c0_range(st, self.source)  # a field's w_per_unit may have changed
            for name in ("c0_step", "theta0", "alpha", "c0", "matrix"):  # `state` may have been set directly
                self._recorder.record_set(name, getattr(st, name))
            self._sync_traits()
            self._pump.mark_dirty()
            self._pump.flush()

    # ------------------------------------------------------- keeping what you see
    @property
    def recording(self):
        """What was applied since the widget was made (or `start_recording`): a
        `rot4d_widget.keep.recording.Recording` of every step (keys, key pad, `press`, repeats) and
        every parameter set (sliders, traits, `refresh`), time-stamped.  Save it
        (``.save(path)``), replay it (`replay`) or render it (`render_animation`)."""
        return self._recorder.recording()

    def start_recording(self) -> None:
        """Forget what was recorded; record from the current state on."""
        with self._pump.lock:
            self._recorder.restart(self.state, _source_settings(self.source))

    def replay(self, recording) -> None:
        """Apply a `Recording` (or a path to a saved one) to this widget: its starting state,
        then every event, ending where the recording ended (to rounding; a source's own
        actions, e.g. a stack's n / b, are replayed on this widget's source).  Redraws once."""
        from ..keep.recording import Recording

        if not isinstance(recording, Recording):
            import os

            if not isinstance(recording, (str, os.PathLike)):
                raise TypeError(f"Expected a Recording or a path to one, got {type(recording).__name__}")
            recording = Recording.load(recording)
        with self._pump.lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            recording.replay(self.state, _LiveSource(self), set_source=self._set_source_setting)
            self._source_version += 1
            self._sync_levels()
            self._sync_stack()
            self._recorder.restart(self.state, _source_settings(self.source))
            self._sync_traits()
            self._pump.mark_dirty()
            self._pump.flush()

    def _set_source_setting(self, name, value) -> None:
        """A recorded source setting, applied as its trait would be (a stack made if needed)."""
        if isinstance(value, list):
            value = tuple(value)
        self._sync_stack()  # the replay's steps changed the source: the traits must say what it is
        self._sync_levels()
        setattr(self, name, value)

    def render_animation(self, path, *, recording=None, fps: float = 10.0, per: str = "step", **options) -> int:
        """Draw `recording` (default: this widget's) without a browser into an animated GIF
        (Pillow) or MP4 (imageio-ffmpeg), by ``path``'s extension; one frame per step
        (``per="step"``) or per 1/fps s of recorded time (``per="time"``); the widget's look
        (`render` settings).  Returns the number of frames.  See
        `rot4d_widget.keep.recording.render_animation` for ``options`` (size, dpi, max_frames ...)."""
        from ..keep.export import settings_of
        from ..keep.recording import render_animation

        rec = self.recording if recording is None else recording
        kwargs = {**settings_of(self), **options}
        return render_animation(rec, None, self._level_source, path, fps=fps, per=per, **kwargs)

    def render(self, path=None, *, size=None, dpi: float = 100, **options):
        """The view as a static matplotlib figure (no browser): the current state, source and
        display settings, the live view's camera, palette and scale; written to ``path`` (PNG,
        SVG or PDF by extension) if given.  ``size`` in pixels, default the canvas's.  Returns
        the `matplotlib.figure.Figure`."""
        from ..keep.export import settings_of
        from ..keep.figures import render_state

        with self._pump.lock:
            state = self.state.copy()
            kwargs = {**settings_of(self), **options}
        size = (self.scene.width, self.scene.height) if size is None else size
        return render_state(state, self._level_source, path, size=size, dpi=dpi, **kwargs)

    def slice_mesh(self, **options):
        """What the view shows as one `trimesh.Trimesh`: every face of the slice (all levels of a
        field, all slices of a stack, placed as shown), in the source's own units, with each
        face's group (cell / level / slice) in ``mesh.face_attributes["group"]`` and the
        view's colours.  ``.export("slice.ply")`` writes OBJ, PLY, STL or GLB by extension.
        See `rot4d_widget.keep.export.slice_mesh` for ``options``."""
        from ..keep.export import slice_mesh

        with self._pump.lock:
            data = self._current_slice()
            colors = self._group_colors()
        kwargs = {"color_by": self.color_by, **options}
        if colors is not None and "group_colors" not in options:
            kwargs["group_colors"] = colors
        return slice_mesh(data, **kwargs)

    def save_state(self, path) -> dict:
        """Write the state (orientation, θ0, α, c0, c0 step, key bindings), what the source is
        and the widget's settings to the JSON file ``path`` (`rot4d_widget.keep.export.save_state`).
        A source that cannot be rebuilt from the file (an in-memory array) is described with a
        warning; `load_state` into a widget showing it still works.  Returns the dict written."""
        from ..keep.export import save_state, settings_of

        with self._pump.lock:
            state = self.state.copy()
            settings = settings_of(self)
        return save_state(path, state, self.source, settings)

    def load_state(self, path) -> None:
        """Read a `save_state` file into this widget: its state (which `r` now resets to), key
        bindings and settings.  The file's source must be of this widget's kind
        (``ValueError`` otherwise; `from_state` builds a widget for the file's own source)."""
        from ..keep.export import load_state

        loaded = load_state(path, source=self.source)
        self._apply_loaded(loaded.state, loaded.settings)

    @classmethod
    def from_state(cls, path, source=None, *, allow_code: bool = False, **kwargs) -> "Rot4DWidget":
        """A widget for a `save_state` file: its source rebuilt from the file (or ``source``,
        needed when the file says it cannot be rebuilt), its settings, its state.

        A file is data: a field made from a function is refused unless ``allow_code=True``
        (then the module the file names is imported) or the source is passed in."""
        from ..keep.export import load_state

        loaded = load_state(path, source=source, allow_code=allow_code)
        if loaded.source is None:
            raise ValueError(f"{path!r} does not say how to rebuild its source: pass it, "
                             "Rot4DWidget.from_state(path, source=...)")
        settings = dict(loaded.settings)
        if _is_stack(loaded.source):  # already parallel slices: not wrapped twice
            for name in ("slices", "spacing", "arrangement"):
                settings.pop(name, None)
        allowed = set(inspect.signature(cls.__init__).parameters)
        init = {k: v for k, v in settings.items() if k in allowed and v is not None}
        w = cls(loaded.source, **{**init, **kwargs})
        w._apply_loaded(loaded.state, {})
        return w

    def _apply_loaded(self, state, settings) -> None:
        from ..keep.export import SETTING_NAMES
        from ..core.state import without_source_keys

        d = state.to_dict()
        d.pop("keymap")
        with self._pump.lock:
            if self._closed:
                raise RuntimeError("This Rot4DWidget is closed")
            self.state.restore(d)  # the loaded state becomes what r resets to
            self._use_keymap(without_source_keys(state.keymap), self.source)
        for name in SETTING_NAMES:  # slices before spacing and arrangement
            value = settings.get(name)
            if value is None or not self.has_trait(name):
                continue
            if isinstance(value, list):
                value = tuple(value)
            if getattr(self, name) != value:
                setattr(self, name, value)
        self.refresh()
        with self._pump.lock:
            self._recorder.restart(self.state, _source_settings(self.source))

    def release_keys(self, page_time=None) -> None:
        """Release every held key (what mouseleave and focus loss do); ``page_time``: the page's
        time of the event in seconds, if known (each key's steps are then corrected to it)."""
        with self._pump.lock:
            for action, inverted, correction in self._repeater.release_all(page_time):
                self._correct(action, inverted, correction)
            self._settle()

    def _settle(self) -> None:
        """At rest (no key held): bring the readout up to date and the rows into the turned frame,
        and send a picture still owed (one whose send failed)."""
        turned = self._shown is not None and self._shown is not self._rows_key
        coarse = self._shown is not None and self._shown[5]
        if self._closed or len(self._repeater):
            return
        if self._readout_stale or turned or coarse:
            self._pump.mark_dirty()
        self._pump.flush()

    def close(self) -> None:
        """Stop the ticker thread, drop the listeners, close every child widget."""
        pump = self.__dict__.get("_pump")
        if pump is None:  # construction failed before any child existed
            return
        with pump.lock:
            if self._closed:
                return
            self._closed = True
            self._repeater.clear()
        pump.close()
        events, companion, scene = (getattr(self, n, None) for n in ("events", "companion", "scene"))
        try:
            if events is not None:
                events.on_dom_event(self._handle_event, remove=True)
            if companion is not None:
                companion.on_drawn(self._handle_drawn, remove=True)
                companion.on_focus_lost(self._handle_focus_lost, remove=True)
                companion.on_screenshot(self._on_screenshot, remove=True)
            if scene is not None:
                scene.on_view_count(self._on_view_count, remove=True)
                scene.on_eye_moved(self._eye_moved, remove=True)
        finally:
            # The Event first, so its document listeners go before the canvas does.
            for ev in self.__dict__.get("_pad_events", ()):
                _close_quietly(ev)
            pad = self.__dict__.get("_pad")
            if pad is not None:
                for row in pad.children:
                    for w in row.children:
                        _close_quietly(w)
                    _close_quietly(row)
            for name in ("events", "companion", "scene", "readout", "help_panel", "errors", "_pad", "_canvas_box",
                         "_side_box"):
                w = getattr(self, name, None)
                if w is not None:
                    _close_quietly(w)
            layout, style = getattr(self, "layout", None), getattr(self, "style", None)
            super().close()
            for w in (layout, style):
                if w is not None:
                    _close_quietly(w)

    def __repr__(self) -> str:
        st = self.state
        return (
            f"Rot4DWidget({self.source!r}, theta0={st.theta0:.6g}, alpha={st.alpha:.6g}, c0={st.c0:.6g}"
            f"{', closed' if self._closed else ''})"
        )

    # --------------------------------------------------------------- traits
    @traitlets.validate("theta0")
    def _valid_theta0(self, proposal):
        value = _theta0(proposal["value"])
        if not self._syncing:  # alpha keeps its ratio: refused here, before the trait changes
            st = self.state
            _check_alpha_beta(st.alpha * (value / st.theta0), value, f"theta0 = {value:.6g} (alpha keeps its ratio)")
        return value

    @traitlets.validate("alpha", "c0")
    def _valid_real(self, proposal):
        value = _finite(proposal["trait"].name, proposal["value"])
        if proposal["trait"].name == "alpha" and not self._syncing:
            _check_alpha_beta(value, self.state.theta0, f"alpha = {value:.6g}")
        return value

    @traitlets.validate("ball_radius", "bar_radius", "face_opacity", "background", "show_balls", "show_bars", "show_faces")
    def _valid_display(self, proposal):
        name = proposal["trait"].name
        return self.scene.check_display({name: proposal["value"]})[name]

    @traitlets.validate("slices")
    def _valid_slices(self, proposal):
        value = proposal["value"]
        if value is not None and (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer))):
            raise TypeError(f"Expected `slices` to be an int in 1 \u2026 64 or None, got {value!r}")
        return value

    @traitlets.validate("spacing")
    def _valid_spacing(self, proposal):
        value = proposal["value"]  # checked here too: True == 1.0 would pass the observer unseen
        if value is not None and (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number))):
            raise TypeError(f"Expected `spacing` to be a finite number > 0 or None, got {value!r}")
        return value

    @traitlets.validate("arrangement")
    def _valid_arrangement(self, proposal):
        value = proposal["value"]
        if value is not None and not isinstance(value, str):
            raise TypeError(f"Expected `arrangement` to be 'oval', 'grid' or 'stack', got {value!r}")
        return value

    @traitlets.validate("color_by")
    def _valid_color_by(self, proposal):
        return _check_color_by(proposal["value"])

    def _sync_traits(self) -> None:
        """Copy the state's parameters into the traits (observers fire for what changed)."""
        st = self.state
        self._syncing = True
        try:
            self.set_trait("orientation", st.matrix)
            for name in _STATE_TRAITS:
                value = getattr(st, name)
                if getattr(self, name) != value:
                    setattr(self, name, value)
        finally:
            self._syncing = False

    @property
    def _level_source(self):
        """The source whose iso levels the `levels` trait holds (a stack's inner source)."""
        return getattr(self.source, "source", self.source) if _is_stack(self.source) else self.source

    def _sync_stack(self) -> None:
        """Copy a stack's N, spacing and arrangement into the traits."""
        if not _is_stack(self.source):
            return
        self._set_quietly("slices", self.source.slices)
        self._set_quietly("spacing", float(self.source.spacing))
        self._set_quietly("arrangement", self.source.arrangement)

    def _set_quietly(self, name, value) -> None:
        """Set a trait without acting on it (the widget copying its own state)."""
        self._syncing = True
        try:
            setattr(self, name, value)
        finally:
            self._syncing = False

    def _source_setting(self, change, target, why_not: str) -> None:
        """A trait that is a setting of (part of) the source: set it on ``target`` and redraw,
        or, if ``target`` is None or refuses the value, put the trait back and raise."""
        if self._syncing:
            return
        with self._pump.lock:
            try:
                if target is None:
                    raise TypeError(why_not)
                with self._source_lock:
                    setattr(target, change["name"], change["new"])
            except Exception:
                self._set_quietly(change["name"], change["old"])
                raise
            self._source_version += 1
            self._recorder.record_source(change["name"], change["new"])
            self._sync_levels()
            self._sync_stack()
            self._pump.mark_dirty()
            self._pump.flush()

    def _on_stack_trait(self, change) -> None:
        if (change["name"] == "slices" and not self._syncing and not _is_stack(self.source)
                and change["new"] is not None):
            with self._pump.lock:  # parallel slices asked for at run time: wrap the source now
                try:
                    self._wrap_in_stack(change["new"])
                except Exception:
                    self._set_quietly("slices", change["old"])
                    raise
                self._recorder.record_source("slices", change["new"])
                self._pump.mark_dirty()
                self._pump.flush()
            return
        self._source_setting(change, self.source if _is_stack(self.source) else None,
                             f"`{change['name']}` applies to parallel slices: set `slices` (or press n) first")

    def _wrap_in_stack(self, slices) -> None:
        """Show ``slices`` parallel slices of the current source from now on (the lock is held).

        The source is wrapped in a `rot4d_widget.sources.tomography.StackSource` (oval, default
        spacing), its keys n / b / g / f join the keymap and the help.  Raises before any
        change if ``slices`` is not allowed.
        """
        from ..sources.tomography import StackSource

        stack = StackSource(self.source, slices=slices)
        # the stack brings the inner source's keys too: rebind them from the reserved ones
        self._use_keymap(without_source_keys(self.state.keymap), stack)
        with self._source_lock:
            self.source = stack
        self._source_version += 1
        self._slice_cache = None
        self._sync_stack()

    def _use_keymap(self, keymap, source) -> None:
        """Bind ``keymap`` plus ``source``'s own keys (its actions runnable), and show them in the help."""
        actions = _source_actions(source)
        if actions:
            keymap = keymap.extended({k: a for k, (a, _, _) in actions.items()})
        self._custom.update({a.name: (run, repeat) for a, run, repeat in actions.values()})
        self.state.keymap = keymap
        self.help_panel.value = ro.help_html(_help_groups(keymap), self._repeater.hold_delay, self._repeater.tick_rate)

    def _sync_levels(self) -> None:
        """Copy the field's settings (iso levels, inside, caps: where the source has them) into the traits."""
        src = self._level_source
        levels = getattr(src, "levels", None)
        if levels is not None:
            self._set_quietly("levels", tuple(float(v) for v in levels))
        for name in ("inside", "caps"):
            if hasattr(src, name):
                self._set_quietly(name, getattr(src, name))

    def _on_field_setting(self, change) -> None:
        src = self._level_source
        self._source_setting(change, src if hasattr(src, change["name"]) else None,
                             f"{_title(self.source)} has no `{change['name']}`: it applies to field sources")

    def _on_levels(self, change) -> None:
        src = self._level_source
        self._source_setting(change, src if hasattr(src, "levels") else None,
                             f"{_title(self.source)} has no iso levels: `levels` applies to field sources")

    def _on_state_trait(self, change) -> None:
        if self._syncing:
            return
        with self._pump.lock:
            setattr(self.state, change["name"], change["new"])
            self._recorder.record_set(change["name"], change["new"])
            if change["name"] == "theta0":  # alpha keeps its ratio to theta0
                self._sync_traits()
            self._pump.mark_dirty()
            self._pump.flush()

    def _on_display_trait(self, change) -> None:
        with self._pump.lock:
            if not self._closed:
                self.scene.set_display(**{change["name"]: change["new"]})

    def _on_color_by(self, change) -> None:
        with self._pump.lock:
            if not self._closed:
                self._pump.mark_dirty()
                self._pump.flush()

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
                key_id = _key_id(event)
                if key_id is not None:
                    self._release(key_id, _page_time(event))
            elif etype == "mouseleave":
                self.release_keys(_page_time(event))
        except Exception as exc:  # shown, never lost, never raised into the kernel
            self._report_error(exc)

    def _handle_drawn(self, seq=None) -> None:
        """Companion: the page rendered a frame containing update ``seq`` (``scene.update_id``)."""
        try:
            self._pump.acknowledge(seq)
        except Exception as exc:
            self._report_error(exc)

    def _handle_focus_lost(self, *args, **kwargs) -> None:
        try:
            self.release_keys()
        except Exception as exc:
            self._report_error(exc)

    def _eye_moved(self, eye) -> None:
        """The camera moved (a mouse orbit ended): send the faces in the order for the new eye."""
        try:
            with self._pump.lock:
                if not self._closed:
                    self._pump.mark_dirty()
                    self._pump.flush()
        except Exception as exc:
            self._report_error(exc)

    def _on_view_count(self, n) -> None:
        try:
            if n > 0:
                self._was_displayed = True
            else:
                self.release_keys()  # no view left: no keyup will come
        except Exception as exc:
            self._report_error(exc)

    def _has_no_view(self) -> bool:
        """True when the canvas was displayed and every view of it is gone.

        Front ends that do not count views leave the count at 0 and never set
        ``_was_displayed``: their keys are always accepted.
        """
        return self._was_displayed and self.scene.view_count == 0

    def _key_down(self, event: Mapping) -> None:
        if event.get("repeat") is True:
            return  # browser auto-repeat: the ticker repeats, not the browser
        if self._has_no_view():
            return  # a listener leaked by a destroyed view (ipyevents): act on nothing
        found = self.state.keymap.lookup(event)
        key_id = _key_id(event)
        if found is None or key_id is None:
            return
        action, inverted = found
        with self._pump.lock:
            if self._closed:
                return
            self._repeater.release(key_id)
            self._press(key_id, action, inverted, _page_time(event))

    def _press(self, key_id, action: Action, inverted: bool, page_time=None) -> None:
        """Key (or key pad button) ``key_id`` went down: one step now, repeats while held (lock held).

        ``page_time``: the page's time of the keydown (s), against which the keyup's corrects
        the number of steps (`rot4d_widget.view.keyhold`)."""
        if action.kind == "help":
            self.help_visible = not self.help_visible
            return
        now = self._pump.clock()
        changed = self._step(action, inverted)
        if action.kind in REPEATING_KINDS or (action.kind == "custom" and self._custom[action.name][1]):
            self._repeater.press(key_id, action, inverted, now, page_time=page_time, applied=changed)
        self._pump.flush(now)

    def _release(self, key_id, page_time=None) -> None:
        """Key (or key pad button) ``key_id`` went up at the page's ``page_time`` (s): no more
        repeats, its steps corrected to what the page says the hold was; at rest, settle."""
        with self._pump.lock:
            held = self._repeater.held(key_id)
            correction = self._repeater.release(key_id, page_time)
            if held is not None:
                self._correct(*held, correction)
            self._settle()

    def _correct(self, action: Action, inverted: bool, correction: int) -> None:
        """Take back (``correction`` < 0) or add (> 0) steps of a released key (lock held).

        A late keyup lets the ticker repeat a key the user had already released; the page's
        timestamps say how many steps the hold made, and this makes the state agree.  Each
        step taken back is the opposite step, recorded like any other."""
        if correction < 0:  # however many (a keyup 80 s late): the traits are synced once
            opposite = _opposite(action, inverted)
            undone = sum(self._apply_step(*opposite) for _ in range(-correction))
            if undone:
                if self._last_label == action.label(inverted):
                    self._last_count = max(self._last_count - undone, 1)
                self._after_steps(action)
        clock = self._pump.clock
        start = clock()
        for _ in range(max(correction, 0)):  # missing steps: within one tick's time, like a tick
            if clock() - start > self._repeater.period:
                break
            self._step(action, inverted)

    # ------------------------------------------------------------ stepping
    def _tick(self, now: float) -> None:
        """Pump callback: the held keys' steps due by ``now``; a tick that overran (slow
        observers, a loaded machine) drops the ticks it missed instead of bursting."""
        rep = self._repeater
        clock = self._pump.clock
        for key_id, action, inverted in rep.due_keys(now):
            if self._step(action, inverted):
                rep.note_applied(key_id)
            if clock() - now > rep.period:
                break  # over budget: the rest of this catch-up is dropped, the lock let go
        after = clock()
        if after - now > rep.period:
            rep.drop_missed(after)

    def _step(self, action: Action, inverted: bool) -> bool:
        """One step of ``action``: applied, recorded, counted in the readout, traits synced."""
        changed = self._apply_step(action, inverted)
        if changed:
            label = action.label(inverted)
            if label == self._last_label:
                self._last_count += 1
            else:
                self._last_label, self._last_count = label, 1
            self._after_steps(action)
        return changed

    def _apply_step(self, action: Action, inverted: bool) -> bool:
        """Apply and record one step (no trait sync: `_after_steps` does it once); True if it changed."""
        if action.kind == "custom":
            run = self._custom.get(action.name)
            if run is None:
                return False
            with self._source_lock:
                result = run[0](-1 if inverted else 1)
            if result is False:  # refused (at a bound): nothing changed, nothing recorded
                return False
            self._source_version += 1
            self._recorder.record(None, False, action, inverted)
            return True
        if action.kind == "screenshot":
            self._screenshot_key()
            return False
        if action.kind == "slices" and not _is_stack(self.source):
            # n on a single slice: the first added slice makes the view a stack of two (recorded
            # as the source setting it is; the stack's own keys are steps from here on)
            if (-1 if inverted else 1) * action.sign <= 0:
                return False
            self._wrap_in_stack(2)
            self._recorder.record_source("slices", 2)
            return True
        changed = self.state.apply(action, inverted)
        if changed:
            self._recorder.record(None, False, action, inverted)
        return changed

    def _after_steps(self, action: Action) -> None:
        """After steps of ``action`` changed something: redraw, and the traits say what it is."""
        self._pump.mark_dirty()
        if action.kind in ("custom", "slices"):
            self._sync_levels()
            self._sync_stack()
        self._sync_traits()

    def _current_slice(self, coarse: bool = False):
        st = self.state
        m, c0, version = st.matrix, st.c0, self._source_version
        coarse = bool(coarse and self._coarse_ok)
        cached = self._cached_slice(m, c0, version, coarse)
        if cached is not None:
            return cached
        data = _checked_slice(self.source, m, c0, coarse, self._source_lock)
        self._slice_cache = (m, c0, version, coarse, data)
        return data

    def _cached_slice(self, m, c0, version, coarse):
        cache = self._slice_cache
        if cache is not None and cache[0] is m and cache[1] == c0 and cache[2] == version and cache[3] == coarse:
            return cache[4]
        return None

    def _send(self):
        """Pump callback: show the latest state; the update's id, or None if nothing was sent.

        While keys are held, a change that only turns the slice in 3-D (the
        rotation since the rows shown leaves w alone, nothing else changed) is
        sent as a turn, a few bytes, without slicing; at rest the rows are
        re-sent in the new frame (the faces' order is exact again).
        """
        st = self.state
        scene = self.scene
        held = bool(len(self._repeater))
        coarse = held and self._coarse_ok
        shown, rows = self._shown, self._rows_key
        key = (st.matrix, st.c0, scene.eye, self._source_version, self.color_by, coarse)
        sent = None
        same_cut = rows is not None and key[1:4] == rows[1:4] and key[4] == rows[4]
        if shown is not None and _same(key, shown) and (shown is rows or held):
            pass  # the view shows this state (turned rows only while keys are held)
        elif (held and same_cut and (key[5] or not rows[5]) and not _is_stack(self.source)
              and _leaves_w_alone(key[0], rows[0])):  # a stack turns each slice about its own centre
            if scene.turn((np.asarray(key[0]) @ np.asarray(rows[0]).T)[:3, :3]):
                sent = scene.update_id
            self._shown = key
        else:
            single = None if self.color_by == "group" else look.as_rgb(self.color_by, "color_by")
            if (self._coarse_ok and same_cut and not rows[5] and not coarse and self._rows_data is not None
                    and _leaves_w_alone(key[0], rows[0])):
                # the same cut turned in 3-D: turn the full-resolution slice shown, no resampling
                t = (np.asarray(key[0]) @ np.asarray(rows[0]).T)[:3, :3]
                data = self._rows_data.turned(t)
            else:
                m, c0, version, coarse_ = key[0], key[1], key[3], bool(coarse and self._coarse_ok)
                data = self._cached_slice(m, c0, version, coarse_)
                if data is None:
                    source, lock = self.source, self._source_lock
                    # the slow part: on the ticker thread it runs with the pump's lock free, so
                    # keys go on changing the state meanwhile (the next picture takes the latest)
                    data = yield (lambda: _checked_slice(source, m, c0, coarse_, lock))
                    if self._closed:
                        return None
                    if self._source_version != version or self.source is not source:
                        self._pump.mark_dirty()  # the source changed meanwhile: never show the old one
                        return None
                    self._slice_cache = (m, c0, version, coarse_, data)
            colors = self._group_colors()
            extra = {} if colors is None else {"group_rgb": colors}
            if scene.show(data, single_rgb=single, **extra):
                sent = scene.update_id
            self._rows_data = data
            self._shown = self._rows_key = key
        now = self._pump.clock()
        if self._update_errors:  # a good picture: the widget has recovered
            self._clear_update_errors()
        if not len(self._repeater) or now - self._readout_at >= READOUT_PERIOD:
            self.readout.value = self._readout_html()
            self._readout_at, self._readout_stale = now, False
        else:
            self._readout_stale = True
        return sent

    # -------------------------------------------------------------- display
    def _readout_html(self) -> str:
        st = self.state
        # a turned view shows the rows' slice turned in 3-D: same census and volume, no new slice
        data = self._rows_data if self._rows_data is not None else self._current_slice()
        if self._last_label is None:
            last = "\u2014"
        else:
            last = html.escape(self._last_label) + (f" \u00d7{self._last_count}" if self._last_count > 1 else "")
        w_range = getattr(self.source, "w_range", None)
        lo, hi = w_range(st.matrix) if w_range is not None else (-self.source.size, self.source.size)
        rows = [
            ("\u03b80", ro.angle_text(st.theta0)),
            ("\u03b1", ro.angle_text(st.alpha)),
            ("\u03b2", ro.angle_text(st.beta)),
            ("c0", ro.gauge_html(st.c0, lo, hi, _w_units(self.source))),
            ("last", last),
        ]
        rows += [(k, html.escape(str(v))) for k, v in getattr(data, "readout", ())]
        colors, labels = self._colours()
        if labels is not None and self.color_by == "group":  # the legend: what each colour is
            rows.append(("colours", " ".join(
                f"<span style='display:inline-block;width:0.9em;height:0.9em;vertical-align:middle;"
                f"background:#{''.join(f'{round(255 * c):02x}' for c in rgb)}'></span>&nbsp;{html.escape(t)}"
                for t, rgb in zip(labels, colors))))
        volume = getattr(data, "volume", None)
        if volume is not None and math.isfinite(float(volume)):
            rows.append(("volume", _volume_text(self.source, float(volume), st.matrix)))
        if self._note:
            rows.append(("picture", html.escape(self._note)))
        return ro.readout_html(_title(self.source), rows, gizmo=ro.gizmo_svg(st.matrix))

    def _group_colors(self):
        """The colour of every group of the source as it is now (`_colours`)."""
        return self._colours()[0]

    def _colours(self):
        """``(rgb (G, 3), labels or None)``: a stack's colours by w, else a field's by level (also
        inside a stack of one slice), else the scene's palette sized to the source's groups
        now (labels None: cells need no legend).  Follows the source when it changes."""
        src = self.source
        if _is_stack(src):
            rgb = src.group_colors()
            if rgb is not None:
                return rgb, [data_w_text(src.source, w) for w in src.levels_at(self.state.c0)]
            src = src.source
        rgb = _level_colors(src)
        if rgb is not None:
            return rgb, [f"{lv:.4g}" for lv in src.levels]
        return self.scene.palette(int(self.source.n_groups)), None

    def _report_error(self, exc: BaseException) -> None:
        """Show an exception in the ``errors`` area (and the log); never raises.

        The area shows what went wrong since the last good picture: the next update that
        is sent clears it (the widget has recovered)."""
        try:
            text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
            log.error("Rot4DWidget: error while handling a key\n%s", text)
            self._repeater.clear()
            if isinstance(exc, BadSlice):  # the source's fault, said in one line: no traceback of ours
                text = f"{type(exc).__name__}: {exc}\n"
            shown = tuple(self.errors.outputs)
            if shown and shown[-1].get("text") == text:
                return  # the same error again (a retry of the same picture): shown once
            item = {"output_type": "stream", "name": "stderr", "text": text}
            self.errors.outputs = shown[-(MAX_ERRORS_SHOWN - 1):] + (item,)
            self._update_errors = self.errors.outputs
        except Exception:
            log.exception("Rot4DWidget: could not report an error")

    def _clear_update_errors(self) -> None:
        shown, self._update_errors = self._update_errors, ()
        if tuple(self.errors.outputs) == tuple(shown):
            self.errors.outputs = ()


# ------------------------------------------------------------------ helpers
def _is_stack(source) -> bool:
    """True for parallel slices (`rot4d_widget.sources.tomography.StackSource`) without importing it."""
    return type(source).__name__ == "StackSource" and hasattr(source, "levels_at")


def _source_settings(source) -> dict:
    """The settings a recording starts from: a source's iso levels, a stack's N, Δ (None while
    it follows N) and arrangement (`rot4d_widget.keep.recording.Recorder`'s ``source_settings``)."""
    out = {}
    stack = _is_stack(source)
    inner = source.source if stack else source
    levels = getattr(inner, "levels", None)
    if levels is not None:
        out["levels"] = tuple(float(v) for v in levels)
    for name in ("inside", "caps"):
        if hasattr(inner, name):
            out[name] = getattr(inner, name)
    if stack:
        out["slices"] = int(source.slices)
        out["spacing"] = None if source.spacing_is_default else float(source.spacing)
        out["arrangement"] = source.arrangement
    return out


def _volume_text(source, volume: float, matrix) -> str:
    """The slice's 3-volume in the source's own units (a field's space units cubed when it names
    them, ``space_units``); a field turned so that w is mixed in counts w at ``w_per_unit`` data
    w per unit of space, and says so."""
    inner = source.source if _is_stack(source) else source
    unit = getattr(inner, "space_units", None)
    text = ro.number_text(volume) + (f" {unit}³" if unit else "")
    wpu = getattr(inner, "w_per_unit", None)
    if wpu is not None and abs(abs(float(np.asarray(matrix)[3, 3])) - 1.0) > 1e-12:
        wu = getattr(inner, "w_units", None)
        text += (f" (w counted at {ro.number_text(wpu)}{' ' + wu if wu else ''} per "
                 f"{unit if unit else 'unit of space'})")
    return text


class _LiveSource:
    """The widget's source as it is at each moment (a replay may turn it into a stack midway)."""

    def __init__(self, widget):
        self._widget = widget

    def __getattr__(self, name):
        return getattr(self._widget.source, name)


def _fit_c0_range(state, source) -> None:
    """The l / h range of ``state`` from ``source``'s w frame: twice its size about its centre."""
    origin, per = w_frame(source)
    state.c0_origin = origin
    state.c0_limit = C0_LIMIT_SIZES * float(source.size) * per


def _w_units(source):
    """The unit of c0 (a field's ``w_units``; None for a polytope)."""
    inner = getattr(source, "source", source) if _is_stack(source) else source
    return getattr(inner, "w_units", None)


def _checked_slice(source, matrix, c0, coarse, lock):
    """``source.slice`` validated once (`rot4d_widget.sources.protocol.check_slice`): a bad slice (None,
    non-finite points, indices out of range, a group beyond ``n_groups``) raises a ValueError
    or TypeError naming the source and the member that is wrong, and is never drawn."""
    with lock:
        data = source.slice(matrix, c0, coarse=True) if coarse else source.slice(matrix, c0)
        n_groups = int(source.n_groups)
    try:
        check_slice(data, n_groups)
    except (TypeError, ValueError) as exc:
        raise BadSlice(f"{_title(source)}.slice(matrix, c0={c0:.6g}) returned a bad slice: {exc}") from None
    return data


def _opposite(action: Action, inverted: bool):
    """``(action, inverted)`` of the step that undoes one step of ``action``."""
    if action.is_rotation or action.kind == "custom":
        return action, not inverted
    return dataclasses.replace(action, sign=-action.sign), inverted


def _page_time(event) -> float | None:
    """The page's time of an ipyevents event in seconds (its ``timeStamp``, ms), or None."""
    t = event.get("timeStamp") if isinstance(event, Mapping) else None
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        return None
    return float(t) / 1000.0


#: Key p's request: a numbered file in the current directory, named when the picture arrives.
_KEY_P = object()


_PNG_FLAGS = os.O_WRONLY | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0)


def _write_png(path, png: bytes) -> str:
    """Write ``png`` to ``path`` (replacing a file) but never through a link at that name."""
    name = os.fspath(path)
    if os.path.islink(name):
        raise OSError(f"{name} is a link: a screenshot is never written through one")
    with os.fdopen(os.open(name, _PNG_FLAGS | os.O_TRUNC, 0o666), "wb") as f:
        f.write(png)
    return name


def _write_numbered_png(png: bytes, start: int) -> tuple:
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


def _takes_coarse(source) -> bool:
    """True if ``source.slice`` accepts ``coarse=`` (a cheaper slice while keys repeat)."""
    try:
        params = inspect.signature(source.slice).parameters
    except (TypeError, ValueError):
        return False
    return "coarse" in params


def _level_colors(source):
    """Colours of a source's iso levels (a matplotlib colormap over its data range), or None."""
    levels = getattr(source, "levels", None)
    if not levels:
        return None
    lo, hi = getattr(source, "data_range", (min(levels), max(levels)))
    return look.level_colors(levels, lo, hi)


def _same(a, b) -> bool:
    """Two (matrix, c0, eye, version, color_by, coarse) keys describe the same state."""
    return a[1:] == b[1:] and (a[0] is b[0] or np.array_equal(a[0], b[0]))


def _leaves_w_alone(m, m_rows) -> bool:
    """True if ``m = R3 @ m_rows`` for a rotation R3 of x, y, z only (w untouched)."""
    t = np.asarray(m) @ np.asarray(m_rows).T
    return abs(t[3, 3] - 1.0) < 1e-12


def _title(source) -> str:
    name = getattr(source, "name", None)
    return str(name) if name else type(source).__name__


def _check_color_by(value):
    if value == "group":
        return value
    try:
        look.as_rgb(value, "color_by")
    except ValueError:
        raise ValueError(
            f"Expected `color_by` to be 'group' or one colour ('#rrggbb', '#rgb', three floats in [0, 1]), got {value!r}"
        ) from None
    return value if isinstance(value, str) else tuple(float(x) for x in value)


def _default_ball_radius(source, scale, state) -> float:
    """min(0.07, 0.1 x displayed edge): the polytope's edge, else the first slice's median segment."""
    edge = getattr(source, "edge_length", None)
    if edge is None:
        data = _checked_slice(source, state.matrix, state.c0, False, threading.RLock())
        seg = np.asarray(data.segments)
        if len(seg):
            p = np.asarray(data.points, dtype=np.float64)
            edge = float(np.median(np.linalg.norm(p[seg[:, 0]] - p[seg[:, 1]], axis=1)))
        if not edge:
            return look.default_ball_radius(0.3)
    return look.default_ball_radius(float(edge) * scale)


def _source_actions(source) -> dict:
    """``{key: (Action, run, repeat)}`` for the source's optional ``actions`` mapping."""
    actions = getattr(source, "actions", None)
    if not actions:
        return {}
    if not isinstance(actions, Mapping):
        raise TypeError(f"Expected `source.actions` to be a mapping of key -> SourceAction, got {type(actions).__name__}")
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


def _help_groups(keymap: Keymap) -> list:
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
        rows.append((" ".join(reserved), "reserved", "iso levels (fields), fewer slices and spacing (parallel slices): not active in this view"))
    return rows


#: The key pad: (row title, ((key, shift), ...)); keys not bound in the keymap are left out.
_PAD_ROWS = (
    ("simple", tuple((k, False) for k in "23468c")),
    ("inverse", tuple((k, True) for k in "23468c")),
    ("double", (("y", False), ("z", False), ("w", False), ("y", True), ("z", True), ("w", True))),
    ("\u03b1, c0", (("k", False), ("j", False), ("l", False), ("h", False))),
    ("step", (("+", False), ("-", False), ("r", False))),
)
_PAD_EVENTS = ("mousedown", "mouseup", "mouseleave", "touchstart", "touchend", "touchcancel")


def _png_size_text(png: bytes) -> str:
    """'600 x 500 px' from a PNG's header (IHDR), or its byte count if it has none."""
    if len(png) >= 24 and png[12:16] == b"IHDR":
        return f"{int.from_bytes(png[16:20], 'big')} \u00d7 {int.from_bytes(png[20:24], 'big')} px"
    return f"{len(png)} bytes"


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
