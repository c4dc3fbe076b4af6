"""Keeping it: pictures and animations frame the object, can be annotated, and show progress.

Runs against the old code too (``PYTHONPATH=/tmp/old-anim pytest tests/keep/test_keep_render.py``):
the framing test fails there (the object filled about a third of the picture).
"""

import io

import numpy as np
import pytest
from PIL import Image

from rot4d_widget.keep.recorder import Recorder
from rot4d_widget.keep.animation import render_animation, render_frames
from rot4d_widget.core.state import RotationState


def _held_4(steps=6):
    st = RotationState()
    rec = Recorder(st, clock=lambda: 0.0)
    action, inverted = st.keymap.resolve("4")
    for k in range(1, steps + 1):
        rec.record("4", False, action, inverted, t=k / 30)
    return rec.recording()


def _filled(rgb, background=(1.0, 1.0, 1.0)):
    """Width and height of the bounding box of non-background pixels, as fractions."""
    rgb = np.asarray(rgb, dtype=np.float64)
    if rgb.max() > 1.0:
        rgb = rgb / 255.0
    drawn = np.abs(rgb[..., :3] - np.asarray(background)).max(axis=2) > 0.05
    rows, cols = np.nonzero(drawn)
    h, w = drawn.shape
    return (cols.max() - cols.min() + 1) / w, (rows.max() - rows.min() + 1) / h


@pytest.mark.parametrize("source", ["24-cell", "5-cell"])
def test_render_state_fills_most_of_the_picture(tmp_path, source):
    from rot4d_widget.keep.pictures.state_picture import render_state

    path = tmp_path / "v.png"
    render_state(RotationState(c0=0.1), source, path, size=(600, 500), dpi=100)
    fw, fh = _filled(np.asarray(Image.open(path).convert("RGB")))
    # the object's box reaches across most of the width or the height (old code: about a third)
    assert max(fw * 600, fh * 500) > 0.6 * 500
    assert max(fw, fh) > 0.8


def test_animation_frames_fill_the_picture_and_keep_one_frame(tmp_path):
    rec = _held_4(8)
    frames = list(render_frames(rec, None, "24-cell", size=(300, 250), dpi=50))
    assert len(frames) == len(rec) + 1  # per="step": the start and one per step, as before
    boxes = [_filled(f) for f in frames]
    assert max(max(w, h) for w, h in boxes) > 0.8


def test_annotation_is_written_when_asked(tmp_path):
    from rot4d_widget.sources import datasets
    from rot4d_widget.keep.pictures.state_picture import render_state

    st = RotationState(theta0=np.pi / 16, c0=0.25)
    fig = render_state(st, "24-cell", annotate=True, size=(300, 250), dpi=50)
    text = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "c0 = +0.25" in text and "\u03c0/16" in text
    plain = render_state(st, "24-cell", size=(300, 250), dpi=50)
    assert not any(t.get_gid() == "annotation" for ax in plain.axes for t in ax.texts)
    # a field: its name, its level with units and a legend, read from the source's attributes
    f = datasets.moving_sphere(resolution=16)
    f.units = "K"
    buf = io.BytesIO()
    fig = render_state(st, f, annotate="hello", size=(300, 250), dpi=50)
    fig.savefig(buf, format="svg")
    svg = buf.getvalue().decode()
    assert "hello" in svg and "level 0 K" in svg and "w cut" in svg
    assert fig.axes[0].get_legend() is not None
    # a stack: the slices' w and their colours
    fig = render_state(RotationState(), "24-cell", slices=3, spacing=0.3, annotate=True, size=(300, 250), dpi=50)
    text = " ".join(t.get_text() for t in fig.axes[0].texts)
    assert "3 slices w = -0.3" in text
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["w = -0.3", "w = +0", "w = +0.3"]


def test_progress_callback_counts_up_to_the_frames(tmp_path):
    rec = _held_4(5)
    seen = []
    n = render_animation(rec, None, "5-cell", tmp_path / "a.gif", size=(120, 100), dpi=40,
                         progress=lambda done, total: seen.append((done, total)))
    assert n == len(rec) + 1
    assert [d for d, _ in seen] == list(range(1, n + 1)) and {t for _, t in seen} == {n}
    with pytest.raises(TypeError, match="progress"):
        render_animation(rec, None, "5-cell", tmp_path / "b.gif", progress="yes")


def test_progress_shows_only_after_a_second_and_only_on_a_terminal():
    from rot4d_widget.core.progress import progress

    class Tty(io.StringIO):
        def isatty(self):
            return True

    now = [0.0]
    out = Tty()
    bar = progress(10, "work", file=out, clock=lambda: now[0])
    assert bar.mode == "text"
    bar.update(3)
    assert out.getvalue() == ""  # quick work stays silent
    now[0] = 1.5
    bar.update(2)
    assert "5/10" in out.getvalue() and "work" in out.getvalue()
    bar.close()
    assert out.getvalue().endswith("\n") and bar.count == 5
    piped = progress(10, file=io.StringIO(), clock=lambda: now[0] + 5)
    assert piped.mode == "none"
    with pytest.raises(ValueError, match="total"):
        progress(-1)


def test_progress_does_not_import_pythreejs():
    import subprocess
    import sys

    code = "import sys, rot4d_widget.core.progress; print('pythreejs' in sys.modules, 'ipywidgets' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


# -- the animation's fast path draws what render_state draws ----------------------------------------------

def test_one_collection_per_slice_holds_draw_slices_patches_in_their_order():
    """`slice_drawing.slice_collection` (animations) has draw_slice's paths, colours and edges, in the
    order matplotlib would paint draw_slice's patches (by zorder, ties in the order added)."""
    from matplotlib.figure import Figure

    from rot4d_widget.core import colours
    from rot4d_widget.keep.pictures import panels, slice_drawing
    from rot4d_widget.geometry.catalogue import polytope
    from rot4d_widget.core.rotation import random_rotation
    from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope

    p = polytope("24-cell")
    s = slice_polytope(p, random_rotation(np.random.default_rng(3)), 0.1)
    style = panels.panel_style(p)
    ax = Figure().add_subplot()
    d = slice_drawing.draw_slice(ax, s, **style)
    patches = [a for a in ax.get_children() if a in {*d.faces, *d.bars, *d.balls, *d.highlights}]
    patches.sort(key=lambda a: a.get_zorder())  # stable: matplotlib's painting order
    coll = slice_drawing.slice_collection(s, scale=style["scale"], ball_radius=style["ball_radius"],
                                     bar_radius=style["bar_radius"], face_alpha=colours.FACE_OPACITY)
    paths = coll.get_paths()
    assert len(paths) == len(patches) == len(s.polygons) + len(s.edges) + 2 * len(s.vertices)
    for k, (patch, path) in enumerate(zip(patches, paths)):
        want = patch.get_patch_transform().transform_path(patch.get_path())
        np.testing.assert_allclose(path.vertices, want.vertices, atol=1e-12)
        np.testing.assert_allclose(coll.get_facecolor()[k], patch.get_facecolor(), atol=1e-12)
        edge = patch.get_edgecolor() if patch.get_edgecolor()[3] else (0, 0, 0, 0)
        np.testing.assert_allclose(coll.get_edgecolor()[k], edge, atol=1e-12)
        lw = patch.get_linewidth() if patch.get_edgecolor()[3] else 0.0
        assert coll.get_linewidth()[k] == pytest.approx(lw)
    np.testing.assert_allclose(coll.items_zorder, [a.get_zorder() for a in patches], atol=1e-9)


@pytest.mark.parametrize("source", ["24-cell", "field"])
def test_animation_frames_are_render_states_pictures(source):
    """Frames drawn into the one reused canvas equal render_state's picture of the same state,
    framing and annotation (text is blended from cached pictures: equal up to rounding)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from rot4d_widget.keep.pictures import framing, state_picture
    from rot4d_widget.sources import datasets
    from rot4d_widget.keep.animation import animation_states

    rec = _held_4(4)
    src = datasets.moving_sphere(resolution=16) if source == "field" else source
    frames = list(render_frames(rec, None, src, size=(240, 200), dpi=40, titles=lambda k, t, s: f"frame {k}"))
    boxes = [state_picture.prepare_render(st, s if s is not None else src)[3]
             for _, st, s in animation_states(rec, None, src)]
    box = framing.union_extent(boxes)
    for k, (t, st, s) in enumerate(animation_states(rec, None, src)):
        fig = state_picture.render_state(st, s if s is not None else src, size=(240, 200), dpi=40, frame=box,
                                   title=f"frame {k}", annotate=f"frame {k + 1}/{len(frames)}")
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        want = np.asarray(canvas.buffer_rgba())[..., :3].astype(int)
        assert frames[k].shape == want.shape
        assert np.abs(frames[k].astype(int) - want).max() <= 2


def test_an_error_while_drawing_leaves_no_gif_and_no_encoder(tmp_path, monkeypatch):
    import threading

    from rot4d_widget.keep.pictures import state_picture

    real, calls = state_picture.render_state, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise RuntimeError("boom")
        return real(*args, **kwargs)

    monkeypatch.setattr(state_picture, "render_state", failing)
    path = tmp_path / "a.gif"
    with pytest.raises(RuntimeError, match="boom"):
        render_animation(_held_4(5), None, "5-cell", path, size=(120, 100), dpi=40, progress=False)
    assert not path.exists()
    assert not any(t.name == "rot4d-encoder" for t in threading.enumerate())
    # and the writer's own errors reach the caller
    with pytest.raises(OSError):
        render_animation(_held_4(2), None, "5-cell", tmp_path / "no" / "such" / "dir.gif", size=(120, 100),
                         dpi=40, progress=False)


def test_in_a_kernel_the_bar_the_view_registered_is_shown(monkeypatch):
    from rot4d_widget.core import progress as core_progress

    shown = []

    class Bar:
        def __init__(self, total, description):
            shown.append(("new", total, description))

        def show(self, count, text):
            shown.append(("show", count))

        def close(self, done):
            shown.append(("close", done))

    monkeypatch.setattr(core_progress, "in_kernel", lambda: True)
    monkeypatch.setattr(core_progress, "_widget_bar", None)
    assert core_progress.progress(3).mode == "none"  # nothing registered: no bar, no error
    core_progress.register_widget_bar(Bar)
    now = [0.0]
    bar = core_progress.progress(3, "work", clock=lambda: now[0])
    assert bar.mode == "widget"
    bar.update()
    now[0] = 2.0
    bar.update(2)
    bar.close()
    assert shown == [("new", 3, "work"), ("show", 3), ("show", 3), ("close", True)]
    with pytest.raises(TypeError, match="callable"):
        core_progress.register_widget_bar("bar")
