"""A field's static render says what its colours mean (issue 21): a colour bar beside the picture
(the colour map over the limits the colours stand for, the variable's name and units, the levels
marked in their surfaces' colours), surfaces coloured along the same map, the box's data
coordinates written at its corners, and a progress bar for a slow volume render."""

from __future__ import annotations

import io

import matplotlib
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from rot4d_widget.core import colours
from rot4d_widget.core import progress as core_progress
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.pictures import ray_caster
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.core.colours import default_clim
from rot4d_widget.keep.pictures.ray_caster import render_grid
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.grid import sample_field

BOX = ((-1.0, 1.0),) * 4


def ball(levels=(0.3, 0.6), **kw):
    return Field4D.from_function(lambda x, y, z, w: 1.0 - (x * x + y * y + z * z) - 0.2 * w, BOX,
                                 resolution=24, levels=levels, **kw)


def pixels(fig):
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].astype(float) / 255.0, canvas


def colorbar(fig):
    bars = [a for a in fig.axes if a.get_gid() == "colorbar"]
    assert len(bars) == 1
    return bars[0]


def test_the_bar_shows_the_map_over_the_limits_with_the_name_and_units():
    f = ball(name="T", units="K")
    state = RotationState()
    size = (240, 200)
    for rendering, clim in (("surface", None), ("surface", (0.1, 0.9)), ("mip", None), ("sections", (-1.0, 2.0))):
        fig = render_state(state, f, rendering=rendering, cmap="plasma", clim=clim, size=size, dpi=50)
        cax = colorbar(fig)
        assert cax.get_ylabel() == "T [K]"
        if clim is None:
            want = f.data_range if rendering == "surface" else default_clim(sample_field(f, np.eye(4), 0.0, 24).values)
        else:
            want = clim
        np.testing.assert_allclose(cax.get_ylim(), want, rtol=1e-6)
        img, canvas = pixels(fig)
        assert img.shape[0] == size[1] and img.shape[1] > size[0]
        # the bar's middle column, bottom to top: the map from 0 to 1
        (x0, y0), (x1, y1) = cax.get_window_extent(canvas.get_renderer()).get_points()
        col = int(round((x0 + x1) / 2))
        h = img.shape[0]
        for frac in (0.1, 0.5, 0.9):
            row = int(round(h - (y0 + frac * (y1 - y0))))
            np.testing.assert_allclose(img[row, col], matplotlib.colormaps["plasma"](frac)[:3], atol=0.03)


def test_long_name_first_then_name_then_value():
    f = ball(name="tas")
    f.long_name = "air temperature"  # xarray's attribute, as a field from xarray keeps it
    f.units = "K"
    assert colorbar(render_state(RotationState(), f, size=(160, 120), dpi=40)).get_ylabel() == "air temperature [K]"
    g = Field4D(np.random.default_rng(0).random((6, 6, 6, 3)), axes="xyzw")  # an array: no name
    assert g.name is None
    assert colorbar(render_state(RotationState(), g, size=(160, 120), dpi=40)).get_ylabel() == "value"


def test_levels_are_marked_in_their_surfaces_colours_and_surfaces_follow_the_map():
    f = ball(levels=(0.3, 0.6))
    state = RotationState()
    for clim in (None, (0.0, 1.0)):
        fig = render_state(state, f, cmap="magma", clim=clim, size=(240, 200), dpi=50, show_bars=False,
                           axis_labels=False)
        cax = colorbar(fig)
        marks = [ln for ln in cax.lines if ln.get_gid() == "level-mark" and ln.get_marker() == ">"]
        assert [m.get_ydata()[0] for m in marks] == [0.3, 0.6]
        lo, hi = f.data_range
        want = (colours.level_colors([0.3, 0.6], lo, hi, "magma") if clim is None
                else colours.level_colors([0.3, 0.6], 0.0, 1.0, "magma", by_value=True))
        np.testing.assert_allclose([matplotlib.colors.to_rgb(m.get_color()) for m in marks], want, atol=1e-9)
        # one level alone is opaque: the surface at the picture's centre has its colour, shaded
        one = render_state(state, f, levels=(0.3,), cmap="magma", clim=clim, size=(240, 200), dpi=50,
                           show_bars=False, axis_labels=False)
        want = (colours.level_colors([0.3], lo, hi, "magma") if clim is None
                else colours.level_colors([0.3], 0.0, 1.0, "magma", by_value=True))[0]
        pixel = pixels(one)[0][100, 120]
        cos = pixel @ want / np.linalg.norm(pixel) / np.linalg.norm(want)
        assert cos > 0.995, (clim, pixel, want)
    # a volume rendering marks no levels (no surfaces are drawn)
    fig = render_state(state, f, rendering="mip", size=(160, 120), dpi=40)
    assert not [ln for ln in colorbar(fig).lines if ln.get_gid() == "level-mark"]


def test_the_picture_keeps_its_pixels_and_a_polytope_has_no_bar():
    f = ball()
    state = RotationState()
    a, _ = pixels(render_state(state, f, size=(200, 160), dpi=50, colorbar=False, axis_labels=False))
    b, _ = pixels(render_state(state, f, size=(200, 160), dpi=50, axis_labels=False))
    assert a.shape == (160, 200, 3) and b.shape[1] > 200
    np.testing.assert_array_equal(a, b[:, :200])
    fig = render_state(state, "24-cell", size=(200, 160), dpi=50)
    assert len(fig.axes) == 1 and pixels(fig)[0].shape == (160, 200, 3)


def test_the_box_is_labelled_with_data_coordinates():
    f = Field4D.from_function(lambda x, y, z, w: x, ((0, 9), (0, 4), (0, 6), (0, 38)), space_units="mm",
                              w_units="s")
    fig = render_state(RotationState(c0=19.0), f, size=(300, 250), dpi=50)
    texts = [t.get_text() for t in fig.axes[0].texts if t.get_gid() == "box-label"]
    assert len(texts) == 4 and texts[0].endswith("w 19 s") and texts[1].startswith("x ")
    assert all("\u2192" in t for t in texts[1:])
    assert not [t for t in render_state(RotationState(c0=19.0), f, size=(300, 250), dpi=50,
                                        axis_labels=False).axes[0].texts if t.get_gid() == "box-label"]


# ---------------------------------------------------------------- progress
def test_render_grid_reports_its_progress_up_to_the_end():
    grid = sample_field(ball(), np.eye(4), 0.0, 32)
    seen = []
    render_grid(grid, "volume", size=(120, 100), limits=((-1.5, 1.5), (-1.25, 1.25)), pixels_per_ray=1,
                progress=seen.append)
    assert len(seen) > 2 and seen[-1] == 1.0 and all(b >= a for a, b in zip(seen, seen[1:]))
    with pytest.raises(TypeError, match="progress"):
        render_grid(grid, "mip", size=(10, 10), limits=((-1, 1), (-1, 1)), progress="yes")


def test_a_slow_render_state_shows_a_progress_bar(monkeypatch):
    """A clock that runs 0.5 s per reading: the render seems slow, and the bar (text, as on a terminal) shows."""
    now = [0.0]

    def clock():
        now[0] += 0.5
        return now[0]

    out = io.StringIO()
    bars = []

    def make(total, description):
        bars.append(core_progress.Progress(total, description, mode="text", file=out, clock=clock))
        return bars[-1]

    monkeypatch.setattr(ray_caster, "make_progress", make)
    render_state(RotationState(), ball(), rendering="volume", size=(200, 160), dpi=50)
    text = out.getvalue()
    assert len(bars) == 1 and "rendering the cut (volume)" in text and text.endswith("\n")
    assert bars[0].count == bars[0].total
    # a quick one (the real clock) stays silent
    monkeypatch.setattr(ray_caster, "make_progress", core_progress.progress)
    quiet = io.StringIO()
    monkeypatch.setattr("sys.stderr", quiet)
    render_state(RotationState(), ball(), rendering="mip", size=(80, 60), dpi=40)
    assert quiet.getvalue() == ""
