"""Static figures: perspective, painter's order, what the panels show, PNG sizes, bad input."""

import math
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.image import imread
from matplotlib.patches import Circle

from rot4d_widget import RotationState, double_rotation, pentachoron, simple_rotation, slice_polytope
from rot4d_widget.core import camera, colours, sizes
from rot4d_widget.keep.pictures.slice_drawing import CAMERA_DISTANCE, FIG4_ALPHA, TITLE_HEIGHT, draw_slice, perspective
from rot4d_widget.keep.pictures.panels import panel_style, paper_figure_3, paper_figure_4, render_key_sequence, render_slice

A = 2.0  # the paper's pentachoron edge


def _pinhole(points, eye_z):
    """Independent projection: intersect the ray eye -> P with the picture plane z = 0."""
    eye = np.array([0.0, 0.0, eye_z])
    out = []
    for p in np.asarray(points, float):
        t = (0.0 - eye[2]) / (p[2] - eye[2])  # eye + t (p - eye) has z = 0
        hit = eye + t * (p - eye)
        out.append(hit[:2])
    return np.array(out)


def _patches(ax, gid):
    return [p for p in ax.patches if p.get_gid() == gid]


def _panel_axes(fig):
    return [ax for ax in fig.axes if ax.texts]  # labelled panels, in order


@pytest.fixture
def tetra_slice():
    return slice_polytope(pentachoron(A), np.eye(4), 0.0)


# --------------------------------------------------------------------------- projection
def test_perspective_matches_pinhole_camera():
    rng = np.random.default_rng(1)
    pts = rng.uniform(-1.5, 1.5, size=(50, 3))
    for d in (5.0, 3.0, 12.5):
        xy, factor = perspective(pts, d)
        np.testing.assert_allclose(xy, _pinhole(pts, d), rtol=1e-12, atol=1e-12)
        # a unit length at depth z looks d/(d-z) long: the apparent length of a small
        # segment along x, measured with the independent projection
        eps = 1e-6
        shifted = _pinhole(pts + [eps, 0, 0], d)
        np.testing.assert_allclose(factor, (shifted - _pinhole(pts, d))[:, 0] / eps, rtol=1e-6)


def test_perspective_fixed_points_and_direction():
    xy, f = perspective([[1.0, 2.0, 0.0], [1.0, 0.0, 2.5], [1.0, 0.0, -5.0]], 5.0)
    np.testing.assert_allclose(xy, [[1, 2], [2, 0], [0.5, 0]])  # nearer is bigger
    np.testing.assert_allclose(f, [1.0, 2.0, 0.5])


@pytest.mark.parametrize(
    "points, distance, exc, match",
    [
        ([[0, 0, 5.0]], 5.0, ValueError, "behind the eye"),
        ([[0, 0, 7.0]], 5.0, ValueError, "behind the eye"),
        ([[0, 0]], 5.0, ValueError, r"shape \(n, 3\)"),
        ([[0, 0, np.nan]], 5.0, ValueError, "finite"),
        ([[0, 0, 0]], 0.0, ValueError, "distance"),
        ([[0, 0, 0]], "5", TypeError, "distance"),
        ([["a", 0, 0]], 5.0, TypeError, "points"),
    ],
)
def test_perspective_bad_input(points, distance, exc, match):
    with pytest.raises(exc, match=match):
        perspective(points, distance)


# --------------------------------------------------------------------------- one panel
def test_balls_sit_at_projected_vertices_with_perspective_radii(tetra_slice):
    fig = Figure()
    ax = fig.add_subplot()
    drawing = draw_slice(ax, tetra_slice, ball_radius=0.1)
    v = np.asarray(tetra_slice.vertices)
    expected = _pinhole(v, CAMERA_DISTANCE)
    assert len(drawing.balls) == len(v) == 4
    centers = np.array([b.center for b in drawing.balls])
    radii = np.array([b.radius for b in drawing.balls])
    np.testing.assert_allclose(centers, expected, atol=1e-12)
    np.testing.assert_allclose(radii, 0.1 * CAMERA_DISTANCE / (CAMERA_DISTANCE - v[:, 2]), rtol=1e-12)
    # the artists found on the axes are the same ones
    assert len(_patches(ax, "ball")) == 4
    assert len(_patches(ax, "bar")) == len(tetra_slice.edges) == 6
    assert len(_patches(ax, "face")) == len(tetra_slice.polygons) == 4


def test_panel_a_is_a_regular_tetrahedron_of_edge_1_6(tetra_slice):
    v = np.asarray(tetra_slice.vertices)
    d = np.linalg.norm(v[:, None] - v[None], axis=2)[np.triu_indices(4, 1)]
    np.testing.assert_allclose(d, 1.6, atol=1e-12)
    # and it is drawn as one: 4 balls, 6 bars, 4 triangular faces
    fig = paper_figure_3()
    ax = _panel_axes(fig)[0]
    assert ax.texts[0].get_text() == "(a)"
    assert len(_patches(ax, "ball")) == 4
    assert len(_patches(ax, "bar")) == 6
    faces = _patches(ax, "face")
    assert sorted(len(f.get_xy()) - 1 for f in faces) == [3, 3, 3, 3]  # closed polygons repeat a corner


def test_painters_order_back_to_front(tetra_slice):
    fig = Figure()
    ax = fig.add_subplot()
    drawing = draw_slice(ax, tetra_slice)
    z = np.asarray(tetra_slice.vertices)[:, 2]
    ball_z = np.array([b.get_zorder() for b in drawing.balls])
    assert np.array_equal(np.argsort(ball_z, kind="stable"), np.argsort(z, kind="stable"))
    # every ball is above the faces behind it: the apex (nearest) ball is the topmost patch
    apex = int(np.argmax(z))
    assert drawing.balls[apex].get_zorder() > max(f.get_zorder() for f in drawing.faces)
    assert drawing.balls[apex].get_zorder() > max(b.get_zorder() for b in drawing.bars)
    # the face nearest the eye is drawn last among faces
    face_z = [np.asarray(tetra_slice.vertices)[np.asarray(p)][:, 2].mean() for p in tetra_slice.polygons]
    assert int(np.argmax([f.get_zorder() for f in drawing.faces])) == int(np.argmax(face_z))


def test_rendered_pixels_nearest_ball_covers_the_faces(tmp_path, tetra_slice):
    """In the PNG, the apex ball's centre has the pure ball colour: no translucent face over it."""
    dpi, size = 100, 4.0
    fig = Figure(figsize=(size, size), dpi=dpi)
    ax = fig.add_axes([0, 0, 1, 1])
    drawing = draw_slice(ax, tetra_slice, ball_color="#0000ff", ball_radius=0.12)
    path = tmp_path / "one.png"
    fig.savefig(path, dpi=dpi)
    img = imread(path)
    z = np.asarray(tetra_slice.vertices)[:, 2]
    apex = int(np.argmax(z))
    (px, py), = ax.transData.transform([drawing.balls[apex].center])
    pixel = img[img.shape[0] - 1 - int(round(py)), int(round(px))]
    np.testing.assert_allclose(pixel[:3], [0, 0, 1], atol=0.02)
    # while a face centre away from balls is tinted (translucent face over white)
    centers = np.array([b.center for b in drawing.balls])
    spots = [np.asarray(f.get_xy())[:-1].mean(axis=0) for f in drawing.faces]
    spot = max(spots, key=lambda c: np.linalg.norm(centers - c, axis=1).min())  # away from balls
    (fx, fy), = ax.transData.transform([spot])
    face_pixel = img[img.shape[0] - 1 - int(round(fy)), int(round(fx))]
    assert 0.05 < 1 - face_pixel[:3].min() < 0.95


def test_same_cell_same_colour_across_panels():
    fig = render_key_sequence("4", 2, state=RotationState(theta0=math.pi / 16), polytope=pentachoron(A))
    a, b = _panel_axes(fig)[:2]
    sa = slice_polytope(pentachoron(A), np.eye(4), 0.0)
    sb = slice_polytope(pentachoron(A), simple_rotation("xw", math.pi / 16), 0.0)
    col_a = {int(c): tuple(f.get_facecolor()) for c, f in zip(sa.cell_ids, _patches(a, "face"))}
    col_b = {int(c): tuple(f.get_facecolor()) for c, f in zip(sb.cell_ids, _patches(b, "face"))}
    common = set(col_a) & set(col_b)
    assert common
    assert all(col_a[c] == col_b[c] for c in common)
    assert len(set(col_a.values())) == len(col_a)  # distinct cells, distinct colours


# --------------------------------------------------------------------------- sequences and paper figures
def _ball_centers(ax):
    return np.array([b.center for b in _patches(ax, "ball")]).reshape(-1, 2)


def _expected_centers(matrix, scale=1.0):
    s = slice_polytope(pentachoron(A), matrix, 0.0)
    return _pinhole(np.asarray(s.vertices) * scale, CAMERA_DISTANCE).reshape(-1, 2)


def _assert_same_points(actual, expected, atol=1e-9):
    """Equal as sets of 2-D points (the slicer's vertex order is not part of the contract)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape
    dist = np.linalg.norm(actual[:, None] - expected[None], axis=2)
    assert dist.min(axis=1).max() <= atol and dist.min(axis=0).max() <= atol


def test_paper_figure_3_png(tmp_path):
    path = tmp_path / "fig3.png"
    fig = paper_figure_3(path, dpi=50)
    img = imread(path)
    assert img.shape[:2] == (round((4 * 2.0 + TITLE_HEIGHT) * 50), 4 * 2.0 * 50)
    panels = _panel_axes(fig)
    assert [ax.texts[0].get_text() for ax in panels] == [f"({c})" for c in "abcdefghijklmnop"]
    # panel k is the slice after k steps of R_xw(pi/16)
    for k in (0, 1, 5, 15):
        _assert_same_points(_ball_centers(panels[k]), _expected_centers(simple_rotation("xw", k * math.pi / 16)))
    with pytest.raises(AssertionError):
        _assert_same_points(_ball_centers(panels[0]), _ball_centers(panels[1]), atol=1e-3)


def test_paper_figure_4_png(tmp_path):
    path = tmp_path / "fig4.png"
    fig = paper_figure_4(path, dpi=40, title=False)
    assert imread(path).shape[:2] == (4 * 2 * 40, 4 * 2 * 40)
    panels = _panel_axes(fig)
    assert len(panels) == 16
    alpha, beta = FIG4_ALPHA, 1.0 - FIG4_ALPHA
    assert alpha == pytest.approx(math.pi * math.sqrt(2) / (8 * math.sqrt(3)))
    for k in (1, 2, 7):
        _assert_same_points(
            _ball_centers(panels[k]), _expected_centers(double_rotation("xz,yw", k * alpha, k * beta))
        )


@pytest.mark.parametrize("fmt", [".pdf", ".svg"])
def test_other_vector_formats(tmp_path, fmt):
    path = tmp_path / f"fig{fmt}"
    paper_figure_3(path)
    assert path.stat().st_size > 1000


def test_grid_size_follows_ncols_and_panel_count(tmp_path):
    fig = render_key_sequence("4", 3, ncols=4, panel_size=1.5, dpi=40)
    path = tmp_path / "g.png"
    fig.savefig(path, dpi=fig.dpi)
    assert imread(path).shape[:2] == (60, 180)  # one row of three, not four
    assert len(_panel_axes(fig)) == 3
    fig = render_key_sequence("4", 7, ncols=3, panel_size=1.0, dpi=30, labels=False)
    assert len(fig.axes) == 9  # 3 x 3 grid, last two empty
    assert all(not ax.texts for ax in fig.axes)
    assert sum(bool(_patches(ax, "ball")) for ax in fig.axes) == 7


def test_state_is_copied_not_modified_and_shift_inverts():
    state = RotationState(theta0=math.pi / 16)
    fig = render_key_sequence("4", 3, state=state, polytope=pentachoron(A), shift=True)
    np.testing.assert_array_equal(state.matrix, np.eye(4))
    panels = _panel_axes(fig)
    _assert_same_points(_ball_centers(panels[2]), _expected_centers(simple_rotation("xw", -2 * math.pi / 16)))


def test_parameter_key_sequence_moves_the_hyperplane():
    state = RotationState(c0=0.0, c0_step=0.25)
    fig = render_key_sequence("l", 3, state=state, polytope=pentachoron(A), scale=1.0)
    panels = _panel_axes(fig)
    # the tetrahedron shrinks towards P4 as c0 rises: edge a (w0 - c0) / (5 w0 / 4)
    w0 = A * math.sqrt(2 / 5)
    for k, ax in enumerate(panels):
        s = slice_polytope(pentachoron(A), np.eye(4), 0.25 * k)
        v = np.asarray(s.vertices)
        edge = np.linalg.norm(v[0] - v[1])
        assert edge == pytest.approx(A * (w0 - 0.25 * k) / (1.25 * w0))
        _assert_same_points(_ball_centers(ax), _pinhole(v, 5.0))


def test_default_scale_makes_every_polytope_the_pentachoron_size():
    fig = render_slice("24-cell", ball_radius=0.07, bar_radius=0.028)  # the pentachoron's sizes
    ax = fig.axes[0]
    fig5 = render_slice(pentachoron(A))
    assert ax.get_xlim() == pytest.approx(fig5.axes[0].get_xlim())
    pts = np.array([b.center for b in _patches(ax, "ball")])
    assert np.abs(pts).max() < ax.get_xlim()[1]


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        (dict(key="q"), ValueError, "not bound"),
        (dict(key=4), TypeError, "key"),
        (dict(key="4", n_panels=0), ValueError, "n_panels"),
        (dict(key="4", n_panels=2.5), TypeError, "n_panels"),
        (dict(key="4", n_panels=True), TypeError, "n_panels"),
        (dict(key="4", ncols=0), ValueError, "ncols"),
        (dict(key="4", panel_size=-1), ValueError, "panel_size"),
        (dict(key="4", dpi=float("nan")), ValueError, "dpi"),
        (dict(key="4", state="fresh"), TypeError, "state"),
        (dict(key="4", polytope=5), TypeError, "polytope"),
        (dict(key="4", title=3), TypeError, "title"),
        (dict(key="4", ball_radius=-0.1), ValueError, "ball_radius"),
        (dict(key="4", face_alpha=1.5), ValueError, "face_alpha"),
        (dict(key="4", cmap="no-such-map"), ValueError, "colormap"),
        (dict(key="4", scale=20.0), ValueError, "radius|behind the eye"),
    ],
)
def test_render_key_sequence_bad_input(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        render_key_sequence(n_panels=kwargs.pop("n_panels", 2), **kwargs)


def test_unknown_polytope_name_is_refused():
    with pytest.raises(ValueError):
        render_key_sequence("4", 1, polytope="7-cell")


def test_draw_slice_bad_input(tetra_slice):
    ax = Figure().add_subplot()
    with pytest.raises(TypeError, match="Axes"):
        draw_slice(None, tetra_slice)
    with pytest.raises(TypeError, match="Slice"):
        draw_slice(ax, np.zeros((4, 3)))
    with pytest.raises(ValueError, match="behind the eye"):
        draw_slice(ax, tetra_slice, scale=10.0)
    with pytest.raises(ValueError, match="radius"):
        draw_slice(ax, tetra_slice, radius=6.0)
    with pytest.raises(TypeError, match="label"):
        draw_slice(ax, tetra_slice, label=1)
    with pytest.raises(ValueError, match="fov"):
        draw_slice(ax, tetra_slice, fov=180.0)
    with pytest.raises(TypeError, match="fov"):
        draw_slice(ax, tetra_slice, fov="40")


def test_without_a_camera_the_frame_fits_the_sphere_or_the_slice(tetra_slice):
    """fov=None keeps the tighter frames: a sphere of `radius` plus the balls, or the slice itself."""
    ax = Figure().add_subplot()
    d = draw_slice(ax, tetra_slice, fov=None, radius=1.0, ball_radius=0.1, bar_radius=0.0)
    r = 5.0 * 1.0 / math.sqrt(25.0 - 1.0) + 0.1 * 5.0 / 4.0  # the sphere's outline + a ball at its front
    assert ax.get_xlim() == pytest.approx((-r, r)) and ax.get_ylim() == pytest.approx((-r, r))
    ax = Figure().add_subplot()
    d = draw_slice(ax, tetra_slice, fov=None)
    reach = np.abs(d.centers).max() + max(b.radius for b in d.balls)
    assert reach < d.limit < 1.2 * reach


def test_cmap_still_colours_by_a_matplotlib_colormap(tetra_slice):
    from matplotlib import colormaps

    d = draw_slice(Figure().add_subplot(), tetra_slice, cmap="tab10")
    tab10 = colormaps["tab10"]
    got = {tuple(f.get_facecolor()[:3]) for f in d.faces}
    assert got == {tuple(tab10(int(c) % 10)[:3]) for c in tetra_slice.cell_ids}


@pytest.mark.parametrize("path, exc", [("fig.jpg", ValueError), (3, TypeError)])
def test_save_path_checked(path, exc):
    with pytest.raises(exc, match="path"):
        paper_figure_3(path)


def test_empty_slice_draws_an_empty_panel():
    s = slice_polytope(pentachoron(A), np.eye(4), 5.0)  # far past the polytope
    assert len(s.vertices) == 0
    ax = Figure().add_subplot()
    drawing = draw_slice(ax, s, radius=1.0)
    assert not ax.patches and drawing.limit > 1.0


def test_figures_import_no_pyplot_and_no_widget_library():
    code = (
        "import sys, rot4d_widget.keep.pictures.state_picture, rot4d_widget.keep.pictures.panels\n"
        "bad = [m for m in ('matplotlib.pyplot', 'ipywidgets', 'pythreejs', 'ipyevents') if m in sys.modules]\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_render_slice_draws_balls():
    assert isinstance(render_slice(), Figure)
    assert all(isinstance(b, Circle) for b in _patches(render_slice().axes[0], "ball"))


def test_panel_style_keeps_dense_polytopes_readable():
    five, dense = panel_style(pentachoron(A)), panel_style("120-cell")
    assert five == pytest.approx({"scale": 1.0, "radius": sizes.REFERENCE_RADIUS, "ball_radius": 0.07,
                                  "bar_radius": 0.028})
    assert dense["radius"] == pytest.approx(sizes.REFERENCE_RADIUS)
    # the live view's rule: 0.1 x the displayed edge (the 120-cell's is 2 x scale), bars 0.4 x balls
    assert dense["ball_radius"] == pytest.approx(0.1 * 2.0 * dense["scale"])
    assert dense["ball_radius"] < five["ball_radius"]
    assert dense["bar_radius"] == pytest.approx(0.4 * dense["ball_radius"])


# --------------------------------------------------------------------------- render_state (issue 12)
def _ndc_pixel(p3, size):
    """Where the live view's three.js camera (core.camera: eye (0, 0, 5), vertical fov 40 deg, aspect
    w / h) puts the displayed point p3: pixel (column, row) of a w x h image, written out here."""

    w, h = size
    d = camera.CAMERA_POSITION[2]
    t = math.tan(math.radians(camera.CAMERA_FOV) / 2)
    x, y, z = p3
    ndc_x = x / ((d - z) * t * (w / h))
    ndc_y = y / ((d - z) * t)
    return (ndc_x + 1) / 2 * w, (1 - ndc_y) / 2 * h


@pytest.mark.parametrize("size", [(600, 500), (320, 400)])
def test_render_state_puts_the_nearest_ball_where_the_live_camera_does(tmp_path, size):
    from rot4d_widget import polytope
    from rot4d_widget.keep.pictures.state_picture import render_state
    from rot4d_widget.core.rotation import random_rotation

    st = RotationState(matrix=random_rotation(4), c0=0.1)
    path = tmp_path / "s.png"
    render_state(st, "24-cell", path, size=size, dpi=80, ball_radius=0.09, frame="camera")
    img = imread(path)
    assert img.shape[:2] == (size[1], size[0])  # the size asked for, in pixels
    s = slice_polytope(polytope("24-cell"), st.matrix, st.c0)
    v = np.asarray(s.vertices) * sizes.REFERENCE_RADIUS / 2.0  # displayed units (24-cell: circumradius 2)
    near = v[np.argmax(v[:, 2])]
    col, row = _ndc_pixel(near, size)
    pixel = img[int(row), int(col), :3]
    np.testing.assert_allclose(pixel, colours.as_rgb(colours.BALL_COLOR), atol=0.03)
    # a corner is background
    np.testing.assert_allclose(img[2, 2, :3], [1, 1, 1], atol=1e-6)
    # balls only: every vertex, the widest ones too, is drawn where the camera puts it
    render_state(st, "24-cell", path, size=size, dpi=80, show_faces=False, show_bars=False,
                 frame="camera")
    img = imread(path)[..., :3]
    for p3 in v:
        col, row = _ndc_pixel(p3, size)
        r, g, b = img[int(row), int(col)]
        assert r > 0.45 and g < 0.3 and b < 0.3, (p3, (r, g, b))
    assert np.abs(v[:, 0]).max() > 0.8  # some are far from the centre (the aspect matters)


def test_render_state_display_options_and_colours(tmp_path):
    from rot4d_widget.keep.pictures.state_picture import render_state

    st = RotationState()
    path = tmp_path / "c.png"
    # one opaque colour, no balls or bars, a dark background: only two colours in the picture
    render_state(st, "5-cell", path, color_by="#ff0000", face_opacity=1.0, show_balls=False, show_bars=False,
                 background="#000000", size=(200, 200), dpi=50)
    img = imread(path)[..., :3]
    col, row = _ndc_pixel((0.0, 0.0, 0.0), (200, 200))
    np.testing.assert_allclose(img[int(row), int(col)], [1, 0, 0], atol=1e-6)
    np.testing.assert_allclose(img[1, 1], [0, 0, 0], atol=1e-6)
    reddish = (img[..., 0] > 0.5) & (img[..., 1] < 0.2)
    assert 0.05 < reddish.mean() < 0.6
    # by group (the default): the cells' palette colours over white, no pure red
    render_state(st, "5-cell", path, face_opacity=1.0, show_balls=False, show_bars=False, size=(200, 200), dpi=50)
    img = imread(path)[..., :3].reshape(-1, 3)
    pal = colours.group_palette(5)
    drawn = img[np.abs(img - 1).max(axis=1) > 0.02]  # not background
    near = np.abs(drawn[:, None, :] - pal[None]).max(axis=2).min(axis=1) < 0.02
    assert len(drawn) > 0.05 * len(img) and near.mean() > 0.75  # (edges antialiased) opaque faces in the cells' colours
    # show_faces=False leaves balls and bars on white
    def green(**kw):
        render_state(st, "5-cell", path, color_by="#00ff00", face_opacity=1.0, size=(200, 200), dpi=50, **kw)
        r, g, b = np.moveaxis(imread(path)[..., :3], -1, 0)
        return ((g > r + 0.3) & (g > b + 0.3)).mean()

    assert green() > 0.05
    assert green(show_faces=False) == 0  # balls (red) and bars (grey) only


def test_render_state_field_levels_and_stack(tmp_path):
    from rot4d_widget import Field4D
    from rot4d_widget.keep.pictures.state_picture import render_state, state_source
    from rot4d_widget.sources.tomography import StackSource

    f = Field4D.from_function(lambda x, y, z, w: 1 - (x * x + y * y + z * z) - 0.3 * w,
                              [(-1.2, 1.2)] * 3 + [(-1.0, 1.0)], resolution=24, levels=(0.4,))
    st = RotationState()
    path = tmp_path / "f.png"
    render_state(st, f, path, size=(240, 200), dpi=60, show_bars=False)
    img = imread(path)[..., :3]
    col, row = _ndc_pixel((0.0, 0.0, 0.0), (240, 200))
    pixel = img[int(row), int(col)]
    want = colours.level_colors([0.4], *f.data_range)[0]
    cos = pixel @ want / np.linalg.norm(pixel) / np.linalg.norm(want)
    assert cos > 0.995  # the level's colour, shaded
    # levels given: the field itself is left alone
    render_state(st, f, path, levels=(0.2, 0.6), size=(240, 200), dpi=60)
    assert f.levels == (0.4,)
    assert state_source(f, levels=(0.2, 0.6)).source.levels == (0.2, 0.6)
    # a stack: parallel slices of the same source (slices= wraps, a StackSource is re-set)
    stack = state_source("24-cell", slices=5, spacing=0.4, arrangement="grid")
    assert isinstance(stack, StackSource) and (stack.slices, stack.spacing, stack.arrangement) == (5, 0.4, "grid")
    again = state_source(stack, slices=3)
    assert (again.slices, again.spacing, again.arrangement, stack.slices) == (3, 0.4, "grid", 5)
    for ext, magic in (("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")):
        render_state(st, stack, tmp_path / f"s.{ext}", size=(300, 250), dpi=50)
        assert (tmp_path / f"s.{ext}").read_bytes()[:5].startswith(magic)
    one = imread(tmp_path / "s.png")[..., :3]
    render_state(st, "24-cell", tmp_path / "one.png", size=(300, 250), dpi=50)
    assert not np.array_equal(one, imread(tmp_path / "one.png")[..., :3])


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(state="not a state"), TypeError, "RotationState"),
    (dict(size=(600,)), TypeError, "size"),
    (dict(size=(0, 100)), ValueError, r"size\[0\]"),
    (dict(color_by="blue-ish"), ValueError, "color_by"),
    (dict(levels=(0.1,)), TypeError, "levels.*Field4D"),
    (dict(path="x.gif"), ValueError, "end in one of"),
])
def test_render_state_bad_input(kwargs, exc, match):
    from rot4d_widget.keep.pictures.state_picture import render_state

    state = kwargs.pop("state", RotationState())
    with pytest.raises(exc, match=match):
        render_state(state, "5-cell", **kwargs)
