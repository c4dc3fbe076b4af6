"""Volume renderings of a field's cut without a browser: ray casting through a `FieldGrid`.

The camera is the static renders' and the live view's (`rot4d_widget.keep.pictures.slice_drawing`):
the eye at (0, 0, ``distance``) looking down -z through the picture plane z = 0 (`pixel_rays`),
the grid placed in that scene at ``shift + scale * p``.  `render_grid` casts all pixels' rays at
once (a loop over depth, never over pixels; numba kernels when numba is installed), samples the
grid's trilinear interpolant every ``step`` spacings inside its box and counts a sample only in
a cell whose eight nodes are finite.  The renderings, `VOLUME_RENDERINGS`: ``"mip"``,
``"volume"`` (emission-absorption, front to back) and ``"sections"`` (three orthogonal planes),
defined as the page's shader defines them, so both show one picture (docs/design.md, "The cut as
a grid, and the ray-cast renderings").  Results are straight (not premultiplied) RGBA,
(H, W, 4) float64 in [0, 1].
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import map_coordinates

from ...core import camera, colours, renderings
from ...core.colours import default_clim
from ...core.progress import progress as make_progress
from ...core.renderings import DEFAULT_DENSITY, DEFAULT_SECTIONS
from ...core.sizes import REFERENCE_RADIUS
from ...sources.protocol import class_name, inner_source
from . import ray_caster_kernels

#: How far the live view's camera is from the centre (`rot4d_widget.keep.pictures.slice_drawing.CAMERA_DISTANCE`,
#: the same number: that module imports matplotlib, which the widget's import does not need)
CAMERA_DISTANCE = float(camera.CAMERA_POSITION[2])

__all__ = ["VOLUME_RENDERINGS", "pixel_rays", "render_grid", "composite", "draw_volume", "cut_grids"]

# RENDERINGS (what `render_state` draws for a field), check_rendering and the defaults DEFAULT_DENSITY
# and DEFAULT_SECTIONS are core.renderings', view_rotation core.camera's and default_clim core.colours'
# (the live view uses them too).
#: The renderings ray-cast here.
VOLUME_RENDERINGS = ("volume", "mip", "sections")
#: Samples handed to one interpolation call (memory: about 200 bytes each while they are worked on).
_BATCH_POINTS = 400_000
#: A ray this transparent no longer changes a pixel (front-to-back compositing stops for it).
_OPAQUE = 1e-4


def pixel_rays(size, limits, distance: float = CAMERA_DISTANCE):
    """``(eye, directions)``: the eye (3,) and the unit direction (H, W, 3) float64 of each pixel's
    ray for a picture of ``size`` = (W, H) pixels whose picture plane spans ``limits`` =
    ((x0, x1), (y0, y1)) (row 0 at the top, y1)."""
    w, h = (int(v) for v in size)
    (x0, x1), (y0, y1) = limits
    X = x0 + (np.arange(w) + 0.5) * ((x1 - x0) / w)
    Y = y1 - (np.arange(h) + 0.5) * ((y1 - y0) / h)
    d = np.empty((h, w, 3))
    d[..., 0] = X[None, :]
    d[..., 1] = Y[:, None]
    d[..., 2] = -float(distance)
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    return np.array([0.0, 0.0, float(distance)]), d


def _cell_flags(values):
    """(nx, ny, nz) bool: True at node (i, j, k) when the cell it is the lowest corner of has eight
    finite nodes (the last layer along each axis, which starts no cell, is False)."""
    ok = np.isfinite(values)
    out = np.zeros(values.shape, dtype=bool)
    out[:-1, :-1, :-1] = (ok[:-1, :-1, :-1] & ok[1:, :-1, :-1] & ok[:-1, 1:, :-1] & ok[:-1, :-1, 1:]
                          & ok[1:, 1:, :-1] & ok[1:, :-1, 1:] & ok[:-1, 1:, 1:] & ok[1:, 1:, 1:])
    return out


def _trilinear(flat, shape, x, y, z):
    """(values, cell): the trilinear interpolant of the C-ordered array ``flat`` of ``shape`` at the
    index coordinates x, y, z (1-D float64, each within [0, n - 1]) -- `map_coordinates` of order 1,
    by eight gathers -- and the flat index of each point's cell (its lowest corner)."""
    nx, ny, nz = shape
    ix = np.minimum(x.astype(np.intp), nx - 2)
    iy = np.minimum(y.astype(np.intp), ny - 2)
    iz = np.minimum(z.astype(np.intp), nz - 2)
    fx, fy, fz = x - ix, y - iy, z - iz
    cell = (ix * ny + iy) * nz + iz
    sx, sy = ny * nz, nz

    def lerp_z(off):
        lo = flat.take(cell + off)
        return lo + (flat.take(cell + (off + 1)) - lo) * fz

    c0 = lerp_z(0)
    c0 += (lerp_z(sy) - c0) * fy
    c1 = lerp_z(sx)
    c1 += (lerp_z(sx + sy) - c1) * fy
    c0 += (c1 - c0) * fx
    return c0, cell


def _ray_pitch(pixels_per_ray, grid, size, limits, scale, shift, distance):
    """Pixels per ray side: ``pixels_per_ray``, or ("auto") the most that keeps two rays per grid
    spacing where the grid is nearest the eye (a ray per pixel for a small picture)."""
    if pixels_per_ray != "auto":
        return _check_pitch(pixels_per_ray)
    w_px = int(size[0])
    (x0, x1), _ = limits
    near = float(shift[2]) + scale * (float(grid.origin[2]) + grid.spacing * (grid.values.shape[2] - 1))
    if near >= distance:
        return 1
    voxel_px = scale * grid.spacing * distance / (distance - near) * w_px / (x1 - x0)
    return max(1, int(voxel_px // 2))


def _check_pitch(pixels_per_ray) -> int:
    if isinstance(pixels_per_ray, bool) or not isinstance(pixels_per_ray, (int, np.integer)) or pixels_per_ray < 1:
        raise ValueError(f"Expected `pixels_per_ray` to be an int >= 1 or 'auto', got {pixels_per_ray!r}")
    return int(pixels_per_ray)


def _progress_sink(progress, description: str):
    """``(tick(fraction), close())`` for ``progress``: True a bar (`rot4d_widget.core.progress`,
    shown once the work took a second), False nothing, a callable ``progress(fraction)``."""
    if progress is True:
        bar = make_progress(1000, description)
        return (lambda f: bar.update(int(round(1000 * min(1.0, f))) - bar.count)), bar.close
    if progress is False or progress is None:
        return (lambda f: None), (lambda: None)
    if callable(progress):
        return progress, (lambda: None)
    raise TypeError(f"Expected `progress` to be True, False or a callable (fraction done), got {progress!r}")


def render_grid(grid, rendering: str, *, size, limits, cmap="viridis", clim=None, scale: float = 1.0,
                shift=(0.0, 0.0, 0.0), distance: float = CAMERA_DISTANCE, density: float = DEFAULT_DENSITY,
                step: float = 0.5, pixels_per_ray=1, sections=DEFAULT_SECTIONS, progress=True,
                view=None) -> np.ndarray:
    """(H, W, 4) straight RGBA: ``grid`` (a `rot4d_widget.sources.field.grid.FieldGrid`) ray-cast as
    ``rendering`` (``"mip"``, ``"volume"`` or ``"sections"``, defined in docs/design.md) for a picture of
    ``size`` = (W, H) pixels whose picture plane spans ``limits`` = ((x0, x1), (y0, y1)), the grid
    placed at ``shift + scale * p``.  ``cmap``: a matplotlib colour map name; ``clim``: (lo, hi),
    default `default_clim` of the grid's values (1st-99th percentile); ``density``: the volume's
    optical depth across the grid's longest side at the top of the ramp; ``step``: samples every
    ``step`` spacings along a ray; ``sections``: (fx, fy, fz), the planes' places as fractions of
    the grid's extent.  ``pixels_per_ray``: one ray for every p x p pixels, the picture between
    the rays' pixels bilinear in premultiplied colour (1, the default: a ray through every pixel's
    centre, the full resolution); "auto": two rays per grid spacing where the grid is nearest, at
    most one per pixel (sections: always one per pixel).  The rays are cast by a compiled kernel
    (`rot4d_widget.keep.pictures.ray_caster_kernels`) when numba is installed, else in numpy: the same picture.
    ``progress``: True a progress bar once the casting took a second
    (`rot4d_widget.core.progress`), False none, or a callable given the fraction done (0 to 1).
    ``view``: (3, 3) the camera's rotation (`view_rotation` of its position; None: the identity,
    the eye on +z): the rays are turned back into the scene, so the grid is seen from there."""
    # matplotlib's colour map registry: the keep wing's, looked up by name
    from matplotlib import colormaps

    if rendering not in VOLUME_RENDERINGS:
        raise ValueError(f"Expected `rendering` to be one of {', '.join(map(repr, VOLUME_RENDERINGS))}, "
                         f"got {rendering!r}")
    colormap = colormaps[colours.check_cmap(cmap)]
    fractions = np.asarray(renderings.check_sections(sections), dtype=np.float64)
    vals = np.asarray(grid.values)
    clim = default_clim(vals) if clim is None else colours.check_clim(clim)
    w_px, h_px = (int(v) for v in size)
    if grid.empty or min(vals.shape) < 2:
        return np.zeros((h_px, w_px, 4))
    scale = float(scale)
    shift = np.asarray(shift, dtype=np.float64)
    tick, close = _progress_sink(progress, f"ray casting ({rendering})")
    try:
        if rendering == "sections":
            pitch = 1 if pixels_per_ray == "auto" else _check_pitch(pixels_per_ray)
        else:
            pitch = _ray_pitch(pixels_per_ray, grid, size, limits, scale, shift, distance)
        args = (grid, rendering, colormap, clim)
        view = np.eye(3) if view is None else np.asarray(view, dtype=np.float64).reshape(3, 3)
        rest = (scale, shift, distance, density, step, fractions, tick, view)
        if pitch == 1:
            out = _cast(*args, (w_px, h_px), limits, *rest)
            tick(1.0)
            return out
        # rays through the centres of p x p blocks (the last block may hang over the picture's edge)
        (x0, x1), (y0, y1) = limits
        cw, ch = -(-w_px // pitch), -(-h_px // pitch)
        coarse_limits = ((x0, x0 + (x1 - x0) * cw * pitch / w_px), (y1 - (y1 - y0) * ch * pitch / h_px, y1))
        small = _cast(*args, (cw, ch), coarse_limits, *rest)
        pre = np.concatenate([small[..., :3] * small[..., 3:4], small[..., 3:4]], axis=-1)
        r = (np.arange(h_px) + 0.5) / pitch - 0.5  # a pixel's centre in the rays' picture, in rays
        c = (np.arange(w_px) + 0.5) / pitch - 0.5
        rr, cc = np.meshgrid(r, c, indexing="ij")
        big = np.stack([map_coordinates(pre[..., i], [rr, cc], order=1, mode="nearest") for i in range(4)],
                       axis=-1)
        a = big[..., 3:4]
        rgb = np.where(a > 0, big[..., :3] / np.where(a > 0, a, 1.0), 0.0)
        tick(1.0)
        return np.clip(np.concatenate([rgb, a], axis=-1), 0.0, 1.0)
    finally:
        close()


def _box_entry(eye, dirs, lo_box, hi_box):
    """``(t_in, t_out)`` (n,): where each ray ``eye + t dirs`` (dirs (n, 3), unit) enters and leaves
    the box [lo_box, hi_box] (slabs; a zero component never crosses its pair), t_in >= 0 (never
    behind the eye); t_out <= t_in when the ray misses the box."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dirs
        t1, t2 = (lo_box - eye) * inv, (hi_box - eye) * inv
    flat_dir = dirs == 0.0
    inside = (eye >= lo_box) & (eye <= hi_box)
    t1 = np.where(flat_dir, np.where(inside, -np.inf, np.inf), t1)
    t2 = np.where(flat_dir, np.where(inside, np.inf, -np.inf), t2)
    return np.maximum(np.minimum(t1, t2).max(axis=1), 0.0), np.maximum(t1, t2).min(axis=1)


def _cast(grid, rendering, colormap, clim, size, limits, scale, shift, distance, density, step, fractions,
          tick=lambda f: None, view=None, *, compiled: bool = True):
    """`render_grid` with a ray through every pixel's centre; ``tick(fraction)`` as it goes; ``view``
    the camera's rotation (None: the identity).  The compiled kernel's picture
    (`rot4d_widget.keep.pictures.ray_caster_kernels.cast`, ray by ray) when numba is there and ``compiled``, else
    numpy's (every ray at once, a step at a time)."""
    view = np.eye(3) if view is None else np.asarray(view, dtype=np.float64).reshape(3, 3)
    if compiled:
        out = ray_caster_kernels.cast(grid, rendering, colormap, clim, size, limits, scale, shift, distance, density,
                                  step, fractions, tick, view, cells=_cell_flags(np.asarray(grid.values)),
                                  opaque=_OPAQUE)
        if out is not None:
            return out
    vals = np.asarray(grid.values)
    spacing = float(grid.spacing)
    w_px, h_px = size
    out = np.zeros((h_px, w_px, 4))
    shape = vals.shape
    lo_box = shift + scale * np.asarray(grid.origin, dtype=np.float64)
    hi_box = lo_box + scale * spacing * (np.asarray(shape) - 1)
    eye, dirs = pixel_rays(size, limits, distance)
    dirs = dirs.reshape(-1, 3)
    if not np.array_equal(view, np.eye(3)):  # the rays back into the scene: p_scene = view.T p_camera
        eye, dirs = view.T @ eye, dirs @ view
    t_in, t_out = _box_entry(eye, dirs, lo_box, hi_box)
    hit = np.flatnonzero(t_out > t_in)
    if not len(hit):
        return out
    flat = np.where(np.isfinite(vals), vals, 0.0).astype(np.float64).ravel()
    cells = _cell_flags(vals).ravel()
    t_in, t_out = t_in[hit], t_out[hit]
    a0 = ((eye - shift) / scale - np.asarray(grid.origin, dtype=np.float64)) / spacing  # the eye, grid indices
    b = dirs[hit] / (scale * spacing)  # grid indices per scene unit along each ray
    upper = np.asarray(shape, dtype=np.float64) - 1
    lo, hi = clim
    if rendering == "sections":
        best_t, best_v = _sections(flat, cells, shape, a0, b, t_in, t_out, upper * fractions, scale * spacing)
        seen = np.isfinite(best_t)
        rgba = np.zeros((len(hit), 4))
        rgba[seen] = colormap(np.clip((best_v[seen] - lo) / (hi - lo), 0.0, 1.0))
        rgba[seen, 3] = 1.0
        out.reshape(-1, 4)[hit] = rgba
        return out
    dt = step * spacing * scale  # scene units per sample
    n_steps = int(math.ceil(float((t_out - t_in).max()) / dt))
    mip = rendering == "mip"
    best = np.full(len(hit), -np.inf)
    colour = np.zeros((len(hit), 3))
    trans = np.ones(len(hit))
    live = np.arange(len(hit))  # rays still worth sampling
    extinction = float(density) / (scale * spacing * (max(shape) - 1))  # per scene unit at ramp 1
    k = 0
    while k < n_steps and len(live):
        batch = max(1, min(n_steps - k, _BATCH_POINTS // len(live)))
        start = t_in[live][None, :] + (k + np.arange(batch))[:, None] * dt
        piece = np.clip(t_out[live][None, :] - start, 0.0, dt)  # the ray's length in each step
        t_mid = (start + 0.5 * piece).ravel()
        bl = b[live]
        xyz = [np.clip(a0[c] + t_mid * np.tile(bl[:, c], batch), 0.0, upper[c]) for c in range(3)]
        v, cell = _trilinear(flat, shape, *xyz)
        v = v.reshape(piece.shape)
        ok = (piece > 0) & cells.take(cell).reshape(piece.shape)
        if mip:
            best[live] = np.maximum(best[live], np.where(ok, v, -np.inf).max(axis=0))
        else:
            x = np.clip((v - lo) / (hi - lo), 0.0, 1.0)
            alpha = np.where(ok, -np.expm1(-extinction * x * piece), 0.0)  # (batch, rays)
            rgb = np.asarray(colormap(x))[..., :3]
            # front to back within the batch: what reaches sample j is T times the (1 - alpha) before it
            before = np.cumprod(np.vstack([np.ones((1, len(live))), 1.0 - alpha[:-1]]), axis=0)
            colour[live] += trans[live][:, None] * np.einsum("br,brc->rc", before * alpha, rgb)
            trans[live] *= before[-1] * (1.0 - alpha[-1])
            live = live[trans[live] > _OPAQUE]
        k += batch
        tick(k / n_steps)
    rgba = np.zeros((len(hit), 4))
    if mip:
        seen = np.isfinite(best)
        rgba[seen] = colormap(np.clip((best[seen] - lo) / (hi - lo), 0.0, 1.0))
        rgba[seen, 3] = 1.0
    else:
        a = 1.0 - trans
        rgba[:, :3] = np.where(a[:, None] > 0, colour / np.where(a > 0, a, 1.0)[:, None], 0.0)
        rgba[:, 3] = a
    out.reshape(-1, 4)[hit] = np.clip(rgba, 0.0, 1.0)
    return out


def _sections(flat, cells, shape, a0, b, t_in, t_out, planes, unit):
    """``(t, v)`` (n,): for each ray ``a0 + t b`` in grid indices (``b`` (n, 3) per scene unit,
    inside the box for t_in <= t <= t_out), the nearest t at which it crosses one of the planes
    index_a = ``planes[a]`` in a cell of eight finite nodes (``cells``), and the trilinear value
    there; t = inf, v = NaN for a ray that crosses none.  ``unit``: scene units per spacing (the
    slack of a millionth of a spacing at the box's faces)."""
    n = len(t_in)
    best_t = np.full(n, np.inf)
    best_v = np.full(n, np.nan)
    slack = 1e-6 * unit
    upper = np.asarray(shape, dtype=np.float64) - 1
    for a in range(3):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (planes[a] - a0[a]) / b[:, a]
        rays = np.flatnonzero((b[:, a] != 0.0) & (t >= t_in - slack) & (t <= t_out + slack) & (t < best_t))
        if not len(rays):
            continue
        tr = t[rays]
        xyz = [np.full(len(rays), planes[a]) if c == a else np.clip(a0[c] + tr * b[rays, c], 0.0, upper[c])
               for c in range(3)]
        v, cell = _trilinear(flat, shape, *xyz)
        ok = cells.take(cell)
        rays, tr, v = rays[ok], tr[ok], v[ok]
        best_t[rays], best_v[rays] = tr, v
    return best_t, best_v


def composite(images) -> np.ndarray:
    """Straight RGBA pictures (H, W, 4), listed back to front, painted over one another (the
    "over" operator): one straight RGBA picture."""
    images = list(images)
    acc = np.zeros_like(images[0]) if images else None
    for im in images:
        a = im[..., 3:4]
        rgb = im[..., :3] * a + acc[..., :3] * acc[..., 3:4] * (1.0 - a)
        alpha = a + acc[..., 3:4] * (1.0 - a)
        acc = np.concatenate([np.where(alpha > 0, rgb / np.where(alpha > 0, alpha, 1.0), 0.0), alpha], axis=-1)
    return acc


def cut_grids(stack, data, matrix):
    """The grids (`FieldGrid`, one per slice of ``data``, the stack's slice at ``matrix``) of the
    cuts of ``stack``'s field: its inner source's ``sample(matrix, w)`` at each cut w (the source
    protocol's optional ``sample``; a TypeError naming it for a source without)."""
    inner = inner_source(stack)
    sample = inner.sample
    if not callable(sample):
        raise TypeError(f"A volume rendering needs a source sampled on a grid (a Field4D: `sample`), "
                        f"got {class_name(inner)}")
    return [sample(matrix, float(w)) for w in np.asarray(data.cuts, dtype=np.float64)]


def grids_clim(grids) -> tuple:
    """`default_clim` of the finite values of all ``grids`` ((0, 1) when every one is empty)."""
    finite = [np.asarray(g.values)[np.isfinite(g.values)] for g in grids if not g.empty]
    return default_clim(np.concatenate(finite)) if finite else (0.0, 1.0)


def draw_volume(ax, stack, data, matrix, rendering: str, *, size, cmap="viridis", clim=None,
                density: float = DEFAULT_DENSITY, sections=DEFAULT_SECTIONS, grids=None, progress=True, view=None):
    """Paint the cut(s) of ``stack``'s field (a `StackSource` whose inner source has ``sample``,
    like `Field4D.sample`) on ``ax`` as ``rendering`` ("mip", "volume" or "sections"): every slice
    of ``data`` (the stack's slice at ``matrix``) sampled at its cut (``grids``: sampled before,
    `cut_grids`) and placed as the live view places it, ray-cast at ``size`` = (W, H) pixels over
    the axes' limits, slices composited back to front by the depth of their centres, one image
    under the box's bars.  ``clim`` None: the 1st-99th percentile of the finite values of all the
    cuts (`grids_clim`).  ``progress``: as `render_grid`'s, one bar for the sampling and every
    slice.  Returns the ``AxesImage``, whose ``get_clim()`` is the (lo, hi) coloured (None when
    no cut meets the data)."""
    n = len(data.cuts)
    tick, close = _progress_sink(progress, f"rendering the cut ({rendering})")
    try:
        if grids is None:
            grids = cut_grids(stack, data, matrix)
        tick(1.0 / (n + 1))
        if clim is None:
            clim = grids_clim(grids)
        scale = REFERENCE_RADIUS / stack.size  # source units -> displayed units (the live view's)
        centres = np.asarray(data.centres, dtype=np.float64).reshape(-1, 3)
        scales = np.asarray(data.scales, dtype=np.float64).ravel()
        limits = (tuple(ax.get_xlim()), tuple(ax.get_ylim()))
        depth = centres[:, 2] if view is None else (centres @ np.asarray(view, dtype=np.float64).reshape(3, 3).T)[:, 2]
        order = np.argsort(depth, kind="stable") if n > 1 else np.arange(n)
        images = []
        for rank, k in enumerate(order):
            if grids[k].empty:
                continue
            shift = scale * centres[k] if n > 1 else np.zeros(3)
            sc = scale * scales[k] if n > 1 else scale
            images.append(render_grid(grids[k], rendering, size=size, limits=limits, cmap=cmap, clim=clim, scale=sc,
                                      shift=shift, density=density, sections=sections, view=view,
                                      progress=lambda f, r=rank: tick((1.0 + r + f) / (n + 1))))
    finally:
        close()
    if not images:
        return None
    from .slice_drawing import Z_BASE  # matplotlib's side: imported when a figure is drawn

    (x0, x1), (y0, y1) = limits
    image = ax.imshow(composite(images), extent=(x0, x1, y0, y1), origin="upper", interpolation="nearest",
                      aspect="auto", zorder=Z_BASE - 5.0)
    image.set_gid(rendering)
    image.set_clim(*clim)  # what its colours stand for (an RGBA image draws without its norm)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    return image
