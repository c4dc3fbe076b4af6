"""rot4d_widget.core.colours, .sizes and .camera: one palette, scale, camera and default radii for the figures and
the live view."""

import math
import subprocess
import sys

import numpy as np

from rot4d_widget.core.rotation import random_rotation
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from rot4d_widget import pentachoron, polytope, slice_polytope
from rot4d_widget.core import camera, colours, sizes
from rot4d_widget.keep.pictures import panels, slice_drawing
from rot4d_widget.view import buffers
from rot4d_widget.keep.pictures.slice_drawing import draw_slice
from rot4d_widget.keep.pictures.panels import panel_style, render_slice


def _projected_corners(slice_, k, scale):
    """Corners of slice polygon k as figures place them: x d / (d - z), y d / (d - z)."""
    p = np.asarray(slice_.vertices)[slice_.polygons[k]] * scale
    d = camera.CAMERA_POSITION[2]
    return p[:, :2] * (d / (d - p[:, 2]))[:, None]


def _face_of_polygon(faces, corners):
    """The face patch whose corners are ``corners`` (as a set): independent of drawing order."""
    hits = []
    for f in faces:
        xy = np.asarray(f.get_xy())[:-1]  # closed polygons repeat the first corner
        if xy.shape == corners.shape:
            dist = np.linalg.norm(xy[:, None] - corners[None], axis=2)
            if dist.min(axis=0).max() < 1e-9 and dist.min(axis=1).max() < 1e-9:
                hits.append(f)
    assert len(hits) == 1
    return hits[0]


# --------------------------------------------------------------------------- the palette
@pytest.mark.parametrize("name, seed", [("5-cell", 0), ("16-cell", 1), ("24-cell", 2), ("120-cell", 3)])
def test_a_cell_has_the_live_views_colour_in_a_figure(name, seed):
    p = polytope(name)
    s = slice_polytope(p, random_rotation(np.random.default_rng(seed)), 0.05 * p.circumradius)
    assert len(s.cell_ids) >= 4
    style = panel_style(p)
    ax = Figure().add_subplot()
    drawing = draw_slice(ax, s, **style)
    palette = colours.group_palette(len(p.cells))  # what the live view is given for this polytope
    assert len(drawing.faces) == len(s.cell_ids)
    for k, cell in enumerate(s.cell_ids):
        face = _face_of_polygon(drawing.faces, _projected_corners(s, k, style["scale"]))
        rgba = face.get_facecolor()
        np.testing.assert_array_equal(np.float32(rgba[:3]), palette[cell])  # the RGB, before blending
        assert rgba[3] == pytest.approx(colours.FACE_OPACITY)


def test_a_rendered_panel_uses_the_palette_too():
    fig = render_slice("24-cell", random_rotation(np.random.default_rng(7)))
    s = slice_polytope(polytope("24-cell"), random_rotation(np.random.default_rng(7)), 0.0)
    faces = [f for f in fig.axes[0].patches if f.get_gid() == "face"]
    seen = {tuple(np.float32(f.get_facecolor()[:3])) for f in faces}
    palette = colours.group_palette(24)
    assert seen == {tuple(palette[c]) for c in s.cell_ids}


def test_buffers_palette_is_looks():
    for n in (0, 1, 5, 24, 120, 600):
        np.testing.assert_array_equal(buffers.cell_palette(n), colours.group_palette(n))
    assert colours.cell_palette is colours.group_palette
    assert buffers.as_rgb("#c8102e", "ball_color") == colours.as_rgb("#c8102e", "ball_color")


def test_group_palette_is_distinct_prefix_stable_and_in_range():
    a = colours.group_palette(600)
    assert a.shape == (600, 3) and a.dtype == np.float32
    assert 0.0 <= a.min() and a.max() <= 1.0
    assert len({tuple(c) for c in np.rint(a * 255).astype(int)}) == 600  # distinct 8-bit colours
    np.testing.assert_array_equal(a[:24], colours.group_palette(24))
    assert colours.group_palette(0).shape == (0, 3)
    with pytest.raises(ValueError, match="n_cells"):
        colours.group_palette(-1)


# --------------------------------------------------------------------------- colours
def test_colours_are_valid_and_drawn_by_default(tmp_path):
    for name in ("BACKGROUND", "BALL_COLOR", "BAR_COLOR", "SINGLE_FACE_COLOR"):
        rgb = colours.as_rgb(getattr(colours, name), name)
        assert len(rgb) == 3
    # the single face colour is a light, low-saturation blue: blue the largest, all of it light
    r, g, b = colours.as_rgb(colours.SINGLE_FACE_COLOR)
    assert b > g > r > 0.5
    assert 0.0 < colours.FACE_OPACITY < 1.0
    s = slice_polytope(pentachoron(2.0), np.eye(4), 0.0)
    drawing = draw_slice(Figure().add_subplot(), s)
    assert drawing.balls[0].get_facecolor()[:3] == pytest.approx(colours.as_rgb(colours.BALL_COLOR))
    assert drawing.bars[0].get_facecolor()[:3] == pytest.approx(colours.as_rgb(colours.BAR_COLOR))
    fig = panels.paper_figure_3(tmp_path / "f.png", dpi=20)
    assert fig.get_facecolor()[:3] == pytest.approx(colours.as_rgb(colours.BACKGROUND))


@pytest.mark.parametrize(
    "color, rgb",
    [("#fff", (1.0, 1.0, 1.0)), (" #C8102E ", (200 / 255, 16 / 255, 46 / 255)), ((0, 0.5, 1), (0.0, 0.5, 1.0))],
)
def test_as_rgb_reads_hex_and_triples(color, rgb):
    assert colours.as_rgb(color) == pytest.approx(rgb)


@pytest.mark.parametrize("color", ["red", "#12345", (0, 0, 2), (0, 0), None])
def test_as_rgb_names_the_allowed_forms(color):
    with pytest.raises(ValueError, match=r"Expected `face` to be '#rgb', '#rrggbb' or three floats in \[0, 1\]"):
        colours.as_rgb(color, "face")


# --------------------------------------------------------------------------- scale and radii
def test_reference_radius_is_the_paper_pentachorons_and_figures_use_it():
    assert sizes.REFERENCE_RADIUS == pytest.approx(pentachoron(2.0).circumradius)
    for name in ("5-cell", "8-cell", "600-cell"):
        st = panel_style(name)
        assert st["scale"] * polytope(name).circumradius == pytest.approx(sizes.REFERENCE_RADIUS)


def test_default_radii_follow_the_displayed_edge():
    assert sizes.default_ball_radius(2.0) == pytest.approx(0.07)  # capped
    assert sizes.default_ball_radius(0.3) == pytest.approx(0.03)
    assert sizes.default_bar_radius(0.05) == pytest.approx(0.02)
    for name in ("5-cell", "24-cell", "120-cell"):
        p = polytope(name)
        st = panel_style(p)
        e = p.edges[0]
        edge = float(np.linalg.norm(p.vertices[e[0]] - p.vertices[e[1]])) * st["scale"]
        assert st["ball_radius"] == pytest.approx(sizes.default_ball_radius(edge))
        assert st["bar_radius"] == pytest.approx(sizes.default_bar_radius(st["ball_radius"]))
    # draw_slice without sizes: the reference pentachoron's
    s = slice_polytope(pentachoron(2.0), np.eye(4), 0.0)
    d = draw_slice(Figure().add_subplot(), s)
    radii = np.array([b.radius for b in d.balls]) / d.factors
    np.testing.assert_allclose(radii, sizes.default_ball_radius(2.0))


# --------------------------------------------------------------------------- camera
def _three_ndc(points, aspect):
    """NDC of a three.js PerspectiveCamera at CAMERA_POSITION looking down -z (makePerspective)."""
    near, far = camera.CAMERA_NEAR, camera.CAMERA_FAR
    top = near * math.tan(math.radians(camera.CAMERA_FOV) / 2)
    right = top * aspect
    proj = np.array([
        [near / right, 0, 0, 0],
        [0, near / top, 0, 0],
        [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
        [0, 0, -1, 0],
    ])
    view = np.eye(4)
    view[:3, 3] = -np.asarray(camera.CAMERA_POSITION)  # the inverse of the camera's translation
    h = np.c_[points, np.ones(len(points))] @ (proj @ view).T
    return h[:, :2] / h[:, 3:]


@pytest.mark.parametrize("size", [(6.0, 5.0), (4.0, 4.0), (3.0, 6.0)])  # the widget's 600 x 500, square, tall
def test_figure_projects_like_the_live_camera(size):
    s = slice_polytope(polytope("24-cell"), random_rotation(np.random.default_rng(5)), 0.1)
    scale = panel_style("24-cell")["scale"]
    fig = Figure(figsize=size, dpi=50)
    FigureCanvasAgg(fig)
    ax = fig.add_axes([0, 0, 1, 1])
    drawing = draw_slice(ax, s, scale=scale)
    fig.canvas.draw()  # the aspect is applied at draw time: the frame must survive it
    points = np.asarray(s.vertices) * scale  # displayed units
    centres = np.array([b.center for b in drawing.balls])
    fractions = ax.transAxes.inverted().transform(ax.transData.transform(centres))
    np.testing.assert_allclose(2 * fractions - 1, _three_ndc(points, size[0] / size[1]), atol=1e-9)


def test_panels_of_a_grid_share_the_live_cameras_frame():
    fig = panels.render_key_sequence("4", 2, ncols=2)
    half = camera.CAMERA_POSITION[2] * math.tan(math.radians(camera.CAMERA_FOV) / 2)
    for ax in fig.axes:
        assert ax.get_xlim() == pytest.approx((-half, half)) and ax.get_ylim() == pytest.approx((-half, half))
    assert slice_drawing.CAMERA_DISTANCE == camera.CAMERA_POSITION[2] and slice_drawing.CAMERA_FOV == camera.CAMERA_FOV
    assert camera.CAMERA_POSITION == (0.0, 0.0, 5.0)
    assert (camera.CAMERA_FOV, camera.CAMERA_NEAR, camera.CAMERA_FAR) == (40.0, 0.1, 100.0)


def test_the_look_modules_import_numpy_only():
    code = (
        "import sys, rot4d_widget.core.camera, rot4d_widget.core.colours, rot4d_widget.core.renderings\n"
        "import rot4d_widget.core.sizes, rot4d_widget.core.text\n"
        "bad = [m for m in ('matplotlib', 'ipywidgets', 'pythreejs', 'ipyevents', 'traitlets') if m in sys.modules]\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
