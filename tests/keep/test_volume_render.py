"""Maximum intensity and volume renderings of a field's cut, without a browser, against closed forms.

The camera is the static renders': the eye at (0, 0, D) looking down -z, a point (x, y, z) drawn at
(x, y) D / (D - z) in the picture plane.  A bright blob lands on the pixel its centre projects to; a
constant field's MIP is that constant's colour inside the box's silhouette and nothing outside; a
uniform medium's opacity along a ray is Beer-Lambert's 1 - exp(-sigma l) of the ray's length l
through the box (each computed here, not by the package); rendering="surface" is today's picture.
"""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from rot4d_widget.core.camera import CAMERA_FOV
from rot4d_widget.core.sizes import REFERENCE_RADIUS
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.core.colours import default_clim
from rot4d_widget.keep.pictures.ray_caster import render_grid
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.grid import sample_field

D = 5.0  # the eye's distance
BOX = ((-1.0, 1.0),) * 4


def project(p, scale=1.0, shift=(0.0, 0.0, 0.0)):
    """Picture-plane (X, Y) of slice point p placed at shift + scale p."""
    P = np.asarray(shift, dtype=float) + scale * np.asarray(p, dtype=float)
    return P[:2] * D / (D - P[2])


def to_pixel(X, Y, size, limits):
    """(column, row) of the picture-plane point (X, Y), pixel centres at integers."""
    (x0, x1), (y0, y1) = limits
    w, h = size
    return (X - x0) / (x1 - x0) * w - 0.5, (y1 - Y) / (y1 - y0) * h - 0.5


def pixels(fig):
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


def camera_limits(size):
    limit = D * math.tan(math.radians(CAMERA_FOV) / 2)
    aspect = size[0] / size[1]
    return (-limit * aspect, limit * aspect), (-limit, limit)


def brightest(image):
    """(column, row): the centroid of the pixels within 2 % of the brightest."""
    lum = image[..., :3].sum(axis=-1) * image[..., 3]
    rows, cols = np.nonzero(lum >= 0.98 * lum.max())
    return cols.mean(), rows.mean()


def blob(q0, sigma=0.08):
    return lambda x, y, z, w: np.exp(-((x - q0[0]) ** 2 + (y - q0[1]) ** 2 + (z - q0[2]) ** 2
                                       + (w - q0[3]) ** 2) / (2 * sigma**2))


# ---------------------------------------------------------------- a blob lands where its centre projects
def test_a_blob_lands_on_the_pixel_its_centre_projects_to():
    rng = np.random.default_rng(2)
    q0 = np.array([0.3, -0.25, 0.35, 0.1])
    field = Field4D.from_function(blob(q0), BOX)
    size, limits = (150, 125), ((-1.3, 1.5), (-1.1, 1.2))
    for _ in range(2):
        m = random_rotation(rng)
        r = m @ q0  # the blob's centre after the turn: slice point r[:3] of the cut w = r[3]
        grid = sample_field(field, m, r[3], 48)
        scale, shift = 0.9, np.array([0.1, -0.05, 0.2])
        for mode in ("mip", "volume"):
            image = render_grid(grid, mode, size=size, limits=limits, cmap="gray", scale=scale, shift=shift,
                                pixels_per_ray=1)
            col, row = to_pixel(*project(r[:3], scale, shift), size, limits)
            c, rr = brightest(image)
            assert abs(c - col) < 1.5 and abs(rr - row) < 1.5, (mode, c, rr, col, row)


def test_render_state_puts_the_blob_where_the_camera_projects_it():
    q0 = np.array([0.3, -0.2, 0.4, 0.0])
    field = Field4D.from_function(blob(q0), BOX)
    size = (300, 250)
    limits = camera_limits(size)
    scale = REFERENCE_RADIUS / field.size  # the live view's displayed size
    col, row = to_pixel(*project(q0[:3], scale), size, limits)
    for mode in ("mip", "volume"):
        fig = render_state(RotationState(), field, rendering=mode, cmap="gray", frame="camera", size=size,
                           show_bars=False, background="black", axis_labels=False)
        img = pixels(fig) / 255.0
        # the picture is the first size[0] columns; its colour bar is in a strip right of it
        assert img.shape[0] == size[1] and img.shape[1] > size[0]
        c, r = brightest(img[:, :size[0]])
        assert abs(c - col) < 2.0 and abs(r - row) < 2.0, (mode, c, r, col, row)


# ---------------------------------------------------------------- a constant's MIP fills the silhouette
def constant_field(value=1.0):
    return Field4D(np.full((9, 9, 9, 5), value), axes="xyzw", extent=BOX)


@pytest.mark.parametrize("pixels_per_ray", [1, "auto"])
def test_a_constant_fields_mip_is_its_colour_inside_the_silhouette(pixels_per_ray):
    grid = sample_field(constant_field(1.0), np.eye(4), 0.0, 16)
    scale = 0.8
    size, limits = (200, 160), ((-1.5, 1.5), (-1.2, 1.2))
    image = render_grid(grid, "mip", size=size, limits=limits, cmap="viridis", clim=(0.0, 2.0), scale=scale,
                        pixels_per_ray=pixels_per_ray)
    # the cube [-s, s]^3 seen from (0, 0, D): its silhouette is its front face's projection
    s = scale * 1.0
    half = s * D / (D - s)
    (x0, x1), (y0, y1) = limits
    px = (x1 - x0) / size[0]
    X = x0 + (np.arange(size[0]) + 0.5) * px
    Y = y1 - (np.arange(size[1]) + 0.5) * px
    reach = np.maximum(np.abs(X)[None, :], np.abs(Y)[:, None])
    inside, outside = reach < half - 3 * px, reach > half + 3 * px
    want = np.asarray(matplotlib.colormaps["viridis"](0.5))
    np.testing.assert_allclose(image[inside], np.broadcast_to(want, (inside.sum(), 4)), atol=1e-6)
    assert np.all(image[outside] == 0.0)
    assert inside.sum() > 1000 and outside.sum() > 1000


# ---------------------------------------------------------------- Beer-Lambert through a uniform medium
def cube_lengths(size, limits, s):
    """Length of each pixel's ray through the cube [-s, s]^3 (slabs, written out here)."""
    (x0, x1), (y0, y1) = limits
    X = x0 + (np.arange(size[0]) + 0.5) * (x1 - x0) / size[0]
    Y = y1 - (np.arange(size[1]) + 0.5) * (y1 - y0) / size[1]
    XX, YY = np.meshgrid(X, Y)
    d = np.stack([XX, YY, np.full_like(XX, -D)], axis=-1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    eye = np.array([0.0, 0.0, D])
    with np.errstate(divide="ignore"):
        ta, tb = (-s - eye) / d, (s - eye) / d
    t_in = np.minimum(ta, tb).max(axis=-1)
    t_out = np.maximum(ta, tb).min(axis=-1)
    return np.maximum(t_out - t_in, 0.0)


def test_a_uniform_mediums_opacity_follows_beer_lambert():
    grid = sample_field(constant_field(1.0), np.eye(4), 0.0, 16)
    scale, density = 0.8, 2.0
    size, limits = (120, 100), ((-1.5, 1.5), (-1.25, 1.25))
    image = render_grid(grid, "volume", size=size, limits=limits, cmap="viridis", clim=(0.0, 1.0), scale=scale,
                        density=density, step=0.5, pixels_per_ray=1)
    side = scale * max(b - a for a, b in grid.extent)  # the grid's longest side, scene units
    sigma = density / side  # extinction at the top of the ramp (value 1 = clim[1])
    length = cube_lengths(size, limits, scale)
    tau = -np.log1p(-np.minimum(image[..., 3], 1 - 1e-15))
    through = length > 0.05
    # a sample counts the whole piece of ray around it: each end of the medium within half a step
    dt = 0.5 * grid.spacing * scale
    assert np.all(np.abs(tau[through] - sigma * length[through]) <= sigma * dt + 1e-9)
    assert np.all(image[length == 0.0][..., 3] == 0.0)
    # the central ray runs straight down the cube: 2 s exactly, samples ending on the faces
    centre = image[size[1] // 2 - 1:size[1] // 2 + 1, size[0] // 2 - 1:size[0] // 2 + 1, 3]
    np.testing.assert_allclose(centre, 1 - math.exp(-sigma * 2 * scale), atol=2e-3)
    # opacity grows with the length through the medium
    edges = np.quantile(length[through], np.linspace(0.0, 1.0, 6))
    which = np.clip(np.searchsorted(edges, length[through], side="right") - 1, 0, 4)
    means = [image[..., 3][through][which == b].mean() for b in range(5)]
    assert np.all(np.diff(means) > 0), means
    # the colour of a uniform medium is its colour on the map
    want = np.asarray(matplotlib.colormaps["viridis"](1.0))[:3]
    np.testing.assert_allclose(image[through][:, :3], np.broadcast_to(want, (through.sum(), 3)), atol=1e-6)


# ---------------------------------------------------------------- render_state: the default is today's
def test_rendering_surface_is_the_default_pixel_for_pixel():
    field = Field4D.from_function(blob(np.array([0.2, 0.0, -0.1, 0.0]), 0.3), BOX, levels=0.5)
    state = RotationState()
    a = pixels(render_state(state, field, size=(200, 160)))
    b = pixels(render_state(state, field, size=(200, 160), rendering="surface", cmap="viridis", clim=None))
    np.testing.assert_array_equal(a, b)
    c = pixels(render_state(state, "24-cell", size=(200, 160)))
    np.testing.assert_array_equal(c, pixels(render_state(state, "24-cell", size=(200, 160), rendering="surface")))


def test_render_state_saves_each_rendering_and_a_stack(tmp_path):
    field = Field4D.from_function(blob(np.array([0.2, 0.0, -0.1, 0.0]), 0.3), BOX)
    state = RotationState()
    for mode in ("mip", "volume", "sections"):
        path = tmp_path / f"{mode}.png"
        fig = render_state(state, field, path, rendering=mode, size=(160, 120))
        assert path.exists() and [im.get_gid() for im in fig.axes[0].images] == [mode]
    fig = render_state(state, field, rendering="mip", slices=3, size=(200, 160))
    assert len(fig.axes[0].images) == 1


def test_bad_renderings_are_named():
    field = constant_field()
    state = RotationState()
    with pytest.raises(ValueError, match="'surface', 'volume', 'mip', 'sections'"):
        render_state(state, field, rendering="isosurface")
    with pytest.raises(TypeError, match="sample"):
        render_state(state, "5-cell", rendering="mip")
    with pytest.raises(ValueError, match="viridis"):
        render_state(state, field, rendering="mip", cmap="viridiss")
    with pytest.raises(ValueError, match="lo < hi"):
        render_state(state, field, rendering="mip", clim=(1.0, 0.0))


def test_the_default_clim_is_robust_to_outliers():
    v = np.r_[np.linspace(0.0, 10.0, 1001), 1e12, -1e12, np.nan]
    lo, hi = default_clim(v)
    assert 0.0 <= lo < 0.2 and 9.8 < hi <= 10.0
    assert default_clim(np.full(5, 3.0)) == (1.5, 4.5)
    assert default_clim(np.full(5, np.nan)) == (0.0, 1.0)


@pytest.mark.parametrize("rendering", ["mip", "volume", "sections"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_compiled_caster_draws_numpys_picture(rendering, seed):
    """The numba kernel (ray by ray) against numpy's passes (every ray at once), on turned cuts with
    holes of NaN: the same pixels, within the opacity at which a volume ray stops (1e-4)."""
    from matplotlib import colormaps

    from rot4d_widget.keep.pictures import ray_caster

    pytest.importorskip("numba")
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.0, 1.0, (9, 8, 10, 7))
    a[2:4, 3:5, 1:3, :] = np.nan  # a hole the rays must see through
    f = Field4D(a, axes="xyzw", extent=BOX)
    m = random_rotation(rng)
    g = sample_field(f, m, 0.1, 20)
    args = (g, rendering, colormaps["magma"], (0.2, 0.8), (90, 70), camera_limits((90, 70)), 1.3,
            np.array([0.1, -0.2, 0.3]), D, 4.0, 0.5, np.array([0.3, 0.5, 0.7]))
    compiled = ray_caster._cast(*args)
    plain = ray_caster._cast(*args, compiled=False)
    assert (plain[..., 3] > 0).sum() > 500
    np.testing.assert_allclose(compiled, plain, atol=1e-4 if rendering == "volume" else 1e-12)
