"""A 4-D field in the widget: coarse while keys repeat, full at rest, no resampling for 3-D turns.

Kernel side only (recording comms, fake clock); the page side is in
tests/browser/test_fields_browser.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rot4d_widget.core import colours
from rot4d_widget.sources.field.container import Field4D
from test_widget import down, up
from test_widget_scene import drawn, run_ticker
from widget_time import service

pytestmark = pytest.mark.usefixtures("recording_comms")

R = 0.8


def ball_field(**kw):
    """f = R^2 - |q|^2 on [-1, 1]^4: every slice {f >= 0} is a ball of radius sqrt(R^2 - c0^2)."""
    kw.setdefault("resolution", 24)
    kw.setdefault("coarse_resolution", 12)
    return Field4D.from_function(lambda x, y, z, w: R * R - (x * x + y * y + z * z + w * w),
                                 [(-1.0, 1.0)] * 4, levels=[0.0], **kw)


class Counting:
    """Wraps a field's ``slice`` and records each call's ``coarse`` flag (what was resampled)."""

    def __init__(self, field):
        self.calls = []
        self._slice = field.slice
        field.slice = self

    def __call__(self, matrix, c0, coarse=False):
        self.calls.append(bool(coarse))
        return self._slice(matrix, c0, coarse=coarse)


def surface_points(w):
    """The shown surface's points, de-quantised, in the source's units (view scale undone)."""
    s = w.scene.surface
    pos = np.frombuffer(s["position"], dtype="<u2").reshape(-1, 3).astype(np.float64)
    p = np.asarray(s["lo"]) + pos / 65535.0 * np.asarray(s["span"])
    return p / w.scene.scale


def settle(w, clock, seconds):
    """Acknowledge whatever is drawn and run the ticker for ``seconds`` of the fake clock."""
    until = clock.t + seconds
    while clock.t < until:
        drawn(w)
        run_ticker(w, clock, min(until, clock.t + 0.05))


def test_a_field_is_drawn_as_one_smooth_surface_with_its_box(make):
    f = ball_field()
    w = make(f)
    s = w.scene.surface
    assert s["n_vertices"] > 100 and s["n_indices"] % 3 == 0 and s["n_indices"] > 0
    # the surface's points lie on the sphere of radius R (c0 = 0), to the sampling's accuracy
    r = np.linalg.norm(surface_points(w), axis=1)
    assert np.all(np.abs(r - R) < 0.03)
    # the rows carry no faces (they go to the surface) and the box's bars
    balls, bars, faces = w.scene.counts
    assert balls == 0 and faces == 0 and bars == len(w.slice.segments) >= 12
    assert w.levels == (0.0,)


def test_a_held_key_samples_coarsely_and_the_release_brings_full_resolution(make, clock):
    f = ball_field()
    w = make(f)
    calls = Counting(f).calls
    down(w, "4")
    assert calls == [True]  # the keydown's step, already coarse
    settle(w, clock, 1.0)  # repeats while held
    assert len(calls) > 3 and all(calls)
    coarse_n = w.scene.surface["n_vertices"]
    up(w, "4")
    settle(w, clock, 0.5)
    assert calls[-1] is False and calls.count(False) == 1  # one full step, at rest
    assert w.scene.surface["n_vertices"] > coarse_n  # finer
    assert w._painter.shown.coarse is False


@pytest.mark.parametrize("key", ["2", "3", "6"])
def test_rotations_that_leave_w_alone_never_resample(make, clock, key):
    f = ball_field()
    w = make(f, c0=0.3)
    calls = Counting(f).calls
    before = surface_points(w)
    vol = w.slice.volume
    down(w, key)
    settle(w, clock, 0.8)
    n_turns = w.stats.updates
    up(w, key)
    settle(w, clock, 0.5)
    assert calls == []  # turned, held and at rest, without a new sample of the field
    assert n_turns > 2
    after = surface_points(w)
    # the same surface turned: same radii (the ball at c0 = 0.3), moved points
    r = math.sqrt(R * R - 0.3 * 0.3)
    assert np.all(np.abs(np.linalg.norm(after, axis=1) - r) < 0.03)
    assert not np.allclose(np.sort(after, axis=0), np.sort(before, axis=0), atol=1e-3)
    # and it is what slicing again would show: the same volume (the ball's)
    assert w._painter.rows_data.volume == pytest.approx(vol)
    assert w._painter.rows_data.volume == pytest.approx(4 / 3 * math.pi * r**3, rel=0.05)


def test_rotations_that_move_w_resample_at_full_resolution_at_rest(make, clock):
    f = ball_field()
    w = make(f)
    calls = Counting(f).calls
    w.press("8")  # a single step from code: no key held, full resolution
    service(w, clock.t)
    assert calls == [False]


def test_levels_trait_and_level_keys_follow_each_other(make, clock):
    f = ball_field()
    w = make(f)
    calls = Counting(f).calls
    w.levels = (-0.1, 0.2)
    assert f.levels == (-0.1, 0.2) and calls  # re-sliced
    drawn(w)
    service(w, clock.t)
    s = w.scene.surface
    assert s["opacity"] == pytest.approx(colours.SURFACE_OPACITY)  # nested: translucent
    rgb = np.frombuffer(s["rgb"], dtype=np.uint8).reshape(-1, 3)
    assert len(np.unique(rgb, axis=0)) == 2  # one colour per level
    before = w.levels
    w.press("o")
    assert w.levels == f.levels and all(b > a for a, b in zip(before, w.levels))
    w.press("i")
    np.testing.assert_allclose(w.levels, before)
    with pytest.raises(ValueError):
        w.levels = (float("nan"),)
    np.testing.assert_allclose(w.levels, before)  # refused, unchanged
    assert f.levels == w.levels


def test_levels_do_not_apply_to_polytopes(make):
    with pytest.raises(TypeError, match="levels"):
        make("5-cell", levels=[0.5])
    w = make("5-cell")
    assert w.levels is None
    with pytest.raises(TypeError, match="levels"):
        w.levels = (0.5,)
    assert w.levels is None


def test_surface_quantisation_is_within_half_a_step():
    from rot4d_widget.view import buffers as bf

    f = ball_field()
    data = f.slice(np.eye(4), 0.0)
    arrays = bf.surface_arrays(data, scale=2.0, eye=(0.0, 0.0, 5.0))
    p = np.asarray(arrays["lo"]) + arrays["position"] / 65535.0 * np.asarray(arrays["span"])
    used = np.unique(np.asarray(data.triangles))
    np.testing.assert_allclose(np.sort(p, axis=0), np.sort(2.0 * np.asarray(data.points)[used], axis=0),
                               atol=max(arrays["span"]) / 65535.0)
    n = arrays["normal"].astype(np.float64) / 127.0
    assert np.all(np.abs(np.linalg.norm(n, axis=1) - 1.0) < 0.02)
    # triangles farthest first from the eye
    idx = arrays["index"].reshape(-1, 3)
    d = np.linalg.norm(p[idx].mean(axis=1) - np.array([0.0, 0.0, 5.0]), axis=1)
    assert np.all(np.diff(d) <= 1e-4)  # up to the quantisation
    assert arrays["index"].dtype == np.uint32 and arrays["position"].dtype == np.uint16


def test_an_empty_surface_clears_the_layer(make, clock):
    f = ball_field()
    w = make(f)
    assert w.scene.surface["n_indices"] > 0
    w.levels = (5.0,)  # above the maximum: nothing, not an error
    drawn(w)
    service(w, clock.t)
    assert w.scene.surface["n_indices"] == 0
    assert w.scene.counts[1] >= 12  # the box is still drawn


def test_the_rows_carry_only_the_box_so_an_update_stays_small(make):
    """The row table is sized for the box's bars, not the surface's triangles (they travel quantised)."""
    from rot4d_widget.view import buffers as bf

    f = ball_field()
    w = make(f)
    assert len(w.slice.triangles) > 200
    assert w.scene.capacity <= bf.capacity_for(32)  # a box slice has at most 32 edges (a 4-D box has 32)
    s = w.scene.surface
    surface_bytes = sum(len(s[k]) for k in ("position", "normal", "rgb", "index"))
    assert surface_bytes == 12 * s["n_vertices"] + 4 * s["n_indices"]  # 6 + 3 + 3 B per point, 4 per index
    assert w.scene.rows.nbytes < surface_bytes / 4


def test_the_readme_field_example_runs_as_written_and_shows_a_surface(clock):
    """The README's "Your own data" block, executed as written (its widget on the fake clock)."""
    import pathlib
    import re

    from rot4d_widget.view.widget import Rot4DWidget as Real

    readme = (pathlib.Path(__file__).resolve().parents[2] / "README.md").read_text()
    # the first field example (the next, on inside/caps/sample_field, is test_readme_data's)
    blocks = [b for b in re.findall(r"```python\n(.*?)```", readme, re.S) if "Field4D(" in b]
    assert blocks and "inside=" not in blocks[0], "the README's first field example"
    made = []

    def widget(*a, **kw):
        made.append(Real(*a, _clock=clock, _autotick=False, **kw))
        return made[-1]

    ns = {}
    code = blocks[0].replace("from rot4d_widget import Field4D, Rot4DWidget", "from rot4d_widget import Field4D")
    ns["Rot4DWidget"] = widget
    try:
        exec(compile(code, "README.md", "exec"), ns)
        w = ns["w"]
        assert w.source is ns["field"] and w.levels == (pytest.approx(float(ns["f"].mean())),)
        assert w.scene.surface["n_indices"] > 0
        # axes="wzyx": the array's first axis is w (time), 24 samples; shape is in x, y, z, w order
        assert ns["field"].shape == (20, 20, 20, 24)
    finally:
        for x in made:
            x.close()


def test_the_readout_has_a_colour_legend_of_the_levels(make, clock):
    f = ball_field()
    w = make(f, levels=[-0.2, 0.1])
    html = w.readout.value
    colors = colours.level_colors(f.levels, *f.data_range)
    for lv, rgb in zip(f.levels, colors):
        hexed = "#" + "".join(f"{round(255 * c):02x}" for c in rgb)
        assert hexed in html and f"{lv:.4g}" in html
    assert "w cut" in html  # the time span the cut covers
