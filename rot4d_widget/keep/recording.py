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

The names live in two modules and are all importable from here: `rot4d_widget.keep.recorder`
(the events, `Recording`, `Recorder`) and `rot4d_widget.keep.animation` (`animation_states`,
`render_frames`, `render_animation`, the paper's animations).
"""

from __future__ import annotations

from .animation import (
    ANIMATION_FORMATS,
    animation_states,
    paper_animation,
    paper_recording,
    render_animation,
    render_frames,
)
from .animation import _Encoder as _Encoder
from .animation import _frames as _frames
from .animation import _write_gif as _write_gif
from .animation import _write_mp4 as _write_mp4
from .recorder import (
    MAX_EVENTS,
    RECORDING_FORMAT,
    RECORDING_VERSION,
    SOURCE_SETTINGS,
    Recorder,
    Recording,
    Setting,
    SourceSetting,
    Step,
)
from .recorder import SETTABLE as SETTABLE

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
