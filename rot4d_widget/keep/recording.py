"""Recorded key sequences: what was applied, when, replayed and rendered as GIF or MP4.

A `Recorder` is the widget's hook: created with the `RotationState` as it is when recording
starts, it is told every action the widget applies (``recorder.record(key, shift, action,
inverted)``, a repeat tick as well as a key press) and every parameter set from outside the keys
(``recorder.record_set("c0", 0.3)``, a slider) and every setting of the source
(``recorder.record_source("levels", (2.0, 3.0))``: ``levels``, ``slices``, ``spacing``,
``arrangement``), with a time stamp.  It keeps at most
``max_events``; older events are folded into the starting state, so a recording always replays
to the live state.  ``recorder.recording()`` is an immutable `Recording`:

* ``initial``: the state the events start from (`RotationState.to_dict` with its reset point,
  so a recorded ``r`` resets where the live one did);
* ``initial_source``: the source settings the events start from (``{"levels": [...], ...}``, those
  the recorder was told with ``source_settings=``, and those folded in), possibly empty;
* ``events``: `Step` (t, key, shift, action, inverted, label), `Setting` (t, name, value) and
  `SourceSetting` (t, name, value);
* ``to_dict`` / ``from_dict``, ``save(path)`` / ``load(path)`` (JSON), ``replay(state, source)``.

A recording is data: loading one imports nothing and runs nothing it names (a source's own
action is looked up by name among the actions of the source the caller passes).

Replaying applies the same floating-point operations in the same order, so the final state is
the recorded one bit for bit (tested).  A source's own actions (a field's level keys, a stack's
slice keys) and the source's settings are replayed on a source when one is given
(`Recording.replay`; ``set_source=`` lets the widget apply a setting itself, as turning a single
view into a stack replaces its source), else skipped.

`render_animation` draws a recording with `rot4d_widget.keep.figures.render_state` -- one frame
per step, or one per 1/fps seconds of the recorded time -- into an animated GIF (Pillow) or an
MP4 (imageio with imageio-ffmpeg's ffmpeg).  `paper_animation(3)` / `paper_animation(4)` are
the paper's Figs. 3 and 4 (the key sequences of `figures.paper_figure_3` / ``_4``) as animations.
"""

from __future__ import annotations

import collections
import copy
import dataclasses
import json
import math
import os
import threading
import time
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Iterator, Mapping

import numpy as np

from ..core.keymap import Action
from ..core.state import RotationState, action_from_data, action_to_data

__all__ = [
    "RECORDING_FORMAT",
    "RECORDING_VERSION",
    "MAX_EVENTS",
    "ANIMATION_FORMATS",
    "Step",
    "Setting",
    "SourceSetting",
    "SOURCE_SETTINGS",
    "Recording",
    "Recorder",
    "animation_states",
    "render_frames",
    "render_animation",
    "paper_recording",
    "paper_animation",
]

RECORDING_FORMAT = "rot4d_widget recording"
#: Version 2 adds `SourceSetting` events; a recording without them is written as version 1
#: (so that an older rot4d_widget still reads it).
RECORDING_VERSION = 2
#: Default bound of a `Recorder`: 100 000 events is about 55 minutes of a key held at 30 Hz
#: (some 10 MB of JSON).
MAX_EVENTS = 100_000
ANIMATION_FORMATS = (".gif", ".mp4")
#: What `Recorder.record_set` accepts: the state's settable parameters.
SETTABLE = ("theta0", "alpha", "c0", "c0_step", "matrix")
#: What `Recorder.record_source` accepts: the source's settings the widget has as traits.
SOURCE_SETTINGS = ("levels", "inside", "caps", "slices", "spacing", "arrangement")
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
    ``"oval"``, ``"grid"`` or ``"stack"``.  Not a `Setting` (the state's): a sibling."""

    _KEY = "source"


def _time(t) -> float:
    if isinstance(t, bool) or not isinstance(t, Real) or not math.isfinite(t) or t < 0:
        raise ValueError(f"Expected a time stamp >= 0 (seconds), got {t!r}")
    return float(t)


def _check_setting(name, value):
    if name not in SETTABLE:
        raise ValueError(f"Expected a setting among {', '.join(map(repr, SETTABLE))}, got {name!r}")
    if name == "matrix":
        from ..core.rotation import as_rotation_matrix

        return as_rotation_matrix(value).tolist()
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
        raise ValueError(f"Expected {name!r} to be set to a finite number, got {value!r}")
    return float(value)


def _check_source_setting(name, value):
    """``value`` as a `SourceSetting` holds it (JSON-able); ValueError naming what is allowed."""
    if name not in SOURCE_SETTINGS:
        raise ValueError(f"Expected a source setting among {', '.join(map(repr, SOURCE_SETTINGS))}, got {name!r}")
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
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Real) or not (math.isfinite(value) and value > 0):
            raise ValueError(f"Expected 'spacing' to be set to a finite number > 0 or None (the default), got {value!r}")
        return float(value)
    from ..sources.tomography import ARRANGEMENTS

    if value not in ARRANGEMENTS:
        raise ValueError(f"Expected 'arrangement' to be set to one of {', '.join(map(repr, ARRANGEMENTS))}, "
                         f"got {value!r}")
    return str(value)


def _check_source_settings(settings) -> dict:
    """A ``{name: value}`` of source settings, checked (`_check_source_setting`), in `SOURCE_SETTINGS` order."""
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise ValueError(f"Expected the source settings as a dict {{name: value}}, got {settings!r}")
    for name in settings:
        if name not in SOURCE_SETTINGS:
            raise ValueError(f"Expected a source setting among {', '.join(map(repr, SOURCE_SETTINGS))}, got {name!r}")
    return {name: _check_source_setting(name, settings[name]) for name in SOURCE_SETTINGS if name in settings}


def _event_from_dict(d):
    if not isinstance(d, Mapping) or "t" not in d:
        raise ValueError(f"Expected a recorded event with a time 't', got {d!r}")
    t = _time(d["t"])
    if "set" in d:
        return Setting(t, d["set"], _check_setting(d["set"], d.get("value")))
    if "source" in d:
        return SourceSetting(t, d["source"], _check_source_setting(d["source"], d.get("value")))
    if "action" not in d:
        raise ValueError(f"Expected a recorded event with an 'action', a 'set' or a 'source', got {dict(d)!r}")
    key = d.get("key")
    if key is not None and not isinstance(key, str):
        raise ValueError(f"Expected an event's 'key' to be a string or null, got {key!r}")
    shift, inverted = d.get("shift", False), d.get("inverted", False)
    if not isinstance(shift, bool) or not isinstance(inverted, bool):
        raise ValueError(f"Expected 'shift' and 'inverted' to be true or false in {dict(d)!r}")
    return Step(t, key, shift, action_from_data(d["action"]), inverted)


# ============================================================================ applying
def _source_action(source, name: str):
    actions = getattr(source, "actions", None) or {}
    for sa in actions.values():
        if getattr(sa, "name", None) == name:
            return sa
    return None


def _is_stack(source) -> bool:
    from ..sources.tomography import StackSource

    return isinstance(source, StackSource)


def _set_on_source(source, name: str, value) -> None:
    """Set a source setting on ``source`` in place: ``levels`` on a field (a stack's inner one),
    the others on a stack.  ValueError if ``source`` has no such setting."""
    if name in _FIELD_SETTINGS:
        target = source.source if _is_stack(source) else source
        if not hasattr(target, name):
            raise ValueError(f"A recorded {name!r} applies to a source that has it (a field), not "
                             f"{type(target).__name__}")
        setattr(target, name, tuple(value) if name == "levels" else value)
        return
    if not _is_stack(source):
        raise ValueError(f"A recorded {name!r} applies to parallel slices, and {type(source).__name__} is a single "
                         "view: replay with set_source= (Rot4DWidget.replay turns its view into a stack), or "
                         "on a StackSource")
    setattr(source, name, value)


def _with_source_setting(source, name: str, value):
    """``source`` with a source setting applied: in place, or (``slices`` of a single view) a new
    `StackSource` around it, as the widget does."""
    if name == "slices" and not _is_stack(source):
        from ..sources.tomography import StackSource

        return StackSource(source, slices=value)
    _set_on_source(source, name, value)
    return source


def _apply(state: RotationState, event, source=None, set_source=None) -> bool:
    """Apply one event to ``state`` (a source's own action and a source setting to ``source``, or
    a source setting through ``set_source(name, value)``); True if applied."""
    if isinstance(event, SourceSetting):
        if set_source is not None:
            set_source(event.name, event.value)
            return True
        if source is None:
            return False
        _set_on_source(source, event.name, event.value)
        return True
    if isinstance(event, Setting):
        setattr(state, event.name, np.asarray(event.value) if event.name == "matrix" else event.value)
        return True
    action = event.action
    if action.kind == "custom":
        sa = _source_action(source, action.name) if source is not None else None
        if sa is None:
            return False
        sa.run(-1 if event.inverted else 1)
        return True
    state.apply(action, event.inverted)
    return True


# ============================================================================ recordings
class Recording:
    """A starting state and the events applied to it (immutable; see the module docstring)."""

    def __init__(self, initial: Mapping, events=(), *, dropped: int = 0, initial_source: Mapping | None = None):
        RotationState.from_dict(initial)  # validates
        self._initial_source = _check_source_settings(initial_source)
        self._initial = json.loads(json.dumps(dict(initial)))  # a private, JSON-clean copy
        self.events = tuple(events)
        for e in self.events:
            if not isinstance(e, (Step, Setting, SourceSetting)):
                raise TypeError(f"Expected Step, Setting or SourceSetting events, got {type(e).__name__}")
        if isinstance(dropped, (bool, np.bool_)) or not isinstance(dropped, Integral) or dropped < 0:
            raise ValueError("Expected `dropped` (how many events were folded into the starting state) to be an "
                             f"int >= 0, got {dropped!r}")
        self.dropped = int(dropped)

    @property
    def initial_source(self) -> dict:
        """The source settings at the start (``{name: value}`` of `SOURCE_SETTINGS`; a copy)."""
        return json.loads(json.dumps(self._initial_source))

    @property
    def initial(self) -> dict:
        """The starting state as `RotationState.to_dict(initial=True)` data (a copy)."""
        return json.loads(json.dumps(self._initial))

    def initial_state(self, keymap=None) -> RotationState:
        """A fresh `RotationState` at the start of the recording (its reset point as recorded)."""
        return RotationState.from_dict(self._initial, keymap=keymap)

    def for_source(self, source) -> "Recording":
        """This recording with c0 in ``source``'s w units: a recording made before c0 followed
        the data's units (its starting state of format 1) has its c0, initial c0, c0 step and
        every recorded ``c0`` / ``c0_step`` setting converted by the source's ``w_frame``
        (`rot4d_widget.sources.protocol.w_frame`: c0 -> origin + per_unit c0); any other recording, or a
        source whose frame is (0, 1) (a polytope), gives ``self``."""
        from ..sources.protocol import w_frame

        if source is None or self._initial.get("format", 2) >= 2:
            return self
        frame = w_frame(source)
        if frame == (0.0, 1.0):
            return self
        origin, per = frame
        initial = RotationState.from_dict(self._initial, w_frame=frame).to_dict(initial=True)

        def converted(e):
            if isinstance(e, Setting) and e.name == "c0":
                return Setting(e.t, "c0", origin + per * float(e.value))
            if isinstance(e, Setting) and e.name == "c0_step":
                return Setting(e.t, "c0_step", per * float(e.value))
            return e

        return Recording(initial, [converted(e) for e in self.events], dropped=self.dropped,
                         initial_source=self._initial_source)

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
        # version 1 unless a source setting needs 2: older readers keep reading what they can
        version = 2 if self._initial_source or any(isinstance(e, SourceSetting) for e in self.events) else 1
        d = {"format": RECORDING_FORMAT, "version": version, "initial": self.initial}
        if self._initial_source:
            d["initial_source"] = self.initial_source
        d.update(dropped=self.dropped, events=[e.to_dict() for e in self.events])
        return d

    @classmethod
    def from_dict(cls, d) -> "Recording":
        if not isinstance(d, Mapping) or d.get("format") != RECORDING_FORMAT:
            raise ValueError(f"Not a rot4d_widget recording (no \"format\": \"{RECORDING_FORMAT}\")")
        v = d.get("version")
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= RECORDING_VERSION:
            raise ValueError(f"A recording of version {v!r}; this rot4d_widget reads versions 1 ... {RECORDING_VERSION}")
        if "initial" not in d or not isinstance(d.get("events"), list):
            raise ValueError("A recording needs its 'initial' state and a list of 'events'")
        events = [_event_from_dict(e) for e in d["events"]]
        if any(b.t < a.t for a, b in zip(events, events[1:])):
            raise ValueError("Expected a recording's events in time order")
        return cls(d["initial"], events, dropped=d.get("dropped", 0), initial_source=d.get("initial_source"))

    def save(self, path) -> None:
        """Write the recording as JSON to ``path``."""
        with open(os.fspath(path), "w", encoding="utf-8") as fh:
            json.dump(self.to_dict(), fh, allow_nan=False)
            fh.write("\n")

    @classmethod
    def load(cls, path) -> "Recording":
        """Read a recording `save` wrote; ``ValueError`` naming what is wrong otherwise."""
        try:
            with open(os.fspath(path), encoding="utf-8") as fh:
                d = json.load(fh)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"{os.fspath(path)!r} is not a rot4d_widget recording: not JSON ({exc})") from None
        return cls.from_dict(d)

    # -- replay ----------------------------------------------------------------------------
    def replay(self, state: RotationState | None = None, source=None, *, restart: bool = True,
               set_source=None) -> RotationState:
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
        """
        if set_source is not None and not callable(set_source):
            raise TypeError(f"Expected `set_source` to be a callable (name, value), got {type(set_source).__name__}")
        if source is not None and self._initial.get("format", 2) < 2:
            return self.for_source(source).replay(state, source, restart=restart, set_source=set_source)
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
            for e in self._start_settings():
                _apply(state, e, source, set_source)
        for e in self.events:
            _apply(state, e, source, set_source)
        return state

    def _start_settings(self) -> list:
        """`initial_source` as `SourceSetting` events at t = 0."""
        return [SourceSetting(0.0, name, value) for name, value in self.initial_source.items()]

    def _check_source_settings(self, source, restart: bool = True) -> None:
        """ValueError now if ``source`` cannot take the recording's source settings in place."""
        names = {e.name for e in self.events if isinstance(e, SourceSetting)}
        if restart:
            names |= set(self._initial_source)
        inner = source.source if _is_stack(source) else source
        missing = [n for n in _FIELD_SETTINGS if n in names and not hasattr(inner, n)]
        if missing:
            raise ValueError(f"The recording sets {', '.join(map(repr, missing))}, which apply to a field "
                             f"(a source with iso levels), not {type(inner).__name__}")
        stack_names = sorted(names & set(_STACK_SETTINGS))
        if stack_names and not _is_stack(source):
            raise ValueError(f"The recording sets {', '.join(map(repr, stack_names))}, which apply to parallel "
                             f"slices, and {type(source).__name__} is a single view: replay with set_source= "
                             "(Rot4DWidget.replay turns its view into a stack), or on a StackSource")


class Recorder:
    """The widget's hook: collects the actions it applies, bounded to ``max_events``.

    ``Recorder(state)`` starts from ``state`` as it is now (copied).  Call ``record(key, shift,
    action, inverted)`` after each applied action and ``record_set(name, value)`` after a
    parameter set from outside the keys; ``t`` defaults to the seconds since the recorder was
    made (``clock``, default `time.monotonic`).  Thread-safe (the widget's ticker thread records
    while the kernel's thread may read).  Past ``max_events`` the oldest event is folded into
    the starting state, so `recording` always replays to the live state (custom source actions
    that fall out are lost: count in ``dropped``; a source setting that falls out becomes the
    recording's `Recording.initial_source`).  ``record_source(name, value)`` records a source
    setting (``levels``, ``slices``, ``spacing``, ``arrangement``); ``source_settings`` (here and
    in `restart`) are the source's settings when recording starts, ``{name: value}``.
    """

    def __init__(self, state: RotationState, *, max_events: int = MAX_EVENTS, clock=time.monotonic,
                 source_settings: Mapping | None = None):
        if not isinstance(state, RotationState):
            raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
        if isinstance(max_events, bool) or not isinstance(max_events, int) or max_events < 1:
            raise ValueError(f"Expected `max_events` to be an int >= 1, got {max_events!r}")
        if not callable(clock):
            raise TypeError("Expected `clock` to be a callable returning seconds")
        self.max_events = max_events
        self._clock = clock
        self._lock = threading.Lock()
        self._start(state, source_settings)

    def _start(self, state, source_settings=None):
        settings = _check_source_settings(source_settings)
        self._t0 = self._clock()
        self._shadow = state.copy()  # the state before the oldest kept event
        self._shadow_source = settings  # the source settings before the oldest kept event
        self._events = collections.deque()
        self.dropped = 0

    def restart(self, state: RotationState, source_settings: Mapping | None = None) -> None:
        """Forget everything; record from ``state`` (and the source's ``source_settings``) as they are now."""
        with self._lock:
            self._start(state, source_settings)

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
                else:
                    _apply(self._shadow, old)
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
        """A source setting (``"levels"``, ``"slices"``, ``"spacing"``, ``"arrangement"``) set to
        ``value`` -- what the widget calls after its trait changed the source."""
        setting = SourceSetting(self._stamp(t), name, _check_source_setting(name, value))
        self._push(setting)
        return setting

    def recording(self) -> Recording:
        """The events so far as an immutable `Recording`."""
        with self._lock:
            return Recording(self._shadow.to_dict(initial=True), tuple(self._events), dropped=self.dropped,
                             initial_source=self._shadow_source)

    def __len__(self) -> int:
        return len(self._events)


# ============================================================================ animations
def _own_copy(source):
    """A copy of ``source`` that replaying its own actions may change (the original stays)."""
    from ..sources.protocol import as_source
    from ..sources.tomography import StackSource

    src = as_source(source)
    if isinstance(src, StackSource):
        return StackSource(_own_copy(src.source), slices=src.slices,
                           spacing=None if src.spacing_is_default else src.spacing,
                           arrangement=src.arrangement, color_by=src.color_by)
    return copy.copy(src)


def animation_states(recording: Recording, initial_state: RotationState | None = None, source=None, *,
                     per: str = "step", fps: float = 10.0) -> Iterator[tuple]:
    """``(t, state, source)`` for each frame: after each step (``per="step"``, the first frame the
    starting state) or at t = k / fps over the recorded time (``per="time"``: the state after every
    event up to t).  ``state`` and ``source`` are the same objects every time, changed in place
    (but a recorded ``slices`` on a single view makes the source a new `StackSource` around it,
    as the widget does): draw them before taking the next.  ``initial_state``: start there
    instead of the recording's starting state (its copy is used).  ``source`` is copied before
    its own actions and the recorded source settings change it."""
    if per not in ("step", "time"):
        raise ValueError(f"Expected `per` to be 'step' or 'time', got {per!r}")
    fps = _positive("fps", fps)
    if source is not None and not isinstance(source, str):
        recording = recording.for_source(source)  # c0 of an older recording in the source's units
    if initial_state is None:
        state = recording.initial_state()
    elif isinstance(initial_state, RotationState):
        state = initial_state.copy()
    else:
        raise TypeError(f"Expected `initial_state` to be a RotationState or None, got {type(initial_state).__name__}")
    src = None if source is None else _own_copy(source)

    def set_source(name, value):  # the copy is ours: replace it where the widget would
        nonlocal src
        src = _with_source_setting(src, name, value)

    setter = None if src is None else set_source
    if src is not None:
        for e in recording._start_settings():
            set_source(e.name, e.value)
    events = recording.events
    yield 0.0, state, src
    if per == "step":
        for e in events:
            _apply(state, e, src, setter)
            yield e.t, state, src
        return
    n = _frame_count(recording, "time", fps)
    i = 0
    for k in range(1, n):
        t = k / fps
        while i < len(events) and events[i].t <= t + 1e-9:
            _apply(state, events[i], src, setter)
            i += 1
        yield t, state, src


def _frame_count(recording, per: str, fps: float) -> int:
    """Frames of an animation: the start and one per step, or one per 1/fps s of recorded time."""
    if per == "step":
        return len(recording.events) + 1
    return int(math.ceil(recording.duration * fps - 1e-9)) + 1


def _positive(name, value) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not (math.isfinite(value) and value > 0):
        raise ValueError(f"Expected `{name}` to be a finite number > 0, got {value!r}")
    return float(value)


def _figure_rgb(fig) -> np.ndarray:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


#: Slices kept from the framing pass for the drawing pass, in bytes (beyond it they are recomputed).
_SLICE_CACHE_BYTES = 256 * 2**20
_PREPARE_KEYS = ("levels", "inside", "caps", "slices", "spacing", "arrangement", "ball_radius", "show_balls")


def _data_bytes(data) -> int:
    return sum(int(getattr(np.asarray(getattr(data, name, ())), "nbytes", 0))
               for name in ("points", "segments", "triangles", "groups", "normals"))


def render_frames(recording: Recording, initial_state=None, source="5-cell", *, per: str = "step",
                  fps: float = 10.0, max_frames: int = 3000, titles=None, frame="fit", annotate=True,
                  **settings) -> Iterator[np.ndarray]:
    """The frames of `render_animation`, one (H, W, 3) uint8 array at a time.

    ``settings`` go to `rot4d_widget.keep.figures.render_state` (``size``, ``dpi``, ``levels``,
    ``slices``, ``color_by`` ...).  ``titles``: a callable ``(k, t, state) -> str`` giving each
    frame a title, or None.  More than ``max_frames`` frames raises ``ValueError`` before any is drawn.
    When the recording has source settings (``levels``, ``slices``, ``spacing``,
    ``arrangement``: its `Recording.initial_source` or recorded ones), those keywords are the
    source's settings at the start unless ``initial_source`` has them, and each frame shows them
    as recorded up to it.

    ``frame="fit"`` (default): every frame is framed alike, by the union of the projected
    bounding boxes of all frames' slices (`figures.frame_extent`), which fills 90 % of the
    picture's width or height -- the slices are computed once for this, in a first pass, and
    kept for drawing (up to 256 MB); ``"camera"`` or a box as `render_state`.  ``annotate``
    (default True): each frame carries "t = ... s, frame k/n", θ0, c0 and what the source tells
    of itself (`figures.annotation`), and a legend; False for a bare picture.
    """
    for f in _frames(recording, initial_state, source, per=per, fps=fps, max_frames=max_frames, titles=titles,
                     frame=frame, annotate=annotate, **settings):
        yield _as_rgb(f)


def _frames(recording: Recording, initial_state=None, source="5-cell", *, per: str = "step", fps: float = 10.0,
            max_frames: int = 3000, titles=None, frame="fit", annotate=True, **settings) -> Iterator[np.ndarray]:
    """`render_frames`' frames as they are drawn: (H, W, 4) uint8 RGBA views of one reused canvas
    (valid until the next frame is asked for), or (H, W, 3) RGB arrays when `figures.render_state`
    hands back a figure of its own.  Every frame is drawn into ONE figure (`figures._FrameCanvas`):
    its artists replaced, the annotation's text and legend kept and updated."""
    from . import figures
    from .figures import state_source

    fps = _positive("fps", fps)
    n = _frame_count(recording, per, fps)
    if n > max_frames:
        raise ValueError(f"The animation would have {n} frames, more than max_frames = {max_frames}; "
                         "lower fps, use per='step', or raise max_frames")
    if recording.initial_source or any(isinstance(e, SourceSetting) for e in recording.events):
        # the settings given are where the source starts; the recorded ones change it from there
        start = {k: settings.pop(k) for k in SOURCE_SETTINGS if k in settings}
        source = state_source(source, **start)
    prep = {k: settings[k] for k in _PREPARE_KEYS if k in settings}
    cache: list = []
    canvas = figures._FrameCanvas()  # one figure for every frame
    if isinstance(frame, str) and frame == "fit":  # pass 1: every frame's slice and box
        boxes, kept = [], 0
        for t, state, src in animation_states(recording, initial_state, source, per=per, fps=fps):
            _, data, _, box = figures._prepare(state, src if src is not None else "5-cell", **prep)
            boxes.append(box)
            kept += _data_bytes(data)
            cache.append(data if kept <= _SLICE_CACHE_BYTES else None)
        box = figures.union_extent(boxes)
        frame = "camera" if box is None else box
    for k, (t, state, src) in enumerate(animation_states(recording, initial_state, source, per=per, fps=fps)):
        title = titles(k, t, state) if titles is not None else None
        note = f"t = {t:.2f} s, frame {k + 1}/{n}" if annotate else False
        drawn = src if src is not None else "5-cell"
        extra = {}
        if k < len(cache) and cache[k] is not None:
            extra["_prepared"] = figures._prepare(state, drawn, data=cache[k], **prep)
            cache[k] = None  # drawn once: let it go
        fig = figures.render_state(state, drawn, title=title, frame=frame, annotate=note, _canvas=canvas, **extra,
                                   **settings)
        yield canvas.rgba() if fig is canvas.fig else _figure_rgb(fig)


def _as_rgb(frame) -> np.ndarray:
    """A frame of `_frames` as its own (H, W, 3) uint8 array."""
    f = np.asarray(frame)
    return f[..., :3].copy() if f.shape[-1] == 4 else f


def _pil_rgb(frame):
    """A frame of `_frames` as a Pillow RGB image of its own (Pillow drops the alpha in C)."""
    from PIL import Image

    f = np.asarray(frame)
    if f.shape[-1] == 4 and f.flags.c_contiguous:
        h, w = f.shape[:2]
        return Image.frombuffer("RGBA", (w, h), f, "raw", "RGBA", 0, 1).convert("RGB")
    return Image.fromarray(np.ascontiguousarray(f[..., :3]))


def _progress_sink(progress, total: int):
    """``(update(done), close())`` for render_animation's ``progress=`` (True, False or a callable)."""
    if progress is True:
        from ..core.progress import progress as make_progress

        bar = make_progress(total, "rendering frames")
        return (lambda done: bar.update(done - bar.count)), bar.close
    if progress is False or progress is None:
        return (lambda done: None), (lambda: None)
    if callable(progress):
        return (lambda done: progress(done, total)), (lambda: None)
    raise TypeError(f"Expected `progress` to be True, False or a callable (done, total), got {progress!r}")


def render_animation(recording: Recording, initial_state=None, source="5-cell", path=None, *,
                     fps: float = 10.0, per: str = "step", max_frames: int = 3000, titles=None,
                     frame="fit", annotate=True, progress=True, **settings) -> int:
    """Draw ``recording`` (from ``initial_state``, default its own start) of ``source`` into ``path``.

    ``.gif``: an animated GIF (Pillow), looping, 1/fps s per frame (Pillow merges identical
    consecutive frames into one longer frame; each frame gets its own 256-colour palette, fast
    octree); ``.mp4``: H.264 (imageio with imageio-ffmpeg's ffmpeg), ``fps`` frames per second,
    streamed to ffmpeg as they are drawn.  One frame per step (``per="step"``, plus the
    starting state) or per 1/``fps`` s of the recorded time (``per="time"``).  ``settings``
    are `rot4d_widget.keep.figures.render_state`'s (``size=(w, h)`` pixels, ``dpi``, ``levels``,
    ``slices``, ``color_by`` ...; an MP4's size is rounded up to even numbers of pixels).
    ``frame`` and ``annotate`` as `render_frames` (default: every frame framed alike to fill
    the picture, and annotated).  ``progress``: True (default) shows a progress bar
    (`rot4d_widget.view.progress`: a widget in a notebook, a line on a terminal's stderr, only after
    a second), False nothing, a callable ``progress(done, total)`` is called after each frame.
    Returns the number of frames drawn.
    """
    if path is None:
        raise TypeError("Expected `path`, a file name ending in .gif or .mp4")
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in ANIMATION_FORMATS:
        raise ValueError(f"Expected `path` to end in one of {', '.join(ANIMATION_FORMATS)}, got {os.fspath(path)!r}")
    fps = _positive("fps", fps)
    total = _frame_count(recording, per, fps)
    update, close = _progress_sink(progress, total)
    frames = _frames(recording, initial_state, source, per=per, fps=fps, max_frames=max_frames,
                     titles=titles, frame=frame, annotate=annotate, **settings)
    count = 0
    # The file is written by a thread of its own while the next frame is drawn: Pillow's quantizing,
    # its GIF frame differences and the pipe to ffmpeg let go of the GIL; drawing holds it.
    encoder = _Encoder(_write_gif if ext == ".gif" else _write_mp4, os.fspath(path), fps)
    try:
        for f in frames:
            encoder.put(_pil_rgb(f))  # a copy: the canvas is drawn over for the next frame
            count += 1
            update(count)
        encoder.finish()
        return count
    finally:
        encoder.abort()
        close()


class _Encoding(Exception):
    """The frames stopped coming (an error while drawing): the encoder gives up the file."""


class _Encoder:
    """``write(path, fps, images)`` run in a thread, fed frame by frame through a short queue
    (`put`, then `finish`, which waits for the file and raises what the writer raised)."""

    _END = object()

    def __init__(self, write, path, fps, depth: int = 4):
        import queue
        import threading

        self._queue = queue.Queue(depth)
        self._error = None
        self._aborted = False
        self._thread = threading.Thread(target=self._run, args=(write, path, fps), name="rot4d-encoder",
                                        daemon=True)
        self._thread.start()

    def _images(self):
        while True:
            item = self._queue.get()
            if self._aborted:
                raise _Encoding("the frames stopped")
            if item is self._END:
                return
            yield item

    def _run(self, write, path, fps):
        try:
            write(path, fps, self._images())
        except BaseException as e:  # handed to the drawing thread by put / finish
            self._error = e
            while True:  # unblock a put waiting on a full queue
                try:
                    self._queue.get_nowait()
                except Exception:
                    break

    def _check(self):
        if self._error is not None and not isinstance(self._error, _Encoding):
            raise self._error

    def put(self, item) -> None:
        import queue

        while True:
            self._check()
            if not self._thread.is_alive():
                raise RuntimeError("the animation's encoder stopped before the last frame")
            try:
                self._queue.put(item, timeout=0.05)
                return
            except queue.Full:
                continue

    def finish(self) -> None:
        self.put(self._END)
        self._thread.join()
        self._check()

    def abort(self) -> None:
        """After an error while drawing (no-op after `finish`): the writer stops without a file."""
        if not self._thread.is_alive():
            return
        self._aborted = True
        try:
            self._queue.put(self._END, timeout=1.0)
        except Exception:
            pass
        self._thread.join(timeout=10.0)


def _write_gif(path, fps, images) -> None:
    """An animated GIF from RGB images as they come: each quantized to 256 colours (fast octree)
    and handed to Pillow's writer, which compares each frame with the one before as it goes."""
    from PIL import Image

    def quantized():
        for im in images:
            yield im.quantize(256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)

    frames = quantized()
    first = next(frames, None)
    if first is None:
        return
    first.save(path, save_all=True, append_images=frames, duration=round(1000.0 / fps), loop=0)


def _write_mp4(path, fps, images) -> None:
    """H.264 (imageio with imageio-ffmpeg's ffmpeg) from RGB images, streamed as they come."""
    import imageio.v2 as imageio

    with imageio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                            pixelformat="yuv420p", macro_block_size=1, ffmpeg_log_level="error") as writer:
        for im in images:
            f = np.asarray(im)
            h, w = f.shape[:2]
            if h % 2 or w % 2:  # yuv420p needs even sizes: repeat the last row / column
                f = np.pad(f, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
            writer.append_data(f)


# ============================================================================ the paper's figures
def paper_recording(figure: int, frames: int = 16, fps: float = 4.0) -> tuple:
    """``(recording, source)`` of the paper's Fig. 3 (key "4", R_xw, theta0 = pi/16) or Fig. 4
    (key "z", R_xz,yw, alpha = pi sqrt2 / (8 sqrt3), beta = 1 - alpha) on the a = 2 pentachoron:
    ``frames - 1`` presses 1/fps s apart, the sequences of `figures.paper_figure_3` / ``_4``
    (frame k is panel k)."""
    from .figures import FIG3_THETA0, FIG4_ALPHA, FIG4_THETA0
    from ..geometry.polytopes import pentachoron
    from ..sources.protocol import PolytopeSource

    if figure == 3:
        state, key = RotationState(theta0=FIG3_THETA0), "4"
    elif figure == 4:
        state, key = RotationState(theta0=FIG4_THETA0, alpha=FIG4_ALPHA), "z"
    else:
        raise ValueError(f"Expected `figure` 3 or 4 (the paper's key sequences), got {figure!r}")
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise ValueError(f"Expected `frames` to be an int >= 2, got {frames!r}")
    fps = _positive("fps", fps)
    rec = Recorder(state, clock=lambda: 0.0)
    action, inverted = state.keymap.resolve(key)
    for k in range(1, frames):
        rec.record(key, False, action, inverted, t=k / fps)
    return rec.recording(), PolytopeSource(pentachoron(2.0))


def paper_animation(figure: int, path, *, frames: int = 16, fps: float = 4.0, size=(400, 400), dpi: float = 100,
                    labels: bool = True, **settings) -> int:
    """The paper's Fig. 3 or 4 as an animation (GIF or MP4 by ``path``'s extension): frame k is the
    figure's panel k, labelled (a), (b) ... like its panels when ``labels``.  Returns the number of
    frames (``frames``)."""
    import string

    rec, src = paper_recording(figure, frames, fps)
    key = rec.events[0].key

    def title(k, t, state):
        letter = f"({string.ascii_lowercase[k]})" if k < 26 else f"({k + 1})"
        return f"Fig. {figure} {letter}: key \u201c{key}\u201d \u00d7 {k}"

    return render_animation(rec, None, src, path, fps=fps, per="step", size=size, dpi=dpi,
                            titles=title if labels else None, **settings)
