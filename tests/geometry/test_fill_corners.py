"""A non-convex section's even-odd fill adds corners (`Slice.n_fill`) that are not points of the
slice: no ball is drawn there -- in the live view's rows, in a stack's rows, and in static
pictures (`draw_slice`, which draws such a slice's faces from its triangles)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from rot4d_widget import polytope, slice_polytope  # noqa: E402
from rot4d_widget.core.rotation import random_rotation  # noqa: E402
from rot4d_widget.keep.pictures.slice_drawing import slice_collection, draw_slice  # noqa: E402
from rot4d_widget.sources.protocol import PolytopeSource  # noqa: E402
from rot4d_widget.sources.tomography import StackSource  # noqa: E402
from rot4d_widget.view.buffers import ball_count, slice_rows  # noqa: E402
from rot4d_widget.view.scene import Scene  # noqa: E402

NAME = "small stellated 120-cell"  # pentagram faces, star cells: sections filled even-odd


def _crossings(p, m, c0):
    """Where the edges cross w = c0, from the vertices and edges alone."""
    r = np.asarray(p.vertices) @ m.T
    a, b = r[p.edges[:, 0]], r[p.edges[:, 1]]
    cut = (a[:, 3] - c0) * (b[:, 3] - c0) < 0
    t = (c0 - a[cut, 3]) / (b[cut, 3] - a[cut, 3])
    return (a[cut] + t[:, None] * (b[cut] - a[cut]))[:, :3]


@pytest.fixture(scope="module")
def cut():
    p = polytope(NAME)
    m = random_rotation(np.random.default_rng(5))
    return p, m, PolytopeSource(p).slice(m, 0.0)


def test_the_rows_show_balls_only_at_the_edges_crossings(cut):
    p, m, data = cut
    s = data.slice
    assert s.n_fill > 0  # the case this is about
    flags = data.corner_only
    assert flags is not None and flags.sum() == s.n_fill and not flags.flags.writeable
    rows = slice_rows(data)
    want = _crossings(p, m, 0.0)
    n = ball_count(data)
    # the balls are the first rows, every one shown, and no row after them is a ball: the layer
    # draws ``n`` (the scene's count) and never a hidden ball at a fill corner
    assert n == len(want) == len(data.points) - s.n_fill
    assert (rows[:n, 3] == 1.0).all() and (rows[n:, :4] == 0.0).all()
    shown = rows[:n, :3]
    d = np.linalg.norm(shown[:, None].astype(np.float64) - want[None], axis=-1)
    assert d.min(axis=1).max() < 1e-5 and d.min(axis=0).max() < 1e-5


def test_the_scene_draws_as_many_balls_as_crossings(cut):
    """What the page's ball layer draws (`Scene.counts`, sent with the rows) is the crossings, not
    the points with the fill corners: the great icosahedral 120-cell's 10,000 fill corners were
    drawn as hidden balls (22 ms of a frame on software WebGL, docs/performance.md)."""
    p, m, data = cut
    scene = Scene(scale=1.0, n_groups=int(np.max(data.groups)) + 1)
    try:
        scene.show(data)
        assert scene.counts == [len(_crossings(p, m, 0.0)), len(data.segments), len(data.triangles)]
    finally:
        scene.close()


def test_a_stack_keeps_each_slices_fill_flags():
    stack = StackSource(NAME, slices=3)
    m = random_rotation(np.random.default_rng(6))
    data = stack.slice(m, 0.0)
    pieces = data.slices
    want = sum(int(getattr(pc, "n_fill", 0)) for pc in pieces)
    assert want > 0 and data.corner_only is not None and int(data.corner_only.sum()) == want
    off = data.point_offsets
    for k, pc in enumerate(pieces):  # each slice's fill corners are its own last ones
        flags = data.corner_only[off[k]:off[k + 1]]
        assert flags.sum() == pc.n_fill and (pc.n_fill == 0 or flags[-pc.n_fill:].all())
    turned = data.turned(np.eye(3)[[1, 0, 2]] * [1, 1, -1])
    assert np.array_equal(turned.corner_only, data.corner_only)
    # the rows' balls: every slice's points but its fill corners, in order (the corners sit
    # between the slices' points here, not only at the end)
    rows = slice_rows(data)
    n = ball_count(data)
    assert n == len(data.points) - want
    assert np.allclose(rows[:n, :3], np.asarray(data.points)[~data.corner_only], atol=1e-6)
    assert (rows[:n, 3] == 1.0).all() and (rows[n:, :4] == 0.0).all()


def test_static_pictures_draw_no_ball_at_a_fill_corner_and_fill_from_triangles(cut):
    p, m, data = cut
    s = data.slice
    fig, ax = plt.subplots()
    try:
        drawing = draw_slice(ax, s, fov=None, radius=p.circumradius, ball_radius=0.05, bar_radius=0.01)
        assert len(drawing.balls) == len(s.vertices) - s.n_fill == len(_crossings(p, m, 0.0))
        assert len(drawing.faces) == len(s.triangles)  # the even-odd fill, not angle-ordered polygons
        coll = slice_collection(s, scale=1.0, ball_radius=0.05, bar_radius=0.01, face_alpha=0.3)
        n_paths = len(coll.get_paths())
        assert n_paths == len(s.triangles) + len(s.edges) + 2 * (len(s.vertices) - s.n_fill)
    finally:
        plt.close(fig)


def test_a_convex_slice_has_no_flags():
    data = PolytopeSource("600-cell").slice(random_rotation(np.random.default_rng(1)), 0.0)
    assert data.corner_only is None and int(getattr(data.slice, "n_fill", 0)) == 0
    assert (slice_rows(data)[: len(data.points), 3] == 1.0).all()
