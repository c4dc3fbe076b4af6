"""The "sections" rendering (three orthogonal colour-mapped planes through a field's cut), without a
browser, against closed forms written out here.

A linear field's trilinear interpolant is the field itself, so what a pixel shows is known: its
ray's nearest crossing with a plane x = X, y = Y or z = Z inside the grid's box, in a cell with
eight finite nodes, coloured cmap((f - lo) / (hi - lo)); nothing where there is none.  The planes
sit at fractions of the grid's extent (first to last node).
"""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.core.renderings import RENDERINGS
from rot4d_widget.keep.pictures.ray_caster import VOLUME_RENDERINGS, render_grid
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.grid import sample_field

D = 5.0
BOX = ((-1.0, 1.0),) * 4
SIZE, LIMITS = (160, 130), ((-1.6, 1.6), (-1.3, 1.3))


def rays(size, limits):
    (x0, x1), (y0, y1) = limits
    X = x0 + (np.arange(size[0]) + 0.5) * (x1 - x0) / size[0]
    Y = y1 - (np.arange(size[1]) + 0.5) * (y1 - y0) / size[1]
    XX, YY = np.meshgrid(X, Y)
    d = np.stack([XX, YY, np.full_like(XX, -D)], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)  # (H, W, 3) from the eye (0, 0, D)


def expected(grid, f_slice, fractions, scale, shift, clim, cmap="viridis"):
    """(rgba, margin): each pixel's colour by the definition, and where a pixel's hit lies within
    a hundredth of a spacing of a cell's or the box's edge (left out of the comparison)."""
    d = rays(SIZE, LIMITS)
    eye = np.array([0.0, 0.0, D])
    vals = np.asarray(grid.values, dtype=np.float64)
    n = np.array(vals.shape)
    origin, h = np.asarray(grid.origin), grid.spacing
    finite = np.isfinite(vals)
    lo_box = np.asarray(shift) + scale * origin
    hi_box = lo_box + scale * h * (n - 1)
    best_t = np.full(d.shape[:2], np.inf)
    best_v = np.full(d.shape[:2], np.nan)
    margin = np.zeros(d.shape[:2], dtype=bool)
    for a in range(3):
        plane = lo_box[a] + fractions[a] * (hi_box[a] - lo_box[a])
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (plane - eye[a]) / d[..., a]
        P = eye + t[..., None] * d
        inside = np.all((P >= lo_box - 1e-9) & (P <= hi_box + 1e-9), axis=-1) & (t > 0)
        idx = ((P - np.asarray(shift)) / scale - origin) / h  # grid indices
        cell = np.clip(np.floor(idx).astype(int), 0, n - 2)
        near_edge = np.any(np.abs(idx - np.rint(idx)) < 1e-2, axis=-1)
        ok = inside.copy()
        for di in (0, 1):
            for dj in (0, 1):
                for dk in (0, 1):
                    i, j, k = (np.clip(cell[..., c] + o, 0, n[c] - 1) for c, o in enumerate((di, dj, dk)))
                    ok &= finite[i, j, k]
        better = ok & (t < best_t)
        p_slice = (P - np.asarray(shift)) / scale
        best_t = np.where(better, t, best_t)
        best_v = np.where(better, f_slice(p_slice), best_v)
        margin |= inside & near_edge
    rgba = np.zeros(d.shape[:2] + (4,))
    seen = np.isfinite(best_t)
    lo, hi = clim
    rgba[seen] = matplotlib.colormaps[cmap](np.clip((best_v[seen] - lo) / (hi - lo), 0.0, 1.0))
    rgba[seen, 3] = 1.0
    return rgba, margin


def linear_field(a, matrix, c0=0.0, b=0.3):
    """f = a . q + b in data coordinates, and f at slice points of the cut w = c0 after ``matrix``."""
    a = np.asarray(a, dtype=float)
    field = Field4D.from_function(lambda x, y, z, w: a[0] * x + a[1] * y + a[2] * z + a[3] * w + b, BOX)

    def f_slice(p):
        q = field.to_data(p.reshape(-1, 3), matrix, c0)
        return (q @ a + b).reshape(p.shape[:-1])

    return field, f_slice


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_each_pixel_shows_the_nearest_plane_crossing_in_a_finite_cell(seed):
    rng = np.random.default_rng(seed)
    m = np.eye(4) if seed == 0 else random_rotation(rng)
    field, f_slice = linear_field(rng.normal(size=4), m, 0.1)
    grid = sample_field(field, m, 0.1, 20)
    fractions = tuple(rng.uniform(0.15, 0.85, 3))
    scale, shift = 0.8, (0.1, -0.05, 0.3)
    clim = (-1.5, 2.0)
    image = render_grid(grid, "sections", size=SIZE, limits=LIMITS, clim=clim, scale=scale, shift=shift,
                        sections=fractions, progress=False)
    want, margin = expected(grid, f_slice, fractions, scale, shift, clim)
    keep = ~margin
    assert keep.sum() > 0.5 * keep.size
    np.testing.assert_array_equal(image[..., 3][keep], want[..., 3][keep])  # opaque where a plane is seen
    # colours: the map's, up to one step of its 256-entry table (float32 values)
    assert np.abs(image[keep] - want[keep]).max() < 0.02
    seen = want[..., 3] == 1
    assert seen.sum() > 0.1 * seen.size and (~seen).sum() > 0.1 * seen.size


def test_the_section_x_equals_X_of_f_equals_x_has_the_colour_of_X_wherever_it_is_seen():
    field = Field4D.from_function(lambda x, y, z, w: x + 0 * w, BOX)
    grid = sample_field(field, np.eye(4), 0.0, 24)
    (x0, x1) = grid.extent[0]
    fx = 0.3
    X = x0 + fx * (x1 - x0)
    # y = y0 and z = z0 lie in the padding, where the nodes are NaN: only the x plane can show
    image = render_grid(grid, "sections", size=SIZE, limits=LIMITS, cmap="magma", clim=(-2.0, 2.0),
                        sections=(fx, 0.0, 0.0), progress=False)
    seen = image[..., 3] == 1.0
    assert seen.sum() > 300
    want = np.asarray(matplotlib.colormaps["magma"]((X + 2.0) / 4.0))
    np.testing.assert_allclose(image[seen], np.broadcast_to(want, (seen.sum(), 4)), atol=1e-6)
    assert np.all(image[~seen] == 0.0)
    # where it is seen: the plane x = X between the first and last finite nodes along y and z
    ys, zs = grid.axes[1], grid.axes[2]
    fin = np.isfinite(np.asarray(grid.values)[grid.values.shape[0] // 2])
    y_lo, y_hi = ys[fin.any(axis=1)][[0, -1]]
    z_lo, z_hi = zs[fin.any(axis=0)][[0, -1]]
    d = rays(SIZE, LIMITS)
    t = (X - 0.0) / d[..., 0]
    P = np.array([0.0, 0.0, D]) + t[..., None] * d
    h = grid.spacing
    inner = (P[..., 1] > y_lo + 0.02 * h) & (P[..., 1] < y_hi - 0.02 * h) & (P[..., 2] > z_lo + 0.02 * h) \
        & (P[..., 2] < z_hi - 0.02 * h)
    outer = (P[..., 1] < y_lo - 0.02 * h) | (P[..., 1] > y_hi + 0.02 * h) | (P[..., 2] < z_lo - 0.02 * h) \
        | (P[..., 2] > z_hi + 0.02 * h)
    assert np.all(seen[inner]) and not np.any(seen[outer])
    assert inner.sum() > 0.9 * seen.sum()


def test_a_plane_facing_the_eye_shows_each_point_at_the_pixel_it_projects_to():
    field = Field4D.from_function(lambda x, y, z, w: 2.0 * y + 0 * w, BOX)  # f = 2 y on the plane z = Z
    grid = sample_field(field, np.eye(4), 0.0, 24)
    z0, z1 = grid.extent[2]
    fz = 0.8
    Z = z0 + fz * (z1 - z0)
    scale = 0.9
    image = render_grid(grid, "sections", size=SIZE, limits=LIMITS, cmap="gray", clim=(-2.0, 2.0), scale=scale,
                        sections=(0.0, 0.0, fz), progress=False)
    # a point (x, y, Z) is drawn at (x, y) D / (D - scale Z); its grey is (2 y + 2) / 4
    for x, y in ((0.3, -0.4), (-0.5, 0.6), (0.0, 0.1), (0.7, 0.7)):
        k = D / (D - scale * Z)
        X, Y = scale * x * k, scale * y * k
        (a, b), (c, e) = LIMITS
        col = int((X - a) / (b - a) * SIZE[0])
        row = int((e - Y) / (e - c) * SIZE[1])
        # the pixel's centre sees the point a fraction of a pixel away: f = 2 y changes by 2 / pixel size
        grey = image[row, col, 0]
        y_seen = (grey * 4.0 - 2.0) / 2.0
        pixel_y = (e - c) / SIZE[1] / (scale * k)
        assert image[row, col, 3] == 1.0 and abs(y_seen - y) <= pixel_y + 4.0 / 255, (x, y, y_seen)


def test_nan_cells_leave_holes_through_which_the_farther_plane_shows():
    vals = np.fromfunction(lambda i, j, k, t: i + 0.0 * j, (9, 9, 9, 3))  # f = x index = 4 (x + 1)
    vals[4, 4, 6, :] = np.nan  # a NaN node at (0, 0, 0.5)
    field = Field4D(vals, axes="xyzw", extent=BOX)
    grid = sample_field(field, np.eye(4), 0.0, 17)  # nodes every 1/8: on the data's nodes
    fz = (0.5 - grid.extent[2][0]) / (grid.extent[2][1] - grid.extent[2][0])
    fx = (-0.25 - grid.extent[0][0]) / (grid.extent[0][1] - grid.extent[0][0])
    clim = (0.0, 8.0)
    full = render_grid(grid, "sections", size=SIZE, limits=LIMITS, clim=clim, sections=(0.0, 0.0, fz),
                       progress=False)
    both = render_grid(grid, "sections", size=SIZE, limits=LIMITS, clim=clim, sections=(fx, 0.0, fz),
                       progress=False)
    # the NaN node's point (0, 0, 0.5) projects to the picture's centre: a hole there, plane around it
    (a, b), (c, e) = LIMITS
    col, row = int(-a / (b - a) * SIZE[0]), int(e / (e - c) * SIZE[1])
    assert full[row, col, 3] == 0.0 and full[row + 40, col + 40, 3] == 1.0
    hole = full[..., 3] == 0.0
    hole_px = hole[row - 30:row + 30, col - 30:col + 30].sum()
    assert hole_px > 100
    # pixel for pixel as the definition says (the grid's own NaN nodes, cells of eight finite nodes)
    for fractions, image in (((0.0, 0.0, fz), full), ((fx, 0.0, fz), both)):
        want, margin = expected(grid, lambda p: 4.0 * (p[..., 0] + 1.0), fractions, 1.0, (0, 0, 0), clim)
        keep = ~margin
        np.testing.assert_array_equal(image[..., 3][keep], want[..., 3][keep])
        assert np.abs(image[keep] - want[keep]).max() < 0.02
    # with the plane x = -0.25 behind: through the hole, where a ray meets it, the colour of x = -0.25
    want = np.asarray(matplotlib.colormaps["viridis"](3.0 / 8.0))
    through = hole & (both[..., 3] == 1.0)
    assert through.sum() > 40
    np.testing.assert_allclose(both[through], np.broadcast_to(want, (through.sum(), 4)), atol=1e-6)


def test_render_state_draws_sections_through_the_camera_and_checks_them():
    field = Field4D.from_function(lambda x, y, z, w: x + 0 * w, BOX, name="f")
    state = RotationState()
    fig = render_state(state, field, rendering="sections", sections=(0.5, 0.5, 0.9), size=(200, 160))
    assert [im.get_gid() for im in fig.axes[0].images] == ["sections"]
    with pytest.raises(ValueError, match="fractions"):
        render_state(state, field, rendering="sections", sections=(0.5, 0.5, 1.5))
    assert RENDERINGS == ("surface", "volume", "mip", "sections") and "sections" in VOLUME_RENDERINGS
