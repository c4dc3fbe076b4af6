"""What the view shows, and when: the pump's ``send`` callback, the slice cache, the readout.

`Painter` turns the widget's state into pictures: it slices the source (or turns the rows
already shown when only x, y, z turned), hands the slice to the scene and keeps the readout
in step.  `ViewKey` says which state a picture shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core import colours
from ..sources.protocol import (
    BadSlice,
    as_slice,
    c0_text,
    check_slice,
    data_w_text,
    inner_source,
    known_range,
    outline_of,
    source_title,
)
from . import markup as ro
from .buffers import check_update_size
from .cuts import can_sample, cut_labels, grid_cut, rendering_rows
from .fieldview import field_config, view_message
from .pagefield import page_field
from .pagestate import state_message
from .volume_layer import volume_message

__all__ = ["ViewKey", "Painter", "READOUT_PERIOD", "checked_slice", "title"]

#: While keys repeat, the readout (an HTML relayout on the page) changes at most this often (s);
#: it is exact again as soon as no key is held.
READOUT_PERIOD = 0.25
#: While the page steps its keys, the kernel's state goes to it at most this often (s): the page
#: needs it to stay exact and to know the kernel answers, not every step.
STATE_PERIOD = 0.03


@dataclass(frozen=True, eq=False)
class ViewKey:
    """The state a picture shows: the rotation, the cut, the camera, the source's version, the
    colouring, whether the slice was the coarse one (held keys) and how a field is drawn
    ``(cmap, clim, rendering, sections)``."""

    matrix: np.ndarray
    c0: float
    eye: tuple
    version: int
    color_by: object
    coarse: bool
    scale: tuple = ()

    def same_cut(self, other: "ViewKey") -> bool:
        """The same hyperplane level, camera, source version and colours (the rotation aside)."""
        return (self.c0, self.eye, self.version, self.color_by, self.scale) == (
            other.c0, other.eye, other.version, other.color_by, other.scale)

    def same(self, other: "ViewKey") -> bool:
        """Everything equal, the rotation too (the same matrix object, or equal entries)."""
        return (self.same_cut(other) and self.coarse == other.coarse
                and (self.matrix is other.matrix or np.array_equal(self.matrix, other.matrix)))

    def turn_from(self, other: "ViewKey"):
        """The 3-D rotation (3, 3) taking ``other``'s rows to this key's, or None when it moves w."""
        t = np.asarray(self.matrix) @ np.asarray(other.matrix).T
        return t[:3, :3] if abs(t[3, 3] - 1.0) < 1e-12 else None


def title(source) -> str:
    return source_title(source)


def checked_slice(source, matrix, c0, coarse, lock, *, outline: bool = False):
    """``source.slice`` validated once (`rot4d_widget.sources.protocol.check_slice`): a bad slice (None,
    non-finite points, indices out of range, a group beyond ``n_groups``) raises a ValueError
    or TypeError naming the source and the member that is wrong, and is never drawn; a slice
    over the update cap raises `rot4d_widget.view.buffers.UpdateTooLarge`.
    ``outline``: the source's outline instead (`outline_of`: balls and bars, no data read)."""
    with lock:
        if outline:
            data = outline_of(source, matrix, c0)
        else:
            data = source.slice(matrix, c0, coarse=True) if coarse else source.slice(matrix, c0)
        n_groups = int(source.n_groups)
    try:
        check_slice(data, n_groups)
        data = as_slice(data)  # a user's slice object made a `SliceData`: read as one from here on
    except (TypeError, ValueError) as exc:
        raise BadSlice(f"{title(source)}.slice(matrix, c0={c0:.6g}) returned a bad slice: {exc}") from None
    check_update_size(data, name=title(source))
    return data


class Painter:
    """The widget's pictures: ``send`` (the pump's callback), the slice cache, the readout.

    ``shown`` is the `ViewKey` the scene shows; ``rows_key`` the one its rows were sliced for
    (the view may be turned from it); ``rows_data`` the slice those rows show.
    """

    def __init__(self, traits, showing, state, pump, scene, companion, readout, errors, coarse_ok: bool):
        self.traits = traits  # the widget's traits: how a field is coloured and drawn
        self.showing, self.state, self.pump, self.errors = showing, state, pump, errors
        self.scene, self.companion, self.readout = scene, companion, readout
        self.keys = self.shots = self.projection_view = None  # `connect`
        #: sources whose slice(matrix, c0, coarse=...) has a cheaper coarse version (fields):
        #: coarse while keys repeat, full at rest; their rows are turned, not re-sliced, at rest
        self.coarse_ok = coarse_ok
        self.cache = None  # (matrix, c0, version, coarse, data)
        self.grid_cache = None  # (matrix, c0, version, coarse, GridCut): the ray-cast renderings' cut
        #: the colour limits of the ray-cast picture shown (the cut's 1st-99th percentile when
        #: ``clim`` is None), for the colour bar
        self.cast_clim = None
        self.labelled = False  # the scene shows labels (`cut_labels`)
        self.shown = None
        self.rows_key = None
        self.rows_data = None
        self.note = None  # one line for the readout: what a screenshot did
        self.readout_at = -math.inf  # when the readout was last computed
        self.readout_stale = False  # the readout lags the state (keys were repeating)
        self.state_at = -math.inf  # when the kernel's state was last sent to the page

    def connect(self, keys, shots, projection_view) -> None:
        """The units a picture tells: the keys (held, the page's steps, the key table), the
        screenshots owed, the projection's part of each update."""
        self.keys, self.shots, self.projection_view = keys, shots, projection_view

    # -- slices -----------------------------------------------------------------------------
    def current_slice(self, coarse: bool = False):
        st = self.state
        m, c0, version = st.matrix, st.c0, self.showing.version
        coarse = bool(coarse and self.coarse_ok)
        cached = self.cached_slice(m, c0, version, coarse)
        if cached is not None:
            return cached
        data = checked_slice(self.showing.source, m, c0, coarse, self.showing.lock)
        self.cache = (m, c0, version, coarse, data)
        return data

    def cached_slice(self, m, c0, version, coarse):
        cache = self.cache
        if cache is not None and cache[0] is m and cache[1] == c0 and cache[2] == version and cache[3] == coarse:
            return cache[4]
        return None

    @property
    def settled(self) -> bool:
        """True when the scene shows the rows of the exact (not coarse, not turned) state."""
        return self.shown is None or (self.shown is self.rows_key and not self.shown.coarse)

    def send(self):
        """Pump callback: show the latest state; the update's id, or None if nothing was sent.

        While keys are held, a change that only turns the slice in 3-D (the
        rotation since the rows shown leaves w alone, nothing else changed) is
        sent as a turn, a few bytes, without slicing; at rest the rows are
        re-sent in the new frame (the faces' order is exact again).
        """
        st, scene = self.state, self.scene
        held = bool(self.keys.held)
        single = None if self.traits.color_by == "group" else colours.as_rgb(self.traits.color_by, "color_by")
        cut = self.companion.page_cut
        cut.sync(self.showing.source, self.group_colors(), self.showing.scale, single)
        self.sync_field()
        if held and (cut.page_draws or self.companion.page_field.page_draws):  # the page draws them: no work here
            self.send_state("pending")
            self.readout_stale = True  # at rest the picture and the readout follow (`KeyPath.settle`)
            return None
        coarse = held and self.coarse_ok
        shown, rows = self.shown, self.rows_key
        cast = self.traits.rendering != "surface" and can_sample(self.showing.source)  # ray-cast from the cut on grids
        t = self.traits
        key = ViewKey(st.matrix, st.c0, scene.eye, self.showing.version, t.color_by, coarse,
                      (t.cmap, t.clim, t.rendering if cast else "surface", t.sections if cast else None))
        sent = None
        same_cut = rows is not None and key.same_cut(rows)
        # a stack turns each slice about its own centre: never turned as a whole
        turn = key.turn_from(rows) if same_cut and inner_source(self.showing.source) is self.showing.source else None
        if shown is not None and key.same(shown) and (shown is rows or held) and not scene.unsent:
            pass  # the page shows this state (turned rows only while keys are held)
        elif held and turn is not None and (key.coarse or not rows.coarse):
            if scene.turn(turn, **self.projection(key)):
                sent = scene.update_id
            self.shown = key
        elif cast:
            m, c0, version, coarse_ = key.matrix, key.c0, key.version, bool(coarse and self.coarse_ok)
            cached = self.grid_cache
            if cached is not None and cached[0] is m and cached[1:4] == (c0, version, coarse_):
                cut = cached[4]
            else:
                source, lock, scale = self.showing.source, self.showing.lock, self.showing.scale
                cut = yield (lambda: grid_cut(source, m, c0, coarse_, lock, scale))  # the slow part, unlocked
                if self.pump.closed:
                    return None
                if not self.showing.still(source, version):
                    self.pump.mark_dirty()
                    return None
                self.grid_cache = (m, c0, version, coarse_, cut)
            clim = self.traits.clim if self.traits.clim is not None else colours.default_clim(cut.finite_values)
            volume = volume_message(cut.parts, t.rendering, t.cmap, clim, t.sections, held=coarse_)
            labels = cut_labels(self.showing.source, m, c0, cut.data)
            if scene.show(cut.data, single_rgb=single, volume=volume, labels=labels, **self.projection(key)):
                self.labelled = bool(labels)
                sent = scene.update_id
            self.cast_clim = clim
            self.rows_data = cut.data
            self.shown = self.rows_key = key
        else:
            rows_turn = key.turn_from(rows) if same_cut else None
            if (self.coarse_ok and rows_turn is not None and not rows.coarse and not coarse
                    and self.rows_data is not None):
                # the same cut turned in 3-D: turn the full-resolution slice shown, no resampling
                data = self.rows_data.turned(rows_turn)
            else:
                m, c0, version, coarse_ = key.matrix, key.c0, key.version, bool(coarse and self.coarse_ok)
                data = self.cached_slice(m, c0, version, coarse_)
                if data is None:
                    source, lock = self.showing.source, self.showing.lock
                    # the slow part: on the ticker thread it runs with the pump's lock free, so
                    # keys go on changing the state meanwhile (the next picture takes the latest)
                    data = yield (lambda: checked_slice(source, m, c0, coarse_, lock))
                    if self.pump.closed:
                        return None
                    if not self.showing.still(source, version):
                        self.pump.mark_dirty()  # the source changed meanwhile: never show the old one
                        return None
                    self.cache = (m, c0, version, coarse_, data)
            colors = self.group_colors()
            extra = {} if colors is None else {"group_rgb": colors}
            labels = cut_labels(self.showing.source, key.matrix, key.c0, data)
            if labels or self.labelled:  # a source with labels (a field), or to take them away
                extra["labels"] = labels
            if scene.show(data, single_rgb=single, **extra, **self.projection(key)):
                sent = scene.update_id
                self.labelled = bool(labels)
            self.rows_data = data
            self.shown = self.rows_key = key
        # the state and its id, and which picture shows it: this one, if it is of the state now (keys
        # may have changed it while the picture was made), else one is owed
        now_shown = key.matrix is self.state.matrix and key.c0 == self.state.c0
        self.sync_field()  # the colour limits this picture used (the page's while it draws)
        self.send_state(picture=(sent if now_shown else "pending") if sent is not None else
                        (None if now_shown else "pending"))
        self.shots.send_owed()  # screenshots asked meanwhile: of this picture
        now = self.pump.clock()
        self.errors.clear_update_errors()  # a good picture: the widget has recovered
        if not self.keys.held or now - self.readout_at >= READOUT_PERIOD:
            ro.show(self.readout, self.readout_html())
            self.readout_at, self.readout_stale = now, False
        else:
            self.readout_stale = True
        return sent

    def send_state(self, picture=None, *, throttle: bool = False) -> None:
        """The kernel's state and its id to the page (`Companion.kernel_state`), when they changed;
        ``picture``: the update id of the scene's picture that shows it, None when the picture shown
        does, or "pending" when one is owed (the pump sends it).  ``throttle`` (a step of the
        page's keys, many a second): not sooner than `STATE_PERIOD` after the last (the next goes)."""
        now = self.pump.clock()
        if throttle and now - self.state_at < STATE_PERIOD:
            return
        self.keys.page.sync_external()  # a change from the kernel since the last step: a new epoch
        epoch, upto = self.keys.page.state_id
        msg = {"epoch": epoch, "upto": upto if math.isfinite(upto) else None, "state": self._state_message(),
               "keys": self.keys.page.held_since(),
               "picture": picture}
        old = self.companion.kernel_state
        if picture is None and old.get("picture") != "pending" and old.get("state") == msg["state"] \
                and old.get("epoch") == epoch and old.get("upto") == msg["upto"] and old.get("keys") == msg["keys"]:
            return  # unchanged: nothing to send (the picture named before still shows it)
        self.companion.kernel_state = msg
        self.state_at = now

    def send_id(self, *, throttle: bool = False) -> None:
        """The kernel's state id moved on with no change of state (it heard the page's clock
        further: a heartbeat, a release without a step): the same state under the new id, the
        picture named as before -- else the page would rest on the older id until the next change."""
        old = self.companion.kernel_state
        epoch, upto = self.keys.page.state_id
        if not old or (old.get("epoch"), old.get("upto")) == (epoch, upto if math.isfinite(upto) else None):
            return  # none sent yet, or the id it names is the kernel's (the common case: no work)
        if old.get("state") != self._state_message():
            return  # the state changed meanwhile (from the kernel): the pump sends it with its picture
        self.send_state(old.get("picture"), throttle=throttle)

    def _state_message(self) -> dict:
        return state_message(self.state, view_message(self.showing.source, self.traits.rendering,
                                                      self.traits.sections))

    def sync_field(self) -> None:
        """Offer the page the field's copy once it is in memory (`pagefield.PageField`) and say how
        it draws it (`fieldview.field_config`, sent when it changed)."""
        pf = self.companion.page_field
        pf.sync(self.showing.source)
        self.keys.send_config()  # a field's levels are predicted once its range is known without a read
        field = page_field(self.showing.source)
        if field is None or not pf.offered:
            return
        t = self.traits
        cfg = field_config(self.showing.source, self.showing.scale, field, cmap=t.cmap, clim=t.clim,
                           color_by=t.color_by, cast_clim=self.cast_clim, default_clim_=pf.clim,
                           texture_side=pf.texture_side, painted=self.colours())
        if cfg != self.companion.field_config:
            self.companion.field_config = cfg

    def projection(self, key: ViewKey) -> dict:
        """The projection view's part of the update showing ``key`` (`ProjectionView.message`), as the
        scene's ``projection`` keyword ({} while the projection is off): both views from one message."""
        message = self.projection_view.message(key.matrix, key.c0, key.version)
        return {} if message is None else {"projection": message}

    def data_read(self) -> None:
        """The source's background read is over (`ViewBar.follow`): draw again from the data now in
        memory, the readout with what the read found (a field's blocks of NaN: its "missing" row)."""
        try:
            with self.pump.lock:
                if self.pump.closed:
                    return
                self.showing.changed()  # the same source, read: slice it again
                self.pump.mark_dirty()
                self.pump.flush()
        except Exception as exc:
            self.errors.report(exc)

    def eye_moved(self, eye) -> None:
        """Scene: the camera moved (a mouse orbit ended): send the faces in the order for the new eye."""
        try:
            with self.pump.lock:
                if not self.pump.closed:
                    self.pump.mark_dirty()
                    self.pump.flush()
        except Exception as exc:
            self.errors.report(exc)

    def page_holds(self, name) -> None:
        """Companion: the page holds a one-time transfer: the readout says who draws while turning."""
        try:
            with self.pump.lock:
                if not self.pump.closed and name in ("field", "field_box"):
                    ro.show(self.readout, self.readout_html())
        except Exception as exc:
            self.errors.report(exc)

    def turning_text(self):
        """Who draws a field's pictures while keys are held (the readout's "turning" row), or None
        for a source that is not a field."""
        if not can_sample(self.showing.source):
            return None
        pf = self.companion.page_field
        if page_field(self.showing.source) is None:
            return "the kernel draws every picture (the page holds no copy of a function or of unevenly spaced data)"
        if pf.page_draws:
            shape = " \u00d7 ".join(str(n) for n in pf.shape)
            what = "the data" if pf.which == "data" else "the coarse copy"
            return f"the page draws while keys are held, from its copy of {what} ({shape}); the kernel at rest"
        sending = self.companion.transfers.sending("field")
        if sending is not None:
            return (f"the kernel draws while keys are held: the page's copy is on its way "
                    f"({sending[0]}/{sending[1]} parts)")
        if pf.offered:
            return ("the kernel draws while keys are held until the page has its copy (a page without WebGL2 "
                    "never takes one)")
        return "the kernel draws while keys are held until the page has its copy (after the background read)"

    # -- the readout ------------------------------------------------------------------------
    def set_note(self, text: str) -> None:
        self.note = text
        ro.show(self.readout, self.readout_html())

    def readout_html(self) -> ro.Markup:
        st, source = self.state, self.showing.source
        # a turned view shows the rows' slice turned in 3-D: same census and volume, no new slice
        data = self.rows_data if self.rows_data is not None else self.current_slice()
        label, count = self.keys.last.label, self.keys.last.count
        if label is None:
            last = "\u2014"
        else:
            last = label + (f" \u00d7{count}" if count > 1 else "")
        lo, hi = source.w_range(st.matrix)
        rows = [
            ("\u03b80", ro.angle_text(st.theta0)),
            ("\u03b1", ro.angle_text(st.alpha)),
            ("\u03b2", ro.angle_text(st.beta)),
            ("c0", ro.gauge_html(st.c0, lo, hi, inner_source(source).w_units,
                                 text=c0_text(inner_source(source), st.c0))),
            ("last", last),
        ]
        rows += [(k, str(v)) for k, v in data.readout]
        cast = self.cast_shown
        single = inner_source(source) is source
        if cast and single and self.labelled:  # what the ray-cast picture shows, and where its planes are
            cut = self.grid_cache[4] if self.grid_cache is not None else None
            if cut is not None and len(cut.grids) == 1:
                rows += rendering_rows(source, self.shown.matrix, self.shown.c0, self.traits.rendering,
                                       self.traits.sections, cut.grids[0])
        colors, labels = self.colours()
        if labels is not None and self.traits.color_by == "group" and not cast:  # the legend: what each colour is
            rows.append(("colours", ro.legend_html(labels, colors)))  # (a ray-cast picture: the bar says)
        bar = self.colourbar(colors if labels is not None and single else None)
        if bar:
            rows.append(("colour", bar))
        volume = data.volume
        if volume is not None and math.isfinite(float(volume)):
            rows.append(("volume", volume_text(source, float(volume), st.matrix)))
        elif cast and single and inner_source(source).levels:
            rows.append(("volume", "\u2014 (inside the level: the surface rendering's)"))
        turning = self.turning_text()
        if turning is not None:
            rows.append(("turning", turning))
        if self.note:
            rows.append(("picture", self.note))
        views = self.projection_view.readout_row()  # which view is which, with the projection shown
        if views is not None:
            rows.insert(0, views)
        return ro.readout_html(title(source), rows, gizmo=ro.gizmo_svg(st.matrix))

    @property
    def cast_shown(self) -> bool:
        """True while the scene shows a ray-cast picture (volume, mip, sections), not surfaces."""
        return self.shown is not None and self.shown.scale[2:3] not in ((), ("surface",))

    def colourbar(self, level_rgb=None) -> ro.Markup | str:
        """The colour bar of a field's values (`markup.colourbar_html`): ``cmap`` over ``clim`` (or
        the data's range), its name (xarray's ``long_name`` when the field keeps it) and units, a
        mark per iso level in its surface's colour (``level_rgb``; black when the surfaces are
        coloured otherwise: a stack by w, one colour).  A ray-cast picture's bar spans the limits
        its colours used (``clim``, or the cut's 1st-99th percentile) and marks no level.  "" for
        a source without levels."""
        inner = inner_source(self.showing.source)
        levels = inner.levels
        if not levels:
            return ""
        cast = self.cast_shown
        if cast and self.cast_clim is not None:  # a ray-cast picture: the limits its colours used
            lo, hi = self.cast_clim
        else:
            clim = self.traits.clim
            lo, hi = clim if clim is not None else inner.data_range or (min(levels), max(levels))
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            return f"no colour scale (the data's range is {lo:.4g} \u2026 {hi:.4g})"
        if level_rgb is None or self.traits.color_by != "group":
            level_rgb = [(0.0, 0.0, 0.0)] * len(levels)
        label = inner.long_name or inner.name or "value"
        marks = [] if cast else [(float(v), colours.hex_color(c)) for v, c in zip(levels, level_rgb)]
        cmap = self.traits.cmap
        return ro.colourbar_html(colours.cmap_stops(cmap), lo, hi, str(label), inner.units,
                                 marks, cmap=cmap)

    def group_colors(self):
        """The colour of every group of the source as it is now (`colours`)."""
        return self.colours()[0]

    def colours(self):
        """``(rgb (G, 3), labels or None)``: a stack's colours by w, else a field's by level (also
        inside a stack of one slice), else the scene's palette sized to the source's groups
        now (labels None: cells need no legend).  Follows the source when it changes."""
        src = self.showing.source
        inner = inner_source(src)
        if inner is not src:  # parallel slices: coloured by their w (`group_colors`, `cuts_at`)
            rgb = src.group_colors()
            if rgb is not None:
                return rgb, [data_w_text(inner, cut) for cut in src.cuts_at(self.state.c0)]
        rgb = level_colors(inner, self.traits.cmap, self.traits.clim)
        if rgb is not None:
            return rgb, [f"{lv:.4g}" for lv in inner.levels]
        return self.scene.palette(int(src.n_groups)), None


def level_colors(source, cmap: str = colours.LEVEL_COLORMAP, clim=None):
    """Colours of a source's iso levels along the colour map ``cmap``, or None: spread over it by
    rank (``clim`` None: the data's range as known without a full read -- a chunked store's first
    cut until its background read is done -- today's look), else each at its value in ``clim``."""
    levels = source.levels
    if not levels:
        return None
    if clim is not None:
        return colours.level_colors(levels, clim[0], clim[1], cmap, by_value=True)
    lo, hi = known_range(source, (min(levels), max(levels)))
    return colours.level_colors(levels, lo, hi, cmap)


def volume_text(source, volume: float, matrix) -> str:
    """The slice's 3-volume in the source's own units (a field's space units cubed when it names
    them, ``space_units``); a field turned so that w is mixed in counts w at ``w_per_unit`` data
    w per unit of space, and says so."""
    inner = inner_source(source)
    unit = inner.space_units
    text = ro.number_text(volume) + (f" {unit}³" if unit else "")
    wpu = inner.w_per_unit
    if wpu is not None and abs(abs(float(np.asarray(matrix)[3, 3])) - 1.0) > 1e-12:
        wu = inner.w_units
        text += (f" (w counted at {ro.number_text(wpu)}{' ' + wu if wu else ''} per "
                 f"{unit if unit else 'unit of space'})")
    return text
