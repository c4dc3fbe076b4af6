"""Recorded key sequences: the events, a `Recording` and the `Recorder` that makes one.

A `Recorder` is the widget's hook: told every action the widget applies, every parameter set from
outside the keys, every setting of the source and every view setting, with a time stamp, it keeps
at most ``max_events`` (older ones fold into the starting state, so a recording always replays
to the live state).  ``recorder.recording()`` is an immutable `Recording`: a starting state, the
source and view settings it starts from and the events (`Step`, `Setting`, `SourceSetting`,
`ViewSetting`), saved and loaded as JSON.  A recording is data: loading one imports nothing and
runs nothing it names.  Replaying applies the same floating-point operations in the same order,
so it ends on the recorded state bit for bit.  The animations are `rot4d_widget.keep.animation`'s.
"""

from __future__ import annotations

import collections
import dataclasses
import json
import math
import os
import threading
import time
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Mapping

import numpy as np

from ..core import colours, renderings
from ..core.keymap import Action
from ..core.rotation import as_rotation_matrix
from ..core.state import STATE_FORMAT, RotationState, action_from_data, action_to_data, spacing_factor
from ..sources.arrangements import ARRANGEMENTS
from ..sources.protocol import (
    apply_setting,
    as_source,
    class_name,
    inner_source,
    note_matrix,
    settings_of,
    source_title,
    w_frame,
)
from ..sources.tomography import StackSource
from .jsonfile import read_json
from .rebuild import jsonable

RECORDING_FORMAT = "rot4d_widget recording"
#: Version 2 adds `SourceSetting` events, version 3 `ViewSetting` events and ``initial_view``; a
#: recording is written in the lowest version that holds it (so that an older rot4d_widget still
#: reads what it can).
RECORDING_VERSION = 3
#: Default bound of a `Recorder`: 100 000 events is about 55 minutes of a key held at 30 Hz
#: (some 10 MB of JSON).
MAX_EVENTS = 100_000
#: What `Recorder.record_set` accepts: the state's settable parameters.
SETTABLE = ("theta0", "alpha", "c0", "c0_step", "matrix")
#: The built-in source settings (the widget's traits), whose values `Recorder.record_source` checks;
#: it also takes a source's own settings (any name in its protocol ``settings``, a JSON value).
SOURCE_SETTINGS = ("levels", "inside", "caps", "slices", "spacing", "arrangement")
#: The view settings `Recorder.record_view` takes (the widget's traits): how a field's cut is drawn,
#: its colour scale and where its sections lie -- they change the picture, not the state or source.
VIEW_SETTINGS = ("rendering", "cmap", "clim", "sections", "projection")
#: Each view setting's default (the widget's and `rot4d_widget.keep.pictures.state_picture.render_state`'s), as JSON.
VIEW_DEFAULTS = {"rendering": renderings.RENDERINGS[0], "cmap": colours.LEVEL_COLORMAP, "clim": None,
                 "sections": list(renderings.DEFAULT_SECTIONS)}
#: The settings of a field (a stack's inner source).
_FIELD_SETTINGS = ("levels", "inside", "caps")
#: The settings that need parallel slices (a `StackSource`).
_STACK_SETTINGS = ("slices", "spacing", "arrangement")


# ============================================================================ events
@dataclass(frozen=True)
class Step:
    """One applied action: ``t`` seconds after the recording started, the ``key`` pressed (None for
    a step not from a key), ``shift``, the `Action` and whether it was ``inverted``."""

    t: float
    key: str | None
    shift: bool
    action: Action
    inverted: bool

    @property
    def label(self) -> str:
        """``"R_xw"``, ``"R_xz,yw⁻¹"``, ``"c0+"`` ... (`Action.label`)."""
        return self.action.label(self.inverted)

    def to_dict(self) -> dict:
        return {"t": self.t, "key": self.key, "shift": self.shift, "action": action_to_data(self.action),
                "inverted": self.inverted, "label": self.label}


@dataclass(frozen=True)
class _NamedValue:
    """A value set by name at time ``t``; saved as ``{"t", <_KEY>: name, "value"}``."""

    t: float
    name: str
    value: object
    _KEY = "set"

    @property
    def label(self) -> str:
        return f"{self.name} set"

    def to_dict(self) -> dict:
        return {"t": self.t, self._KEY: self.name, "value": self.value}


@dataclass(frozen=True)
class Setting(_NamedValue):
    """A parameter set from outside the keys (a slider, code): ``name`` in `SETTABLE` and its
    ``value`` (a float, or a 4 x 4 list for ``"matrix"``)."""


@dataclass(frozen=True)
class SourceSetting(_NamedValue):
    """A setting of the source (the widget's traits): ``name`` in `SOURCE_SETTINGS` and its
    ``value`` -- ``levels`` a list of floats (a field's iso levels; a stack's inner source's),
    ``inside`` ``"above"`` or ``"below"`` and ``caps`` a bool (a field's, likewise),
    ``slices`` an int >= 1, ``spacing`` a number > 0 or None (the default), ``arrangement``
    ``"oval"``, ``"grid"`` or ``"stack"``; or a source's own setting (a name in its protocol
    ``settings``, a JSON value, set again with its ``apply_setting``).  Not a `Setting` (the
    state's): a sibling."""

    _KEY = "source"


@dataclass(frozen=True)
class ViewSetting(_NamedValue):
    """A view setting (the widget's traits): ``name`` in `VIEW_SETTINGS` and its ``value`` as JSON
    -- ``rendering`` one of `renderings.RENDERINGS`, ``cmap`` a matplotlib colour map name, ``clim``
    [lo, hi] or None (the data's range), ``sections`` [fx, fy, fz] in [0, 1].  It changes how
    the cut is drawn, not the state or the source."""

    _KEY = "view"


def check_view_setting(name, value):
    """``value`` as a `ViewSetting` holds it (JSON: a tuple as a list), checked by the core's checks
    (`rot4d_widget.core.renderings`, `rot4d_widget.core.colours`):
    a ValueError (or a TypeError for a value of the wrong type) naming what is allowed."""
    if name not in VIEW_SETTINGS:
        raise ValueError(f"Expected a view setting among {', '.join(map(repr, VIEW_SETTINGS))}, got {name!r}")
    check = {"rendering": renderings.check_rendering, "cmap": colours.check_cmap, "clim": colours.check_clim,
             "sections": renderings.check_sections, "projection": renderings.check_projection}[name]
    value = check(value, name)
    return list(value) if isinstance(value, tuple) else value


def _check_view_settings(settings) -> dict:
    """A ``{name: value}`` of view settings, checked, in `VIEW_SETTINGS` order."""
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise ValueError(f"Expected the view settings as a dict {{name: value}}, got {settings!r}")
    unknown = [n for n in settings if n not in VIEW_SETTINGS]
    if unknown:
        raise ValueError(f"Expected view settings among {', '.join(map(repr, VIEW_SETTINGS))}, got {unknown[0]!r}")
    return {name: check_view_setting(name, settings[name]) for name in VIEW_SETTINGS if name in settings}


def _time(t) -> float:
    if isinstance(t, bool) or not isinstance(t, Real) or not math.isfinite(t) or t < 0:
        raise ValueError(f"Expected a time stamp >= 0 (seconds), got {t!r}")
    return float(t)


def _check_setting(name, value):
    if name not in SETTABLE:
        raise ValueError(f"Expected a setting among {', '.join(map(repr, SETTABLE))}, got {name!r}")
    if name == "matrix":
        return as_rotation_matrix(value).tolist()
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
        raise ValueError(f"Expected {name!r} to be set to a finite number, got {value!r}")
    return float(value)


def _check_setting_name(name) -> None:
    if name not in SOURCE_SETTINGS and not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"Expected a source setting among {', '.join(map(repr, SOURCE_SETTINGS))} or a "
                         f"source's own setting (a name in its `settings`, a Python identifier), got {name!r}")


def _check_source_setting(name, value):
    """``value`` as a `SourceSetting` holds it (JSON-able); ValueError naming what is allowed.

    The built-in settings' values are checked here; a source's own setting (any other name, as
    its protocol ``settings`` has it) only needs a JSON value: the source checks it when the
    recording is replayed on it (its ``apply_setting``)."""
    _check_setting_name(name)
    if name not in SOURCE_SETTINGS:
        try:
            return jsonable(value, f"the source setting {name!r}")
        except TypeError as exc:
            raise ValueError(f"Expected a source setting's value to be JSON (numbers, strings, lists, dicts): "
                             f"{exc}") from None
    if name == "levels":
        values = [value] if isinstance(value, Real) else value
        ok = isinstance(values, (list, tuple, np.ndarray)) and len(values) > 0 and all(
            isinstance(v, Real) and not isinstance(v, bool) and math.isfinite(v) for v in values)
        if not ok:
            raise ValueError(f"Expected 'levels' to be set to a finite number or a non-empty sequence of them, "
                             f"got {value!r}")
        return [float(v) for v in values]
    if name == "inside":
        if value not in ("above", "below"):
            raise ValueError(f"Expected 'inside' to be set to 'above' or 'below', got {value!r}")
        return str(value)
    if name == "caps":
        if not isinstance(value, (bool, np.bool_)):
            raise ValueError(f"Expected 'caps' to be set to True or False, got {value!r}")
        return bool(value)
    if name == "slices":
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Integral) or value < 1:
            raise ValueError(f"Expected 'slices' to be set to an int >= 1, got {value!r}")
        return int(value)
    if name == "spacing":
        if value is None:
            return None
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Real) or not (
                math.isfinite(value) and value > 0):
            raise ValueError("Expected 'spacing' to be set to a finite number > 0 or None (the default), "
                             f"got {value!r}")
        return float(value)

    if value not in ARRANGEMENTS:
        raise ValueError(f"Expected 'arrangement' to be set to one of {', '.join(map(repr, ARRANGEMENTS))}, "
                         f"got {value!r}")
    return str(value)


def _check_source_settings(settings) -> dict:
    """A ``{name: value}`` of source settings, checked (`_check_source_setting`): the built-in ones in
    `SOURCE_SETTINGS` order, then a source's own in the order given."""
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise ValueError(f"Expected the source settings as a dict {{name: value}}, got {settings!r}")
    for name in settings:
        _check_setting_name(name)
    order = [n for n in SOURCE_SETTINGS if n in settings] + [n for n in settings if n not in SOURCE_SETTINGS]
    return {name: _check_source_setting(name, settings[name]) for name in order}


def _event_from_dict(d):
    if not isinstance(d, Mapping) or "t" not in d:
        raise ValueError(f"Expected a recorded event with a time 't', got {d!r}")
    t = _time(d["t"])
    if "set" in d:
        return Setting(t, d["set"], _check_setting(d["set"], d.get("value")))
    if "source" in d:
        return SourceSetting(t, d["source"], _check_source_setting(d["source"], d.get("value")))
    if "view" in d:
        try:
            return ViewSetting(t, d["view"], check_view_setting(d["view"], d.get("value")))
        except TypeError as exc:  # a file's bad value: the file is wrong
            raise ValueError(str(exc)) from None
    if "action" not in d:
        raise ValueError("Expected a recorded event with an 'action', a 'set', a 'source' or a 'view', "
                         f"got {dict(d)!r}")
    key = d.get("key")
    if key is not None and not isinstance(key, str):
        raise ValueError(f"Expected an event's 'key' to be a string or null, got {key!r}")
    shift, inverted = d.get("shift", False), d.get("inverted", False)
    if not isinstance(shift, bool) or not isinstance(inverted, bool):
        raise ValueError(f"Expected 'shift' and 'inverted' to be true or false in {dict(d)!r}")
    return Step(t, key, shift, action_from_data(d["action"]), inverted)


# ============================================================================ applying
def _source_action(source, name: str):
    actions = source.actions or {}
    for sa in actions.values():
        if getattr(sa, "name", None) == name:
            return sa
    return None


def _is_stack(source) -> bool:
    """A source made around another (the protocol's ``wraps``): parallel slices."""
    return source.wraps is not None


def _set_on_source(source, name: str, value) -> None:
    """Set a source setting on ``source`` in place, by the protocol (`apply_setting`: a stack passes
    its inner source's on).  ValueError if ``source`` has no such setting: a field's on another
    kind, parallel slices' on a single view (say how to replay then), or any other name it lacks."""
    if name not in settings_of(source):
        if name in _FIELD_SETTINGS:
            raise ValueError(f"A recorded {name!r} applies to a source that has it (a field), not "
                             f"{class_name(inner_source(source))}")
        if name in _STACK_SETTINGS and not _is_stack(source):
            raise ValueError(f"A recorded {name!r} applies to parallel slices, and {class_name(source)} is a "
                             "single view: replay with set_source= (Rot4DWidget.replay turns its view into a "
                             "stack), or on a StackSource")
    apply_setting(source, name, value)


def with_source_setting(source, name: str, value):
    """``source`` with a source setting applied: in place, or (``slices`` of a single view) a new
    `StackSource` around it, as the widget does."""
    if name == "slices" and not _is_stack(source) and name not in settings_of(source):
        return StackSource(source, slices=value)
    _set_on_source(source, name, value)
    return source


def apply_event(state: RotationState, event, source=None, set_source=None, set_view=None) -> bool:
    """Apply one event to ``state`` (a source's own action and a source setting to ``source``, or
    a source setting through ``set_source(name, value)``; a view setting through
    ``set_view(name, value)``); True if applied."""
    if isinstance(event, ViewSetting):
        if set_view is None:
            return False
        set_view(event.name, event.value)
        return True
    if isinstance(event, SourceSetting):
        if set_source is not None:
            set_source(event.name, event.value)
            return True
        if source is None:
            return False
        source = as_source(source)
        note_matrix(source, state.matrix)  # as the widget tells it: a default spacing along today's w
        _set_on_source(source, event.name, event.value)
        return True
    if isinstance(event, Setting):
        setattr(state, event.name, np.asarray(event.value) if event.name == "matrix" else event.value)
        return True
    action = event.action
    if action.kind == "custom":
        sa = _source_action(as_source(source), action.name) if source is not None else None
        if sa is None:
            return False
        note_matrix(source, state.matrix)
        sa.run(-1 if event.inverted else 1)
        return True
    state.apply(action, event.inverted)
    return True


# ============================================================================ recordings
class Recording:
    """A starting state and the events applied to it (immutable).

    * ``initial``: the state the events start from (`RotationState.to_dict` with its reset point,
      so a recorded ``r`` resets where the live one did);
    * ``initial_source``: the source settings the events start from (``{"levels": [...], ...}``,
      those the recorder was told with ``source_settings=``, and those folded in), possibly empty;
    * ``initial_view``: the view settings the events start from (``{"rendering": "surface", ...}``,
      told with ``view_settings=``), possibly empty: a renderer then draws with its own;
    * ``events``: `Step` (t, key, shift, action, inverted, label), `Setting` (t, name, value),
      `SourceSetting` (t, name, value) and `ViewSetting` (t, name, value);
    * ``to_dict`` / ``from_dict``, ``save(path)`` / ``load(path)`` (JSON), ``replay(state, source)``.

    Loading imports nothing and runs nothing a recording names: a source's own action is looked up
    by name among the actions of the source the caller passes.  ``replay`` applies a source's own
    actions (a field's level keys, a stack's slice keys) and the source settings to a source when
    one is given (``set_source=`` lets the widget apply a setting itself, as turning a single view
    into a stack replaces its source), else skips them; view settings change neither state nor
    source: they go to ``set_view=`` (the widget sets its traits), else are skipped.
    """

    def __init__(self, initial: Mapping, events=(), *, dropped: int = 0, initial_source: Mapping | None = None,
                 initial_view: Mapping | None = None):
        RotationState.from_dict(initial)  # validates
        self._initial_source = _check_source_settings(initial_source)
        self._initial_view = _check_view_settings(initial_view)
        self._initial = json.loads(json.dumps(dict(initial)))  # a private, JSON-clean copy
        self.events = tuple(events)
        for e in self.events:
            if not isinstance(e, (Step, Setting, SourceSetting, ViewSetting)):
                raise TypeError(f"Expected Step, Setting, SourceSetting or ViewSetting events, got {type(e).__name__}")
        if isinstance(dropped, (bool, np.bool_)) or not isinstance(dropped, Integral) or dropped < 0:
            raise ValueError("Expected `dropped` (how many events were folded into the starting state) to be an "
                             f"int >= 0, got {dropped!r}")
        self.dropped = int(dropped)

    @property
    def initial_source(self) -> dict:
        """The source settings at the start (``{name: value}``: `SOURCE_SETTINGS` or a source's own; a copy)."""
        return json.loads(json.dumps(self._initial_source))

    @property
    def initial_view(self) -> dict:
        """The view settings at the start (``{name: value}`` of `VIEW_SETTINGS`; a copy)."""
        return json.loads(json.dumps(self._initial_view))

    @property
    def initial(self) -> dict:
        """The starting state as `RotationState.to_dict(initial=True)` data (a copy)."""
        return json.loads(json.dumps(self._initial))

    def initial_state(self, keymap=None) -> RotationState:
        """A fresh `RotationState` at the start of the recording (its reset point as recorded)."""
        return RotationState.from_dict(self._initial, keymap=keymap)

    def for_source(self, source) -> "Recording":
        """This recording with c0 and the slices' spacing in ``source``'s w units: a recording made
        before c0 followed the data's units (its starting state of format 1) has its c0, initial c0,
        c0 step and every recorded ``c0`` / ``c0_step`` setting converted by the source's ``w_frame``
        (`rot4d_widget.sources.protocol.w_frame`: c0 -> origin + per_unit c0), and one made before the
        spacing did (format 1 or 2) its recorded and starting ``spacing`` (times per_unit); any
        other recording, or a source whose frame is (0, 1) (a polytope), gives ``self``."""
        fmt = self._initial.get("format", STATE_FORMAT)
        if source is None or fmt >= STATE_FORMAT:
            return self
        frame = w_frame(source)
        if frame == (0.0, 1.0):
            return self
        origin, per = frame if fmt < 2 else (0.0, 1.0)  # c0 in the drawn units up to format 1
        spread = spacing_factor(fmt, frame)  # and the spacing up to format 2
        initial = RotationState.from_dict(self._initial, w_frame=frame).to_dict(initial=True)

        def converted(e):
            if isinstance(e, Setting) and e.name == "c0":
                return Setting(e.t, "c0", origin + per * float(e.value))
            if isinstance(e, Setting) and e.name == "c0_step":
                return Setting(e.t, "c0_step", per * float(e.value))
            if isinstance(e, SourceSetting) and e.name == "spacing" and e.value is not None:
                return SourceSetting(e.t, "spacing", spread * float(e.value))
            return e

        start = dict(self._initial_source or {})
        if start.get("spacing") is not None:
            start["spacing"] = spread * float(start["spacing"])
        return Recording(initial, [converted(e) for e in self.events], dropped=self.dropped,
                         initial_source=start or None, initial_view=self._initial_view)

    @property
    def duration(self) -> float:
        """Seconds from the start to the last event (0 without events)."""
        return self.events[-1].t if self.events else 0.0

    def __len__(self) -> int:
        return len(self.events)

    def __repr__(self) -> str:
        return f"Recording({len(self.events)} events over {self.duration:.3g} s, {self.dropped} dropped)"

    # -- data ------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        # the lowest version that holds it: older readers keep reading what they can
        if self._initial_view or any(isinstance(e, ViewSetting) for e in self.events):
            version = 3
        elif self._initial_source or any(isinstance(e, SourceSetting) for e in self.events):
            version = 2
        else:
            version = 1
        d = {"format": RECORDING_FORMAT, "version": version, "initial": self.initial}
        if self._initial_source:
            d["initial_source"] = self.initial_source
        if self._initial_view:
            d["initial_view"] = self.initial_view
        d.update(dropped=self.dropped, events=[e.to_dict() for e in self.events])
        return d

    @classmethod
    def from_dict(cls, d) -> "Recording":
        if not isinstance(d, Mapping) or d.get("format") != RECORDING_FORMAT:
            raise ValueError(f"Not a rot4d_widget recording (no \"format\": \"{RECORDING_FORMAT}\")")
        v = d.get("version")
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= RECORDING_VERSION:
            raise ValueError(f"A recording of version {v!r}; this rot4d_widget reads versions 1 ... "
                             f"{RECORDING_VERSION}")
        if "initial" not in d or not isinstance(d.get("events"), list):
            raise ValueError("A recording needs its 'initial' state and a list of 'events'")
        events = [_event_from_dict(e) for e in d["events"]]
        if any(b.t < a.t for a, b in zip(events, events[1:])):
            raise ValueError("Expected a recording's events in time order")
        try:
            initial_view = _check_view_settings(d.get("initial_view"))
        except TypeError as exc:  # a file's bad value: the file is wrong
            raise ValueError(f"Bad 'initial_view': {exc}") from None
        return cls(d["initial"], events, dropped=d.get("dropped", 0), initial_source=d.get("initial_source"),
                   initial_view=initial_view)

    def save(self, path) -> None:
        """Write the recording as JSON to ``path``."""
        with open(os.fspath(path), "w", encoding="utf-8") as fh:
            json.dump(self.to_dict(), fh, allow_nan=False)
            fh.write("\n")

    @classmethod
    def load(cls, path) -> "Recording":
        """Read a recording `save` wrote; ``ValueError`` naming what is wrong otherwise."""
        return cls.from_dict(read_json(path, "rot4d_widget recording"))

    # -- replay ----------------------------------------------------------------------------
    def replay(self, state: RotationState | None = None, source=None, *, restart: bool = True,
               set_source=None, set_view=None) -> RotationState:
        """Apply the events to ``state`` (in place; default a fresh state) and return it.

        ``restart``: set ``state`` to the recording's starting state first (its orientation,
        parameters and reset point; its keymap is kept) and the source to its `initial_source`
        settings.  ``source``: a source whose own actions
        (``source.actions``, matched by name) are replayed on it, changing it; without one they
        are skipped.  The result equals the recorded final state bit for bit.

        Source settings (`SourceSetting`: ``levels``, ``slices``, ``spacing``, ``arrangement``)
        are applied by calling ``set_source(name, value)`` when given (the widget's own setter:
        setting ``slices`` on a single view replaces its source with a stack, which only the
        widget can do), else set on ``source`` in place (``levels`` on a stack's inner source);
        a single-view ``source`` given a stack setting is refused (``ValueError``) before
        anything changes.  Without ``source`` or ``set_source`` they are skipped.

        View settings (`ViewSetting`: ``rendering``, ``cmap``, ``clim``, ``sections``; with
        ``restart`` the `initial_view` first) go to ``set_view(name, value)`` at their place among
        the events (the widget sets its traits); without it they are skipped.
        """
        for name, f in (("set_source", set_source), ("set_view", set_view)):
            if f is not None and not callable(f):
                raise TypeError(f"Expected `{name}` to be a callable (name, value), got {type(f).__name__}")
        if source is not None and set_source is None:
            source = as_source(source)  # read by the protocol alone
        if source is not None and self._initial.get("format", STATE_FORMAT) < STATE_FORMAT:
            return self.for_source(source).replay(state, source, restart=restart, set_source=set_source,
                                                  set_view=set_view)
        if set_source is None and source is not None:
            self._check_source_settings(source, restart)
        if state is None:
            state = self.initial_state()
        elif not isinstance(state, RotationState):
            raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
        elif restart:
            d = dict(self._initial)
            d.pop("keymap", None)
            state.restore(d)  # with the recorded reset point ("initial")
        if restart:
            for e in self.start_settings() + self._start_view():
                apply_event(state, e, source, set_source, set_view)
        for e in self.events:
            apply_event(state, e, source, set_source, set_view)
        return state

    def start_settings(self) -> list:
        """`initial_source` as `SourceSetting` events at t = 0: what replaying from the start sets
        on the source first (`replay`, and an animation's frames)."""
        return [SourceSetting(0.0, name, value) for name, value in self.initial_source.items()]

    def _start_view(self) -> list:
        """`initial_view` as `ViewSetting` events at t = 0."""
        return [ViewSetting(0.0, name, value) for name, value in self.initial_view.items()]

    def _check_source_settings(self, source, restart: bool = True) -> None:
        """ValueError now if ``source`` cannot take the recording's source settings in place."""
        names = {e.name for e in self.events if isinstance(e, SourceSetting)}
        if restart:
            names |= set(self._initial_source)
        have = settings_of(source)
        missing = [n for n in _FIELD_SETTINGS if n in names and n not in have]
        if missing:
            raise ValueError(f"The recording sets {', '.join(map(repr, missing))}, which apply to a field "
                             f"(a source with iso levels), not {class_name(inner_source(source))}")
        stack_names = sorted(n for n in names & set(_STACK_SETTINGS) if n not in have)
        if stack_names and not _is_stack(source):
            raise ValueError(f"The recording sets {', '.join(map(repr, stack_names))}, which apply to parallel "
                             f"slices, and {class_name(source)} is a single view: replay with set_source= "
                             "(Rot4DWidget.replay turns its view into a stack), or on a StackSource")
        other = sorted(n for n in names if n not in have)
        if other:
            title = source_title(source)
            raise ValueError(f"The recording sets {', '.join(map(repr, other))}, which {title} does not have; "
                             f"its settings: {', '.join(sorted(have)) or 'none'}")


class Recorder:
    """The widget's hook: collects the actions it applies, bounded to ``max_events``.

    ``Recorder(state)`` starts from ``state`` as it is now (copied).  Call ``record(key, shift,
    action, inverted)`` after each applied action and ``record_set(name, value)`` after a
    parameter set from outside the keys; ``t`` defaults to the seconds since the recorder was
    made (``clock``, default `time.monotonic`).  Thread-safe (the widget's ticker thread records
    while the kernel's thread may read).  Past ``max_events`` the oldest event is folded into
    the starting state, so `recording` always replays to the live state (custom source actions
    that fall out are lost: count in ``dropped``; a source setting that falls out becomes the
    recording's `Recording.initial_source`, a view setting its ``initial_view``).
    ``record_source(name, value)`` records a source setting (``levels``, ``slices``, ``spacing``,
    ``arrangement``, or the source's own) and ``record_view(name, value)`` a view setting
    (`VIEW_SETTINGS`); ``source_settings`` and ``view_settings`` (here and in `restart`) are
    those settings when recording starts, ``{name: value}``.
    """

    def __init__(self, state: RotationState, *, max_events: int = MAX_EVENTS, clock=time.monotonic,
                 source_settings: Mapping | None = None, view_settings: Mapping | None = None):
        if not isinstance(state, RotationState):
            raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
        if isinstance(max_events, bool) or not isinstance(max_events, int) or max_events < 1:
            raise ValueError(f"Expected `max_events` to be an int >= 1, got {max_events!r}")
        if not callable(clock):
            raise TypeError("Expected `clock` to be a callable returning seconds")
        self.max_events = max_events
        self._clock = clock
        self._lock = threading.Lock()
        self._start(state, source_settings, view_settings)

    def _start(self, state, source_settings=None, view_settings=None):
        settings = _check_source_settings(source_settings)
        view = _check_view_settings(view_settings)
        self._t0 = self._clock()
        self._shadow = state.copy()  # the state before the oldest kept event
        self._shadow_source = settings  # the source settings before the oldest kept event
        self._shadow_view = view  # the view settings before the oldest kept event
        self._events = collections.deque()
        self.dropped = 0

    def restart(self, state: RotationState, source_settings: Mapping | None = None,
                view_settings: Mapping | None = None) -> None:
        """Forget everything; record from ``state`` (and the source's ``source_settings``, the
        ``view_settings``) as they are now."""
        with self._lock:
            self._start(state, source_settings, view_settings)

    def since_start(self, clock_time: float) -> float:
        """A time of the recorder's ``clock`` as the recording's ``t`` (seconds since it started)."""
        return max(0.0, clock_time - self._t0)

    def _stamp(self, t):
        return max(0.0, self._clock() - self._t0) if t is None else _time(t)

    def _push(self, event):
        with self._lock:
            if self._events and event.t < self._events[-1].t:  # a clock that stepped back: keep the order
                event = dataclasses.replace(event, t=self._events[-1].t)
            self._events.append(event)
            while len(self._events) > self.max_events:
                old = self._events.popleft()
                if isinstance(old, SourceSetting):  # folded into the starting source settings
                    self._shadow_source[old.name] = old.value
                elif isinstance(old, ViewSetting):  # folded into the starting view settings
                    self._shadow_view[old.name] = old.value
                else:
                    apply_event(self._shadow, old)
                self.dropped += 1

    def record(self, key, shift, action, inverted: bool | None = None, t=None) -> Step:
        """One applied ``action`` (an `Action` or its name, ``"xw"``), from ``key`` with ``shift``;
        ``inverted`` defaults to ``shift`` for rotations (as `Keymap.resolve`)."""
        action = Action.parse(action)
        if key is not None and not isinstance(key, str):
            raise TypeError(f"Expected `key` to be a string or None, got {type(key).__name__}")
        shift = bool(shift)
        inverted = (shift and action.is_rotation) if inverted is None else bool(inverted)
        step = Step(self._stamp(t), key, shift, action, inverted)
        self._push(step)
        return step

    def record_set(self, name: str, value, t=None) -> Setting:
        """A parameter (``"theta0"``, ``"alpha"``, ``"c0"``, ``"c0_step"``, ``"matrix"``) set to ``value``."""
        setting = Setting(self._stamp(t), name, _check_setting(name, value))
        self._push(setting)
        return setting

    def record_source(self, name: str, value, t=None) -> SourceSetting:
        """A source setting (``"levels"``, ``"slices"``, ``"spacing"``, ``"arrangement"``, or a name
        in the source's own protocol ``settings``) set to ``value`` -- what the widget calls after
        its trait changed the source."""
        setting = SourceSetting(self._stamp(t), name, _check_source_setting(name, value))
        self._push(setting)
        return setting

    def record_view(self, name: str, value, t=None) -> ViewSetting:
        """A view setting (``"rendering"``, ``"cmap"``, ``"clim"``, ``"sections"``) set to ``value``
        -- what the widget calls after a user changed it (a trait, a key)."""
        setting = ViewSetting(self._stamp(t), name, check_view_setting(name, value))
        self._push(setting)
        return setting

    def recording(self) -> Recording:
        """The events so far as an immutable `Recording`."""
        with self._lock:
            return Recording(self._shadow.to_dict(initial=True), tuple(self._events), dropped=self.dropped,
                             initial_source=self._shadow_source, initial_view=self._shadow_view)

    def __len__(self) -> int:
        return len(self._events)
