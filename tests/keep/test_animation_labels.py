"""An animation's frames say the cut's c0 in the data's units and how far it is turned, at full
resolution, with nothing over the data (issue 37, problem 4).

Eight taps of 4 on a flame-like field (T in K, 1-4 ms) drawn as frames: each frame's annotation
(its figure, caught as `render_frames` draws it) reads "frame k/9", c0 in seconds and the turn
("turn 22.5° in the x-w plane" after 8 taps: 8 pi/64), never the seconds since the recording began;
a ray-cast frame is cast with a ray through every pixel (the frame's image equals `render_grid`'s
with ``pixels_per_ray=1``); the annotation's text and the box labels lie outside the rectangle the
box's cut projects into, and apart.  The speed is measured by ``benchmarks/animation.py --rev``.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_labels import flame

from rot4d_widget.core.sizes import REFERENCE_RADIUS
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.pictures import state_picture
from rot4d_widget.keep.pictures.slice_drawing import perspective
from rot4d_widget.keep.recorder import Recorder
from rot4d_widget.keep.animation import render_frames
from rot4d_widget.keep.pictures.ray_caster import render_grid


def _recording():
    st = RotationState(c0=0.0025, c0_step=1e-4)
    rec = Recorder(st, clock=lambda: 0.0)
    action, inverted = st.keymap.resolve("4")
    for k in range(1, 9):
        rec.record("4", False, action, inverted, t=k * 3.3)  # recorded seconds: not the data's time
    return rec.recording()


def _frames(rendering, monkeypatch):
    """Each frame's figure-level facts: (annotation text, label window boxes, annotation box, axes, state)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    seen = []
    real = state_picture.render_state

    def caught(state, source, *args, **kwargs):
        fig = real(state, source, *args, **kwargs)
        canvas = FigureCanvasAgg(fig) if fig.canvas is None or not hasattr(fig.canvas, "get_renderer") else fig.canvas
        canvas.draw()
        r = canvas.get_renderer()
        ax = fig.axes[0]
        note = [t for t in ax.texts if t.get_gid() == "annotation"]
        labels = [t.get_bbox_patch().get_window_extent(r) for t in ax.texts if t.get_gid() == "box-label"]
        images = [np.asarray(im.get_array()).copy() for im in ax.images if im.get_gid() == rendering]
        seen.append((note[0].get_text(), labels, note[0].get_bbox_patch().get_window_extent(r), ax,
                     state.copy(), images, (ax.get_xlim(), ax.get_ylim())))
        return fig

    monkeypatch.setattr(state_picture, "render_state", caught)
    f = flame()
    frames = list(render_frames(_recording(), None, f, rendering=rendering, size=(300, 250), dpi=100))
    return f, frames, seen


@pytest.mark.parametrize("rendering", ["surface", "mip"])
def test_each_frame_names_c0_in_seconds_and_the_turn(rendering, monkeypatch):
    f, frames, seen = _frames(rendering, monkeypatch)
    assert len(frames) == len(seen) == 9
    for k, (text, *_rest) in enumerate(seen):
        assert text.splitlines()[0] == f"frame {k + 1}/9", text
        assert "c0 = +0.0025 s" in text and "t = " not in text, text
    assert "turn none (the cut is at constant w)" in seen[0][0]
    assert "turn 22.5\u00b0 in the x\u2013w plane" in seen[8][0], seen[8][0]
    if rendering != "surface":
        assert "level" not in seen[8][0]  # no level is drawn: the annotation says what is


@pytest.mark.parametrize("rendering", ["volume", "mip", "sections"])
def test_frames_are_cast_at_full_resolution_and_nothing_covers_the_data(rendering, monkeypatch):
    f, frames, seen = _frames(rendering, monkeypatch)
    text, labels, note, ax, st, images, (xlim, ylim) = seen[-1]
    g = f.sample(st.matrix, st.c0)
    from rot4d_widget.core import camera
    from rot4d_widget.core.camera import view_rotation

    want = render_grid(g, rendering, size=(300, 250), limits=(xlim, ylim), cmap="viridis",
                       scale=REFERENCE_RADIUS / f.size, pixels_per_ray=1, progress=False,
                       view=view_rotation(camera.default_eye(rendering)))
    np.testing.assert_allclose(images[0], want, atol=1e-12)
    box = f.outline(st.matrix, st.c0)
    from rot4d_widget.core.camera import view_rotation as vr

    pts = np.asarray(box.points)[np.unique(np.asarray(box.segments))] @ vr(camera.default_eye(rendering)).T
    xy = ax.transData.transform(perspective(pts * (REFERENCE_RADIUS / f.size))[0])
    x0, y0 = xy.min(axis=0)
    x1, y1 = xy.max(axis=0)

    def clear(b):
        return b.x1 <= x0 + 0.5 or b.x0 >= x1 - 0.5 or b.y1 <= y0 + 0.5 or b.y0 >= y1 - 0.5

    assert clear(note), (note, (x0, y0, x1, y1))
    for b in labels:
        assert clear(b), (b, (x0, y0, x1, y1))
        assert b.x1 <= note.x0 or note.x1 <= b.x0 or b.y1 <= note.y0 or note.y1 <= b.y0, (b, note)
