"""Recorded key sequences: what was applied, when, replayed and rendered as GIF or MP4.

The names live in two modules, each documented there, and are all importable from here:
`rot4d_widget.keep.recorder` (the events -- steps, settings of the state, the source and the
view --, the immutable `Recording` -- saved as JSON, replayed
bit for bit, never running code it names -- and the widget's hook `Recorder`) and
`rot4d_widget.keep.animation` (`animation_states`, `render_frames`, `render_animation` into a
GIF or MP4, and the paper's Figs. 3 and 4 as animations, `paper_animation`).
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
    VIEW_DEFAULTS,
    VIEW_SETTINGS,
    Recorder,
    Recording,
    Setting,
    SourceSetting,
    Step,
    ViewSetting,
    check_view_setting,
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
    "ViewSetting",
    "VIEW_SETTINGS",
    "VIEW_DEFAULTS",
    "check_view_setting",
    "Recording",
    "Recorder",
    "animation_states",
    "render_frames",
    "render_animation",
    "paper_recording",
    "paper_animation",
]
