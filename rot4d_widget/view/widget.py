"""`Rot4DWidget`: turn a 4-D object with single key strokes, watch its w = c0 slice.

The only module that makes the widget's ipyevents `Event`.  A key travels one way::

    ipyevents dict -> keys.KeyPath -> keymap.lookup -> state.apply -> (pump: flow control)
    -> painter.Painter.send -> source.slice -> buffers -> scene.show (one new float32 array) + readout

The widget holds the traits and the public API and wires small units together, handing each
the collaborators it uses by name (its constructor, and ``connect`` where two units call each
other); none is handed the widget, except as its ``traits`` (the settings it reads and observes,
nothing else: `tests/project/test_rules.py`).  What they share:

* `rot4d_widget.view.showing.Showing` -- the source shown, its scale, its lock and version;
* `rot4d_widget.view.errors.ErrorArea` -- where an exception of a callback is shown;
* `rot4d_widget.view.keys.KeyPath` -- key and key pad events to steps: press, release,
  the steps a held key makes, their recording;
* `rot4d_widget.view.keyhold.KeyRepeater` -- which steps held keys make when
  (hold delay, tick rate, no burst after a stall);
* `rot4d_widget.view.pump.UpdatePump` -- at most `MAX_IN_FLIGHT` updates in flight, the
  "drawn" acknowledgements, the timeout, the ticker thread, the lock, open or closed;
* `rot4d_widget.view.painter.Painter` -- what is shown: slice, turn or nothing, the slice
  cache, the readout;
* `rot4d_widget.view.sync.TraitSync` -- traits <-> state and source settings;
* `rot4d_widget.view.stacking.Stacking` -- a single view made parallel slices at run time;
* `rot4d_widget.view.keypad.KeyPad`, `rot4d_widget.view.screenshots.Screenshots`,
  `rot4d_widget.view.keeping.Keeper` (render, export, state files, recordings);
* `rot4d_widget.view.markup` -- every piece of HTML shown (readout, help), from escaped text;
* `rot4d_widget.view.scene.Scene` -- everything pythreejs.

Rotation stops on keyup, on mouseleave, and when the companion reports that
the page or window lost focus (a keyup after that never arrives).  A widget
whose canvas views are all gone (the cell was re-run) ignores key events:
ipyevents leaves its document key listener behind when a view is destroyed
while hovered, and those keys must not turn an invisible widget.  Exceptions
raised while handling a key are shown in the widget's ``errors`` area (and
stop held keys); they never escape into the event loop.

Parameters are typed traits (`rot4d_widget.view.traits`: `theta0`, `alpha`, `c0`, read-only
`orientation`, and the display options), kept in step with `state`: ``ipywidgets.link`` and
``observe`` work both ways.  Observers of those traits run in the kernel's
ticker thread while a key is held (up to ``tick_rate`` times a second): keep
them short.  The traits live in the kernel only (use ``link``, not
``jslink``).
"""

from __future__ import annotations

import logging
import os
import threading

import ipywidgets as widgets
import numpy as np
import traitlets
from ipyevents import Event

from ..core import colours, renderings, sizes
from ..core.keymap import DEFAULT_KEYMAP, Keymap
from ..core.state import DEFAULT_THETA0, RotationState, check_alpha_beta
from ..sources.arrangements import ARRANGEMENTS
from ..sources.protocol import as_source, inner_source, takes_coarse, w_frame
from . import markup
from . import progress as _progress  # registers the kernel's progress bar with the core; the widget's own
from . import traits as t
from .buffers import estimate_capacity
from .companion import Companion
from .cuts import can_sample
from .errors import MAX_ERRORS_SHOWN, ErrorArea  # noqa: F401 - MAX_ERRORS_SHOWN: part of the module's names
from .keeping import Keeper
from .keyhold import HOLD_DELAY, TICK_RATE, KeyRepeater, positive_seconds
from .keypad import KeyPad, close_quietly
from .keys import KeyPath, help_groups, source_actions
from .painter import READOUT_PERIOD, Painter, checked_slice, title
from .projection import ProjectionFlag, ProjectionView
from .pump import ACK_TIMEOUT, MAX_IN_FLIGHT, UpdatePump
from .renderings import Renderings
from .screenshots import Screenshots
from .showing import C0_LIMIT_SIZES, Showing
from .stacking import Stacking, make_stack
from .sync import DISPLAY_TRAITS, STACK_TRAITS, TraitSync

__all__ = ["Rot4DWidget", "HOLD_DELAY", "TICK_RATE", "ACK_TIMEOUT", "MAX_IN_FLIGHT", "C0_STEP_FRACTION",
           "READOUT_PERIOD"]

log = logging.getLogger(__name__)

#: The l/h step as a fraction of the source's size (circumradius).
C0_STEP_FRACTION = 1.0 / 64.0

_WATCHED_EVENTS = ["keydown", "keyup", "mouseleave"]


def _scene_classes():
    """Import the rendering path lazily (pythreejs is heavy), once."""
    # the scene imports pythreejs (~0.3 s): imported when the first view is built
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
        `rot4d_widget.core.sizes.REFERENCE_RADIUS`).  Default from the source's edge
        length (polytopes) or its first slice.
    face_opacity : float in [0, 1]
    background : colour ('#rrggbb', '#rgb' or three floats in [0, 1])
    show_balls, show_bars, show_faces : bool
    color_by : "group" (each triangle the colour of its group: a polytope's
        4-D cell) or one colour for every face (e.g. ``"#9fb6cd"``)
    group_colors : sequence of colours, one per group, optional
    antialias : bool -- WebGL multisampling (default False).
    slices, spacing, arrangement : int, float, str, optional
        Parallel slices at w = c0 + (k - (N - 1)/2) * spacing (4-D tomography,
        `rot4d_widget.sources.tomography.StackSource`), placed "oval" (on a parabola, the slice at
        c0 nearest the eye), "grid" or "stack"; keys n / b and g / f change N and the spacing (in
        the source's w units, like c0; default: the record's extent along w over N, spread when
        made and on n / b).  Also traits: `slices` (or n) on a single view makes parallel slices.
    levels : float or sequence of floats, optional
        Iso levels of a field source (`Field4D`); also the `levels` trait, and keys
        o / i move them.  Several are drawn as nested translucent surfaces.
    cmap, clim : str; (lo, hi) or None
        A field's colour scale (also traits): a matplotlib colour map name and its limits (None: the
        data's range, the levels spread over the map by rank), for its surfaces and colour bar.
    keypad : bool
        An on-screen key pad under the canvas (default False; also the `keypad` trait): a
        button per action (simple and double rotations and their inverses, alpha, c0, the
        step, reset) for a mouse or a touch screen.  A click is one step; a button held
        down repeats exactly like a held key and stops on release or on leaving it.
    projection : bool -- the whole object projected beside its slice (`rot4d_widget.view.projection`)
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
    progress_bar : `rot4d_widget.view.progress.ViewBar` -- shown while the source is read (``follow``)
    """

    theta0 = t.Angle(DEFAULT_THETA0, help="step angle of every rotation key, radians in (0, pi]")
    alpha = t.Finite(0.0, help="double-rotation angle alpha (beta = theta0 - alpha), radians")
    c0 = t.Finite(0.0, help="level of the slicing hyperplane w = c0, in the source's w units (a field's data w)")
    orientation = traitlets.Any(read_only=True, help="(4, 4) rotation matrix, read-only")
    ball_radius = t.Positive(0.07, upper=10.0, help="ball radius, displayed units")
    bar_radius = t.Positive(0.028, upper=10.0, help="bar radius, displayed units")
    face_opacity = t.Fraction(colours.FACE_OPACITY, help="opacity of the faces, in [0, 1]")
    background = t.Colour(colours.BACKGROUND, help="background colour")
    show_balls = t.Flag(True)
    show_bars = t.Flag(True)
    show_faces = t.Flag(True)
    color_by = t.ColorBy("group", help='"group" or one colour for every face')
    keypad = traitlets.Bool(False, help="show the on-screen key pad (buttons for every action)")
    levels = t.Levels(None, allow_none=True,
                      help="iso levels of a field source (tuple of floats); None for sources without levels")
    inside = t.Choice(None, ("above", "below"), allow_none=True,
                      help='which side of a field\'s iso level its surface encloses; None for sources without one')
    caps = t.Flag(None, allow_none=True, help="a field's surface closed on the data box's faces (True) or open "
                                              "(False); None for sources without one")
    slices = t.Count(None, low=1, high=64, allow_none=True,
                     help="parallel slices shown; None for a single view until set (or n pressed)")
    spacing = t.Spacing(None, allow_none=True, help="distance between parallel slices, in the source's w units")
    arrangement = t.Choice(None, ARRANGEMENTS, allow_none=True, help="where the parallel slices are placed")
    cmap = t.Cmap(colours.LEVEL_COLORMAP, help="a field's colour map (a matplotlib colour map name)")
    clim = t.Clim(None, allow_none=True, help="a field's colour limits (lo, hi); None: the data's range")
    rendering = t.Rendering("surface", help="how a field's cut is drawn: surface, volume, mip or sections")
    sections = t.Sections(renderings.DEFAULT_SECTIONS, help="the section planes, fractions (fx, fy, fz) of the cut")
    projection = ProjectionFlag(False, help="the whole object projected, beside the slice (`view.projection`)")

    def __init__(
        self, source="5-cell", theta0: float = DEFAULT_THETA0, alpha: float | None = None, c0: float | None = None,
        *, keymap: Keymap = DEFAULT_KEYMAP, c0_step: float | None = None, width: int = 600, height: int = 500,
        ball_radius: float | None = None, bar_radius: float | None = None, face_opacity: float = colours.FACE_OPACITY,
        background=colours.BACKGROUND, show_balls: bool = True, show_bars: bool = True, show_faces: bool = True,
        color_by="group", group_colors=None, levels=None, slices=None, spacing=None, arrangement="oval",
        cmap: str = colours.LEVEL_COLORMAP, clim=None, rendering: str = "surface", sections=renderings.DEFAULT_SECTIONS,
        antialias: bool = False, keypad: bool = False, projection: bool = False, hold_delay: float = HOLD_DELAY,
        tick_rate: float = TICK_RATE, ack_timeout: float = ACK_TIMEOUT, _clock=None, _autotick: bool = True,
    ):
        # -- validate before any widget exists --------------------------------
        if not isinstance(keypad, bool):
            raise TypeError(f"Expected `keypad` to be a bool, got {type(keypad).__name__}")
        src, state, actions = _source_and_state(source, theta0, alpha, c0, keymap, c0_step, levels, slices,
                                                spacing, arrangement)
        repeater = KeyRepeater(hold_delay, tick_rate)
        ack_timeout = positive_seconds("ack_timeout", ack_timeout)
        if _clock is not None and not callable(_clock):
            raise TypeError(f"Expected `_clock` to be a callable returning seconds, got {type(_clock).__name__}")
        color_by, cmap, clim = t.check_color_by(color_by), colours.check_cmap(cmap), colours.check_clim(clim)
        rendering, sections, projection = (_check_rendering(src, rendering), renderings.check_sections(sections),
                                           renderings.check_projection(projection))
        scale = sizes.REFERENCE_RADIUS / float(src.size)
        coarse_ok = takes_coarse(src)
        if ball_radius is None:
            ball_radius = _default_ball_radius(src, scale, state)
        if bar_radius is None:
            # a field's bars only outline its data's box: thin
            bar_radius = sizes.default_bar_radius(ball_radius) * (0.35 if coarse_ok else 1.0)

        self.state = state
        self._repeater = repeater
        self._showing = showing = Showing(src, scale)
        self._error_area = errors = ErrorArea(repeater)
        pump = self._pump = UpdatePump(
            None, clock=_clock, ack_timeout=ack_timeout, autotick=_autotick, on_error=errors.report,
            name=f"rot4d-ticker-{id(self):x}", tick_rate=repeater.tick_rate,
        )  # its callbacks are the painter's and the keys', `connect`ed below
        # every applied action and parameter set, time-stamped (bounded; see `recording`)
        self._keeper = keeper = Keeper(self, showing, state, pump)
        self._recorder = keeper.recorder

        # -- widgets ------------------------------------------------------------
        self._build_children(dict(
            scale=scale, n_groups=int(src.n_groups), width=width, height=height, ball_radius=ball_radius,
            bar_radius=bar_radius, face_opacity=face_opacity, background=background, show_balls=show_balls,
            show_bars=show_bars, show_faces=show_faces, group_colors=group_colors, antialias=antialias,
        ))
        # -- the units, each handed what it uses; `connect` closes the loops between them ----------
        scene, companion = self.scene, self.companion
        custom = {a.name: (run, repeat) for a, run, repeat in actions.values()}
        self._painter = painter = Painter(self, showing, state, pump, scene, companion, self.readout, errors,
                                          coarse_ok)
        self._sync = sync = TraitSync(self, showing, state, pump, scene, keeper)
        self._stacking = stacking = Stacking(showing, state, pump, sync, keeper)
        self._shots = shots = Screenshots(pump, scene, companion, errors)
        self._renderings = field_view = Renderings(self, showing, scene, pump)
        self._keys = keys = KeyPath(self, showing, state, repeater, custom, pump, scene, companion, self.help_panel,
                                    errors)
        self._projection = projection_view = ProjectionView(self, self._place_projection, showing, state, scene,
                                                            companion, pump, keys.handle_event)
        self._keypad = KeyPad(self._canvas_box, state, scene, pump, keys, errors)
        keeper.connect(painter, keys, sync, scene)
        painter.connect(keys, shots, projection_view)
        stacking.connect(keys)
        shots.connect(painter, keys)
        projection_view.connect(painter)
        keys.connect(painter, sync, keeper, shots, field_view, stacking)  # the page's keys from here on
        pump.connect(painter.send, tick=keys.tick, deadline=keys.deadline)
        super().__init__(
            [self._canvas_box, self._side_box],
            layout=widgets.Layout(flex_flow="row wrap", align_items="flex-start"),
            **self.scene.display,
            color_by=color_by, cmap=cmap, clim=clim, rendering=rendering, sections=sections, projection=projection,
        )
        try:
            self._wire(keypad)
        except BaseException:
            self.close()  # a source failing here must not leave the widget models behind
            raise

    # ------------------------------------------------------------------ API
    @property
    def source(self):
        """The source shown (a stack around the one given once parallel slices are asked for).

        A polytope name gives a `PolytopeSource`; a source that inherits `SourceBase` (a `Field4D`,
        a `StackSource`, a user's subclass) is itself; any other object given is read through the
        `UserSource` that wraps it (``w.source.user_object`` is the object; its attributes read and
        set through the wrapper, ``w.source.thickness = 2`` then `refresh`)."""
        return self._showing.source

    @property
    def last_screenshot(self):
        """The PNG of the view the page sent last (`screenshot`, key p), or None."""
        return self._shots.last

    @last_screenshot.setter
    def last_screenshot(self, png) -> None:
        self._shots.last = png

    @property
    def polytope(self):
        """The `Polytope` shown, or None when the source is not a polytope."""
        return self.source.polytope

    @property
    def slice(self):
        """The source's slice of the current state (what the view shows, or is about to)."""
        with self._pump.lock:
            return self._painter.current_slice()

    stats = property(lambda self: self._pump.stats, doc="The pump's counters: updates, acks, acknowledged, timeouts.")

    @property
    def held_keys(self) -> tuple:
        """The keys (browser ``code``s) held now, in the order pressed."""
        return self._keys.held

    hold_delay = property(lambda self: self._repeater.hold_delay, doc="Seconds before a held key repeats.")
    tick_rate = property(lambda self: self._repeater.tick_rate, doc="Repeats per second while a key is held.")
    ack_timeout = property(lambda self: self._pump.ack_timeout, doc="Seconds to wait for a drawn acknowledgement.")

    @property
    def in_flight(self) -> bool:
        """True while an update awaits the page's "drawn" acknowledgement."""
        return self._pump.in_flight is not None

    @property
    def help_visible(self) -> bool:
        return self._keys.help_visible

    @help_visible.setter
    def help_visible(self, value: bool) -> None:
        self._keys.help_visible = value

    def press(self, key: str, shift: bool = False) -> bool:
        """Press ``key`` once from code (one step; no hold); False if unbound or no change.  Returns once
        the step is sent (readout and buffers show it), unless updates in flight hold it back."""
        found = self.state.keymap.resolve(key, shift)
        if found is None:
            return False
        action, inverted = found
        with self._pump.lock:
            self._check_open()
            if action.kind == "help":
                self.help_visible = not self.help_visible
                return True
            changed = self._keys.step(action, inverted)
            self._pump.flush()
        self._pump.wait_sent()  # sent by the ticker thread: readout and buffers show the step (unless held back)
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
        if path is not None and not isinstance(path, (str, os.PathLike)):
            raise TypeError(f"Expected `path` to be a str, a path-like or None, got {type(path).__name__}")
        if callback is not None and not callable(callback):
            raise TypeError(f"Expected `callback` to be callable or None, got {type(callback).__name__}")
        with self._pump.lock:
            self._check_open()
            return self._shots.ask(path, callback, warn=True)

    def refresh(self) -> None:
        """Redraw after changing `state` or the source directly; obeys the flow control.  The
        source's own settings (the source protocol's ``settings``) that changed since they were
        last recorded are recorded."""
        self._keeper.refresh()

    # ------------------------------------------------------- keeping what you see (`keeping.Keeper`)
    @property
    def recording(self):
        """What was applied since the widget was made (or `start_recording`): a
        `rot4d_widget.keep.recorder.Recording` of every step (keys, key pad, `press`, repeats) and
        every parameter set (sliders, traits, `refresh`), time-stamped.  Save it
        (``.save(path)``), replay it (`replay`) or render it (`render_animation`)."""
        return self._recorder.recording()

    def start_recording(self) -> None:
        """Forget what was recorded; record from the current state on."""
        with self._pump.lock:
            self._keeper.restart()

    def replay(self, recording) -> None:
        """Apply a `Recording` (or a path to a saved one) to this widget: its starting state,
        then every event, ending where the recording ended (to rounding; a source's own
        actions, e.g. a stack's n / b, are replayed on this widget's source).  Redraws once."""
        self._keeper.replay(recording)

    def render_animation(self, path, *, recording=None, fps: float = 10.0, per: str = "step", **options) -> int:
        """Draw `recording` (default: this widget's) without a browser into an animated GIF
        (Pillow) or MP4 (imageio-ffmpeg), by ``path``'s extension; one frame per step
        (``per="step"``) or per 1/fps s of recorded time (``per="time"``); the widget's look
        (`render` settings).  Returns the number of frames.  See
        `rot4d_widget.keep.animation.render_animation` for ``options`` (size, dpi, max_frames ...)."""
        return self._keeper.render_animation(path, recording=recording, fps=fps, per=per, **options)

    def render(self, path=None, *, size=None, dpi: float = 100, **options):
        """The view as a static matplotlib figure (no browser): the current state, source and
        display settings, the live view's camera, palette and scale; written to ``path`` (PNG,
        SVG or PDF by extension) if given.  ``size`` in pixels, default the canvas's.  Returns
        the `matplotlib.figure.Figure`."""
        return self._keeper.render(path, size=size, dpi=dpi, **options)

    def slice_mesh(self, **options):
        """What the view shows as one `trimesh.Trimesh`: every face of the slice (all levels of a
        field, all slices of a stack, placed as shown), in the source's own units, with each
        face's group (cell / level / slice) in ``mesh.face_attributes["group"]`` and the
        view's colours.  ``.export("slice.ply")`` writes OBJ, PLY, STL or GLB by extension.
        See `rot4d_widget.keep.meshes.slice_mesh` for ``options``."""
        return self._keeper.slice_mesh(**options)

    def save_state(self, path) -> dict:
        """Write the state (orientation, θ0, α, c0, c0 step, key bindings), what the source is
        and the widget's settings to the JSON file ``path`` (`rot4d_widget.keep.statefile.save_state`).
        A source that cannot be rebuilt from the file (an in-memory array) is described with a
        warning; `load_state` into a widget showing it still works.  Returns the dict written."""
        return self._keeper.save_state(path)

    def load_state(self, path) -> None:
        """Read a `save_state` file into this widget: its state (which `r` now resets to), key
        bindings and settings.  The file's source must be of this widget's kind
        (``ValueError`` otherwise; `from_state` builds a widget for the file's own source)."""
        self._keeper.load_state(path)

    @classmethod
    def from_state(cls, path, source=None, *, allow_code: bool = False, **kwargs) -> "Rot4DWidget":
        """A widget for a `save_state` file: its source rebuilt from the file (or ``source``,
        needed when the file says it cannot be rebuilt), its settings, its state.

        A file is data: a field made from a function is refused unless ``allow_code=True``
        (then the module the file names is imported) or the source is passed in."""
        loaded, arguments, late = Keeper.widget_arguments(cls, path, source, allow_code=allow_code, **kwargs)
        w = cls(loaded.source, **arguments)
        w._keeper.apply_loaded(loaded.state, late, defaults=False)  # the view settings the constructor lacks
        return w

    def release_keys(self, page_time=None) -> None:
        """Release every held key (what mouseleave and focus loss do); ``page_time``: the page's
        time of the event in seconds, if known (each key's steps are then corrected to it)."""
        self._keys.release_all(page_time)

    def close(self) -> None:
        """Stop the ticker thread, drop the listeners, close every child widget."""
        pump = self.__dict__.get("_pump")
        if pump is None:  # construction failed before any child existed
            return
        with pump.lock:
            if pump.closed:
                return
            pump.shut()
            self._repeater.clear()
        pump.close()
        try:
            self._unwire()
        finally:
            self._close_children()
            layout, style = getattr(self, "layout", None), getattr(self, "style", None)
            super().close()
            for w in (layout, style):
                if w is not None:
                    close_quietly(w)

    def __repr__(self) -> str:
        st = self.state
        return (
            f"Rot4DWidget({self.source!r}, theta0={st.theta0:.6g}, alpha={st.alpha:.6g}, c0={st.c0:.6g}"
            f"{', closed' if self._pump.closed else ''})"
        )

    # ------------------------------------------------------- building and wiring
    def _wire(self, keypad) -> None:
        """Connect the parts and send the initial picture (the last step of construction)."""
        self._sync.state_traits()
        self._sync.source_traits()
        self._keys.send_config()

        self.events.on_dom_event(self._handle_event)
        self.companion.on_drawn(self._handle_drawn)
        self.companion.on_focus_lost(self._keys.focus_lost)
        self.companion.on_clock(self._keys.heartbeat)
        self.companion.on_screenshot(self._shots.answer)
        self.companion.on_holds(self._painter.page_holds)
        self.companion.transfers.bar = self.progress_bar  # a field's copy on its way to the page: counted there
        self.scene.on_view_count(self._keys.view_count)
        self.scene.on_eye_moved(self._painter.eye_moved)
        self._sync.observe()
        self._renderings.observe()
        self.observe(self._stacking.on_stack_trait, names=list(STACK_TRAITS))
        self.observe(self._on_keypad, names="keypad")
        self.keypad = keypad
        self.observe(self._projection.changed, names="projection")
        self._projection.changed()

        # The initial picture is part of the models' state: not "in flight".
        self._pump.send_now(expect_ack=False)
        # A field is read in the background from now on (the whole of it into memory when it fits its
        # budget, else its coarse copy for held keys), counted on the widget's own bar above the
        # readout; its first picture above read only the chunks the cut touches.  Only with the
        # ticker running (a live widget): scripts and tests stay deterministic.
        if self._pump.autotick:
            self.progress_bar.follow(inner_source(self.source), on_done=self._painter.data_read)

    def _unwire(self) -> None:
        """Drop the listeners `_wire` attached."""
        events, companion, scene = (getattr(self, n, None) for n in ("events", "companion", "scene"))
        if events is not None:
            events.on_dom_event(self._handle_event, remove=True)
        if companion is not None:
            companion.on_drawn(self._handle_drawn, remove=True)
            companion.on_focus_lost(self._keys.focus_lost, remove=True)
            companion.on_clock(self._keys.heartbeat, remove=True)
            companion.on_screenshot(self._shots.answer, remove=True)
            companion.on_holds(self._painter.page_holds, remove=True)
        if scene is not None:
            scene.on_view_count(self._keys.view_count, remove=True)
            scene.on_eye_moved(self._painter.eye_moved, remove=True)

    def _close_children(self) -> None:
        """Close every child widget; never raises.  The Events first, so their document listeners go
        before the canvas does."""
        self._keypad.close()
        self._projection.close()
        bar = getattr(self, "progress_bar", None)
        if bar is not None:
            bar.close_widgets()
        for name in ("events", "companion", "scene", "readout", "help_panel", "errors", "_canvas_box", "_side_box"):
            x = getattr(self, name, None)
            if x is not None:
                close_quietly(x)

    def _build_children(self, options) -> None:
        """The scene, companion, readout, help, errors, the canvas's Event and the boxes; each widget
        made is closed again if a later one fails."""
        Scene, Companion = _scene_classes()

        Scene.check_display({k: v for k, v in options.items() if k in DISPLAY_TRAITS})

        built = []
        try:
            self.scene = Scene(capacity=estimate_capacity(self.source, name=title(self.source)), **options)
            built.append(self.scene)
            self.companion = Companion(self.scene)
            built.append(self.companion)
            self.readout = markup.html_widget()
            self.help_panel = markup.html_widget(
                markup.help_html(help_groups(self.state.keymap), self._repeater.hold_delay, self._repeater.tick_rate),
                layout=widgets.Layout(display="none"),
            )
            self.errors = self._error_area.output = widgets.Output()
            built += [self.readout, self.help_panel, self.errors]
            self.events = Event(
                source=self.scene.canvas,
                watched_events=list(_WATCHED_EVENTS),
                prevent_default_action=True,
                ignore_modifier_key_events=True,
            )
            built.append(self.events)
            self.progress_bar = _progress.ViewBar()  # the source's background read, while it runs
            built += self.progress_bar.widgets
            # the canvas keeps its size; the side panel wraps below it when narrow
            self._canvas_box = widgets.VBox([self.scene.canvas, self.companion], layout=widgets.Layout(flex="0 0 auto"))
            self._side_box = widgets.VBox(
                [self.progress_bar.box, self.readout, self.help_panel, self.errors],
                layout=widgets.Layout(flex="1 1 16em", min_width="16em", padding="0 0 0 1em"),
            )
            self._side_box.add_class("rot4d-side")
            self._side_box.add_class(f"{self.scene.canvas_class}-side")  # the page says here when it is ahead
            built += [self._canvas_box, self._side_box]
        except BaseException:
            for x in reversed(built):
                close_quietly(x)
            raise

    # --------------------------------------------------------------- traits
    @traitlets.validate("theta0")
    def _valid_theta0(self, proposal):
        value = proposal["value"]  # an angle in (0, pi] (`traits.Angle`)
        if not self._sync.syncing:  # alpha keeps its ratio: refused here, before the trait changes
            st = self.state
            check_alpha_beta(st.alpha * (value / st.theta0), value, f"theta0 = {value:.6g} (alpha keeps its ratio)")
        return value

    @traitlets.validate("alpha")
    def _valid_alpha(self, proposal):
        value = proposal["value"]  # finite (`traits.Finite`)
        if not self._sync.syncing:
            check_alpha_beta(value, self.state.theta0, f"alpha = {value:.6g}")
        return value

    def _place_projection(self, box, on: bool) -> None:
        """The projection's box beside the slice view (`ProjectionView`), or taken away."""
        kids = [c for c in self.children if c is not box]
        if on:
            kids.insert(1, box)
        if tuple(kids) != tuple(self.children):
            self.children = tuple(kids)

    def _on_keypad(self, change) -> None:
        self._keypad.show(change["new"])

    # ---------------------------------------------------- front-end handlers
    def _handle_event(self, event) -> None:
        """ipyevents callback (`keys.KeyPath.handle_event`): never raises."""
        self._keys.handle_event(event)

    def _handle_drawn(self, seq=None) -> None:
        """Companion: the page rendered a frame containing update ``seq`` (``scene.update_id``)."""
        try:
            self._pump.acknowledge(seq, draw_time=self.companion.last_draw_time)
        except Exception as exc:
            self._report_error(exc)

    def _check_open(self) -> None:
        self._pump.check_open()

    def _report_error(self, exc: BaseException) -> None:
        """Show an exception in the ``errors`` area (`errors.ErrorArea.report`); never raises."""
        self._error_area.report(exc)


# ------------------------------------------------------------------ helpers
def _check_rendering(source, rendering) -> str:
    """``rendering`` checked (`renderings.check_rendering`) and possible for ``source``: only a source that
    gives its cut on a grid (``sample``) has more than the surface."""
    rendering = renderings.check_rendering(rendering)
    if rendering != "surface" and not can_sample(source):
        raise ValueError(f"rendering={rendering!r} needs a field (a source with `sample`, the cut on a grid); "
                         f"{title(source)} has only rendering='surface'")
    return rendering


def _source_and_state(source, theta0, alpha, c0, keymap, c0_step, levels, slices, spacing, arrangement):
    """The source (levels set, wrapped in a stack for ``slices``), the `RotationState` and the
    source's own actions, validated before any widget exists."""
    src = as_source(source)
    if levels is not None:
        if src.levels is None:
            raise TypeError(f"`levels` applies to sources with iso levels (a Field4D), not {title(src)}")
        src.levels = levels
    if slices is not None:  # parallel slices (4-D tomography): a source that wraps the source
        src = make_stack(src, slices, spacing, arrangement)
    elif spacing is not None:
        raise TypeError("`spacing` applies to parallel slices: give `slices=N` too")
    if not isinstance(keymap, Keymap):
        raise TypeError(f"Expected `keymap` to be a rot4d_widget.Keymap, got {type(keymap).__name__}")
    actions = source_actions(src)
    if actions:
        keymap = keymap.extended({k: a for k, (a, _, _) in actions.items()})
    origin, per = w_frame(src)
    if c0_step is None:
        c0_step = float(src.size) * C0_STEP_FRACTION * per
    state = RotationState(theta0, alpha, origin if c0 is None else c0, keymap=keymap, c0_step=c0_step,
                          c0_limit=C0_LIMIT_SIZES * float(src.size) * per, c0_origin=origin)
    return src, state, actions


def _default_ball_radius(source, scale, state) -> float:
    """min(0.07, 0.1 x displayed edge): the polytope's edge, else the first slice's median segment
    (of its outline, `outline_of`: a field's box cut, nothing read)."""
    edge = source.edge_length
    if edge is None:
        data = checked_slice(source, state.matrix, state.c0, False, threading.RLock(), outline=True)
        seg = np.asarray(data.segments)
        if len(seg):
            p = np.asarray(data.points, dtype=np.float64)
            edge = float(np.median(np.linalg.norm(p[seg[:, 0]] - p[seg[:, 1]], axis=1)))
        if not edge:
            return sizes.default_ball_radius(0.3)
    return sizes.default_ball_radius(float(edge) * scale)
