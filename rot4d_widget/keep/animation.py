"""Recordings drawn as animations: the frames' states, the frames, a GIF or an MP4.

`render_animation` draws a recording with `rot4d_widget.keep.pictures.state_picture.render_state` -- one frame
per step, or one per 1/fps seconds of the recorded time -- into an animated GIF (Pillow) or an
MP4 (imageio with imageio-ffmpeg's ffmpeg).  `paper_animation(3)` / `paper_animation(4)` are
the paper's Figs. 3 and 4 (the key sequences of `panels.paper_figure_3` / ``_4``) as animations.
The recordings themselves are `rot4d_widget.keep.recorder`'s.
"""

from __future__ import annotations

import copy
import inspect
import math
import os
import queue
import string
import threading
from numbers import Real
from typing import Iterator

import numpy as np

from ..core.progress import progress as make_progress
from ..core.state import RotationState
from ..geometry.regular import pentachoron
from ..sources.protocol import PolytopeSource, as_source, note_matrix
from .recorder import (
    SOURCE_SETTINGS,
    VIEW_SETTINGS,
    Recorder,
    Recording,
    SourceSetting,
    apply_event,
    with_source_setting,
)

ANIMATION_FORMATS = (".gif", ".mp4")


# ============================================================================ animations
def _own_copy(source):
    """A copy of ``source`` that replaying its own actions may change (the original stays): the
    protocol's copy semantics, ``copy.copy`` (a stack copies its inner source too)."""
    return copy.copy(as_source(source))


def animation_states(recording: Recording, initial_state: RotationState | None = None, source=None, *,
                     per: str = "step", fps: float = 10.0) -> Iterator[tuple]:
    """``(t, state, source)`` for each frame: after each step (``per="step"``, the first frame the
    starting state) or at t = k / fps over the recorded time (``per="time"``: the state after every
    event up to t).  ``state`` and ``source`` are the same objects every time, changed in place
    (but a recorded ``slices`` on a single view makes the source a new `StackSource` around it,
    as the widget does): draw them before taking the next.  ``initial_state``: start there
    instead of the recording's starting state (its copy is used).  ``source`` is copied before
    its own actions and the recorded source settings change it."""
    for t, state, src, _view in _steps(recording, initial_state, source, per=per, fps=fps):
        yield t, state, src


def _steps(recording: Recording, initial_state=None, source=None, *, per: str = "step", fps: float = 10.0):
    """`animation_states`' frames with the view settings in effect at each: ``(t, state, source,
    view)``, ``view`` a dict (`Recording.initial_view`, then each recorded `ViewSetting` up to
    the frame; the same dict every time, changed in place)."""
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
        note_matrix(src, state.matrix)  # as the widget tells its source: a default spacing along today's w
        src = with_source_setting(src, name, value)
        note_matrix(src, state.matrix)

    setter = None if src is None else set_source
    if src is not None:
        for e in recording.start_settings():
            set_source(e.name, e.value)
    view = recording.initial_view
    set_view = view.__setitem__
    events = recording.events
    yield 0.0, state, src, view
    if per == "step":
        for e in events:
            apply_event(state, e, src, setter, set_view)
            yield e.t, state, src, view
        return
    n = _frame_count(recording, "time", fps)
    i = 0
    for k in range(1, n):
        t = k / fps
        while i < len(events) and events[i].t <= t + 1e-9:
            apply_event(state, events[i], src, setter, set_view)
            i += 1
        yield t, state, src, view


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
    # matplotlib: imported when a figure is drawn
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


#: Slices kept from the framing pass for the drawing pass, in bytes (beyond it they are recomputed).
_SLICE_CACHE_BYTES = 256 * 2**20
_PREPARE_KEYS = ("levels", "inside", "caps", "slices", "spacing", "arrangement", "ball_radius", "show_balls")


def _data_bytes(data) -> int:
    """The bytes of a stack's slice (`SliceData`) kept: its arrays."""
    return sum(0 if a is None else int(np.asarray(a).nbytes)
               for a in (data.points, data.segments, data.triangles, data.groups, data.normals))


def render_frames(recording: Recording, initial_state=None, source="5-cell", *, per: str = "step",
                  fps: float = 10.0, max_frames: int = 3000, titles=None, frame="fit", annotate=True,
                  **settings) -> Iterator[np.ndarray]:
    """The frames of `render_animation`, one (H, W, 3) uint8 array at a time.

    ``settings`` go to `rot4d_widget.keep.pictures.state_picture.render_state` (``size``, ``dpi``, ``levels``,
    ``slices``, ``color_by`` ...).  ``titles``: a callable ``(k, t, state) -> str`` giving each
    frame a title, or None.  More than ``max_frames`` frames raises ``ValueError`` before any is drawn.
    When the recording has source settings (``levels``, ``slices``, ``spacing``,
    ``arrangement``: its `Recording.initial_source` or recorded ones), those keywords are the
    source's settings at the start unless ``initial_source`` has them, and each frame shows them
    as recorded up to it.  Likewise the view settings (``rendering``, ``cmap``, ``clim``,
    ``sections``): the keywords are where the frames start unless `Recording.initial_view` has
    them, and each frame is drawn with those recorded up to it (``sections`` only where
    `render_state` takes it).

    ``frame="fit"`` (default): every frame is framed alike, by the union of the projected
    bounding boxes of all frames' slices (`framing.frame_extent`), which fills 90 % of the
    picture's width or height -- the slices are computed once for this, in a first pass, and
    kept for drawing (up to 256 MB); ``"camera"`` or a box as `render_state`.  ``annotate``
    (default True): each frame carries "frame k/n", θ0, c0 in the data's units, the turn
    (`framing.turn_text`: how far the cut is turned from the data's own w) and what the source tells
    of itself (`framing.annotation`), and a legend; False for a bare picture.
    """
    for f in _frames(recording, initial_state, source, per=per, fps=fps, max_frames=max_frames, titles=titles,
                     frame=frame, annotate=annotate, **settings):
        yield _as_rgb(f)


def _frames(recording: Recording, initial_state=None, source="5-cell", *, per: str = "step", fps: float = 10.0,
            max_frames: int = 3000, titles=None, frame="fit", annotate=True, **settings) -> Iterator[np.ndarray]:
    """`render_frames`' frames as they are drawn: (H, W, 4) uint8 RGBA views of one reused canvas
    (valid until the next frame is asked for), or (H, W, 3) RGB arrays when `state_picture.render_state`
    hands back a figure of its own.  Every frame is drawn into ONE figure (`canvas.FrameCanvas`):
    its artists replaced, the annotation's text and legend kept and updated."""
    # the pictures import matplotlib: imported when a frame is drawn, not with the recordings.
    # render_state and prepare_render are looked up on their module at each call, so that replacing
    # `state_picture.render_state` (a test) reaches every frame
    from .pictures import state_picture
    from .pictures.canvas import FrameCanvas
    from .pictures.framing import union_extent
    from .pictures.state_picture import state_source

    fps = _positive("fps", fps)
    n = _frame_count(recording, per, fps)
    if n > max_frames:
        raise ValueError(f"The animation would have {n} frames, more than max_frames = {max_frames}; "
                         "lower fps, use per='step', or raise max_frames")
    if recording.initial_source or any(isinstance(e, SourceSetting) for e in recording.events):
        # the settings given are where the source starts; the recorded ones change it from there
        start = {k: settings.pop(k) for k in SOURCE_SETTINGS if k in settings}
        source = state_source(source, **start)
    # the view settings given are where the frames start; the recorded ones change them from there
    start_view = {k: settings.pop(k) for k in VIEW_SETTINGS if k in settings}
    takes = inspect.signature(state_picture.render_state).parameters  # a recorded `sections` only where taken
    prep = {k: settings[k] for k in _PREPARE_KEYS if k in settings}
    cache: list = []
    canvas = FrameCanvas()  # one figure for every frame
    if isinstance(frame, str) and frame == "fit":  # pass 1: every frame's slice and box
        boxes, kept = [], 0
        for _t, state, src, view in _steps(recording, initial_state, source, per=per, fps=fps):
            _, data, _, box = state_picture.prepare_render(state, src if src is not None else "5-cell", **prep,
                                               rendering={**start_view, **view}.get("rendering", "surface"),
                                               eye=settings.get("eye"))
            boxes.append(box)
            kept += _data_bytes(data)
            cache.append(data if kept <= _SLICE_CACHE_BYTES else None)
        box = union_extent(boxes)
        frame = "camera" if box is None else box
    for k, (t, state, src, view) in enumerate(_steps(recording, initial_state, source, per=per, fps=fps)):
        title = titles(k, t, state) if titles is not None else None
        note = f"frame {k + 1}/{n}" if annotate else False  # c0 and the turn follow (`framing.annotation`)
        drawn = src if src is not None else "5-cell"
        extra = {}
        if k < len(cache) and cache[k] is not None:
            extra["_prepared"] = state_picture.prepare_render(state, drawn, data=cache[k], **prep,
                                                  rendering={**start_view, **view}.get("rendering", "surface"),
                                                  eye=settings.get("eye"))
            cache[k] = None  # drawn once: let it go
        look_now = {**start_view, **{n: v for n, v in view.items() if n in takes}}
        fig = state_picture.render_state(state, drawn, title=title, frame=frame, annotate=note, _canvas=canvas, **extra,
                                   **look_now, **settings)
        yield canvas.rgba() if fig is canvas.fig else _figure_rgb(fig)


def _as_rgb(frame) -> np.ndarray:
    """A frame of `_frames` as its own (H, W, 3) uint8 array."""
    f = np.asarray(frame)
    return f[..., :3].copy() if f.shape[-1] == 4 else f


def _pil_rgb(frame):
    """A frame of `_frames` as a Pillow RGB image of its own (Pillow drops the alpha in C)."""
    # Pillow: imported when a frame is encoded
    from PIL import Image

    f = np.asarray(frame)
    if f.shape[-1] == 4 and f.flags.c_contiguous:
        h, w = f.shape[:2]
        return Image.frombuffer("RGBA", (w, h), f, "raw", "RGBA", 0, 1).convert("RGB")
    return Image.fromarray(np.ascontiguousarray(f[..., :3]))


def _progress_sink(progress, total: int):
    """``(update(done), close())`` for render_animation's ``progress=`` (True, False or a callable)."""
    if progress is True:
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
    are `rot4d_widget.keep.pictures.state_picture.render_state`'s (``size=(w, h)`` pixels, ``dpi``, ``levels``,
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
    # Pillow: imported when a GIF is written
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
    # imageio (optional, with imageio-ffmpeg): imported when an MP4 is written
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
    ``frames - 1`` presses 1/fps s apart, the sequences of `panels.paper_figure_3` / ``_4``
    (frame k is panel k)."""
    # drawing imports matplotlib: the paper's constants come with it, only when asked for
    from .pictures.slice_drawing import FIG3_THETA0, FIG4_ALPHA, FIG4_THETA0

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
    rec, src = paper_recording(figure, frames, fps)
    key = rec.events[0].key

    def title(k, t, state):
        letter = f"({string.ascii_lowercase[k]})" if k < 26 else f"({k + 1})"
        return f"Fig. {figure} {letter}: key \u201c{key}\u201d \u00d7 {k}"

    return render_animation(rec, None, src, path, fps=fps, per="step", size=size, dpi=dpi,
                            titles=title if labels else None, **settings)
