"""What makes a field's animation cheaper draws the same pictures (issue 19).

The speed itself is shown by ``python benchmarks/animation.py`` only; these tests check that the
shortcuts change no pixel and no number: glyphs drawn from kept bitmaps are matplotlib's own
pixels, a surface's shading and painter's order are the ``[tri].mean(axis=1)`` formula's bit for
bit, and kept level colours cannot be changed by whoever receives them.
"""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.font_manager import FontProperties

from rot4d_widget.core import colours, sizes
from rot4d_widget.keep.pictures import framing, slice_drawing, state_picture
from rot4d_widget.keep.pictures.canvas import FrameCanvas, _glyph_caching_renderer
from rot4d_widget.sources import datasets
from rot4d_widget.keep.recorder import Recorder
from rot4d_widget.keep.animation import render_frames
from rot4d_widget.core.state import RotationState

LINES = ["t = 0.03 s, frame 2/33", "\u03b80 = \u03c0/16, c0 = +0.1234", "w cut \u22120.5 \u2026 0.5 s",
         "ball r=0.5 moving at v=0.75", "AVAWAY fij ;:{}|", "level 0 m\u00b3"]


def _glyph_renderer():
    cls = _glyph_caching_renderer()
    if not cls.glyphs_cached:
        pytest.skip("this matplotlib does not draw text glyph by glyph (3.11+)")
    return cls


def _draw_lines(renderer, rng_seed, antialiased=True):
    rng = np.random.default_rng(rng_seed)
    for k in range(120):
        prop = FontProperties(size=float(rng.choice([6.0, 7.5, 9.0, 10.0, 13.3])),
                              weight="bold" if k % 5 == 0 else "normal")
        gc = renderer.new_gc()
        gc.set_foreground((0.1, 0.2 * (k % 3), 0.3), isRGBA=False)
        gc.set_alpha(1.0 if k % 4 else 0.6)
        gc.set_antialiased(antialiased)
        # fractional pen positions: the glyphs' sub-pixel offsets vary, and repeat
        x, y = float(rng.uniform(0, 400)), float(rng.uniform(20, 280))
        renderer.draw_text(gc, x, y, LINES[k % len(LINES)], prop, 0.0)
        gc.restore()


@pytest.mark.parametrize("antialiased", [True, False])
def test_glyphs_from_kept_bitmaps_are_matplotlibs_own_pixels(antialiased):
    cls = _glyph_renderer()
    cached, plain = cls(500, 300, 100), RendererAgg(500, 300, 100)
    for r in (cached, plain):
        _draw_lines(r, 7, antialiased)
        _draw_lines(r, 7, antialiased)  # the same lines again: now every glyph comes from the kept bitmaps
    got, want = np.asarray(cached.buffer_rgba()), np.asarray(plain.buffer_rgba())
    assert want[..., 3].any()
    np.testing.assert_array_equal(got, want)
    # the kept bitmaps were used: far fewer were rendered than glyphs drawn (~20 a line, 480 lines)
    assert 0 < len(cached._glyphs) < 2000


def test_glyph_cache_is_keyed_by_the_sub_pixel_offset():
    """A glyph at a fractional pen position is a different bitmap: one drawn from the bitmap kept
    for another offset would differ (this is what the key must hold apart)."""
    cls = _glyph_renderer()
    prop = FontProperties(size=9.0)
    a = cls(120, 40, 100)
    for x in (10.0, 10.25, 10.5, 10.75):
        gc = a.new_gc()
        a.draw_text(gc, x, 30.0, "a", prop, 0.0)
        gc.restore()
    offsets = {key[6] for key in a._glyphs}
    assert len(offsets) == 4  # four quarter-pixel pens, four bitmaps (16, 32, 48, 0 in 1/64 pixel)
    bitmaps = [v[0] for v in a._glyphs.values()]
    assert not all(np.array_equal(bitmaps[0], b) for b in bitmaps[1:])


def _held_4(steps):
    st = RotationState()
    rec = Recorder(st, clock=lambda: 0.0)
    action, inverted = st.keymap.resolve("4")
    for k in range(1, steps + 1):
        rec.record("4", False, action, inverted, t=k / 30)
    return rec.recording()


def test_animation_frames_with_and_without_kept_glyphs_are_identical(monkeypatch):
    """Whole annotated frames (title, annotation, legend): kept glyph bitmaps change no pixel."""
    cls = _glyph_renderer()
    rec, src = _held_4(3), datasets.moving_sphere(resolution=12)
    kw = dict(size=(240, 200), dpi=50, titles=lambda k, t, s: f"frame {k}")
    fast = [f.copy() for f in render_frames(rec, None, src, **kw)]
    monkeypatch.setattr(cls, "_draw_text_glyphs_and_boxes", RendererAgg._draw_text_glyphs_and_boxes)
    slow = [f.copy() for f in render_frames(rec, None, src, **kw)]
    assert len(fast) == len(slow) == 4
    for a, b in zip(fast, slow):
        np.testing.assert_array_equal(a, b)


def _surface_collection(state, source):
    stack, data, _, box = state_picture.prepare_render(state, source)
    canvas = FrameCanvas()
    state_picture.render_state(state, stack, frame=box, _canvas=canvas, _prepared=(stack, data, None, box))
    (coll,) = [c for c in canvas.ax.collections if c.get_gid() == "surface"]
    return stack, data, coll


@pytest.mark.parametrize("levels", [[0.0], [0.0, 0.1]])
def test_surface_shading_and_order_are_the_mean_formulas_bit_for_bit(levels):
    """The triangles' colours (shaded by the mean normal) and their painter's order (mean depth)
    equal those of ``[tri].mean(axis=1)`` and ``np.linalg.norm`` exactly, on a turned field."""
    st = RotationState()
    for key in "44z1":  # turned in xw and beyond: a slanted cut, uneven triangles
        st.press(key)
    stack, data, coll = _surface_collection(st, datasets.moving_sphere(levels=levels))
    scale = sizes.REFERENCE_RADIUS / stack.size
    pts = np.asarray(data.points, dtype=np.float64) * scale
    tri = np.asarray(data.triangles)
    groups = np.asarray(data.groups)
    inner = stack.source
    lo, hi = getattr(inner, "data_range", (min(levels), max(levels)))
    rgb = colours.level_colors(inner.levels, lo, hi)[groups]
    n = np.asarray(data.normals)[tri].mean(axis=1)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    light = np.array([-0.35, 0.45, 0.82])
    rgb = np.clip(rgb * (0.45 + 0.55 * np.abs(n @ (light / np.linalg.norm(light))))[:, None], 0.0, 1.0)
    order = np.argsort(pts[tri].mean(axis=1)[:, 2], kind="stable")
    xy, _ = slice_drawing.perspective(pts)
    assert len(tri) > 100
    np.testing.assert_array_equal(coll._tri_verts, xy[tri[order]])
    np.testing.assert_array_equal(coll._tri_rgba[:, :3], rgb[order])


def test_kept_level_colours_are_look_s_and_read_only():
    got = framing._level_colors((0.0, 0.5, 0.2), -1.0, 1.0)
    np.testing.assert_array_equal(got, colours.level_colors([0.0, 0.5, 0.2], -1.0, 1.0))
    assert framing._level_colors([0.0, 0.5, 0.2], -1, 1) is got  # the same levels: the kept array
    with pytest.raises(ValueError, match="read-only"):
        got[0, 0] = 1.0
    with pytest.raises(ValueError, match="finite"):
        framing._level_colors([float("nan")], 0.0, 1.0)
