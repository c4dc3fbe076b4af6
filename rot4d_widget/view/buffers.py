"""A source's slice -> float32 arrays for WebGL: the only place dtypes are cast.

One update of the view is ONE array, the *row table*: an (R, 20) float32,
C-contiguous array that the scene uploads as a single instanced interleaved
buffer and that three instanced meshes (balls, bars, faces) read through
different column offsets.  Row ``i`` carries ball ``i``, bar ``i`` and
triangle ``i`` at once::

    column  0-2   ball centre (x, y, z)            \\ ``BALL``  (itemSize 4)
    column  3     ball shown: 1.0, hidden: 0.0     /
    column  4-6   bar end a                          ``BAR_A`` (itemSize 3)
    column  7-9   bar end b                          ``BAR_B`` (itemSize 3)
    column 10-12  triangle corner a                  ``TRI_A`` (itemSize 3)
    column 13-15  triangle corner b                  ``TRI_B`` (itemSize 3)
    column 16-18  triangle corner c                  ``TRI_C`` (itemSize 3)
    column 19     triangle colour, 0xRRGGBB as float ``TRI_RGB`` (itemSize 1)

Rows ``0 .. n_balls-1`` hold the slice's points that get a ball, in order
(`ball_count`: every point, or none when ``show_points`` is False, less the
fill corners flagged ``corner_only``, which carry a face's corner only, so
a layer never draws hidden balls), rows
``0 .. n_segments-1`` its segments (bars, as end points), rows
``0 .. n_triangles-1`` its triangles (corners counter-clockwise seen from
outside, and the colour of the group -- a polytope's 4-D cell -- each comes
from).  R, the *capacity*, is at least the largest of
the three counts; everything past a count is zero, which the shaders draw as
nothing: a ball with flag 0 is moved outside the clip volume, a bar of length
0 likewise, a triangle with three equal corners has no area.  So an all-zero
row is a hidden row, and hidden rows cost bytes but never pixels.

Positions are multiplied by the scene's ``scale`` here (the 3-D view shows
every source the size of the pentachoron, `rot4d_widget.core.sizes.REFERENCE_RADIUS`).  A 24-bit colour packed into a
float32 is exact (float32 holds every integer below 2**24); the face shader
unpacks it with ``floor``.

Also here: the fixed template shapes (billboard quad for the ball and bar
impostors, barycentric triangle) that the scene builds once.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.colours import as_rgb, cell_palette, group_palette
from ..core.rotation import random_rotation
from ..sources.protocol import BadSlice, as_slice, outline_of

__all__ = [
    "ROW_FLOATS",
    "ROW_BYTES",
    "COLUMNS",
    "rows_needed",
    "ball_count",
    "capacity_for",
    "estimate_capacity",
    "slice_rows",
    "cell_palette",
    "group_palette",
    "as_rgb",
    "pack_rgb",
    "unpack_rgb",
    "quad_template",
    "triangle_template",
    "surface_arrays",
    "surface_message",
    "without_triangles",
    "MAX_UPDATE_BYTES",
    "UpdateTooLarge",
    "update_bytes",
    "check_update_size",
]

#: float32 values per row, and bytes per row
ROW_FLOATS = 20
ROW_BYTES = 4 * ROW_FLOATS

#: attribute name -> (first column, item size); read by the scene's shaders
COLUMNS = {
    "ball": (0, 4),
    "bar_a": (4, 3),
    "bar_b": (7, 3),
    "tri_a": (10, 3),
    "tri_b": (13, 3),
    "tri_c": (16, 3),
    "tri_rgb": (19, 1),
}

#: One update message carries at most this many bytes (32 MiB).  The largest legitimate ones,
#: measured by ``python benchmarks/update_size.py`` (docs/performance.md), are about 1.6 MB (12
#: slices of a 64^4 field ray-cast; the great icosahedral 120-cell's 12,000 faces; a 64^4 field's
#: three surfaces): the cap leaves room for a field sampled at 128 a side, 8 times the bytes,
#: while a slice of millions of points -- 240 MB for 3 M points, which freezes a browser tab for
#: seconds -- is refused before its rows are built.
MAX_UPDATE_BYTES = 32 * 2**20

#: capacities are multiples of this many rows
ROW_QUANTUM = 16
#: spare rows (as a fraction) when a capacity is chosen, so slightly larger
#: slices later do not force a resize
HEADROOM = 0.125


def _shown(data):
    """(n,) bool: the points that get a ball, or None for all of them (``show_points`` aside)."""
    corner = data.corner_only
    return None if corner is None else ~np.asarray(corner, dtype=bool)


def ball_count(data) -> int:
    """Balls a slice draws: its points, less the fill corners (``corner_only``); 0 without ``show_points``."""
    if not data.show_points:
        return 0
    shown = _shown(data)
    return len(data.points) if shown is None else int(shown.sum())


def rows_needed(data) -> int:
    """Rows a slice needs: ``max(n_balls, n_segments, n_triangles)``.

    A smooth surface's triangles (a slice with ``normals``) travel in the surface
    layer (`surface_arrays`), not in rows: they do not count.
    """
    n_triangles = 0 if data.normals is not None else len(data.triangles)
    return max(ball_count(data), len(data.segments), n_triangles)


def capacity_for(rows: int, headroom: float = HEADROOM, quantum: int = ROW_QUANTUM) -> int:
    """A capacity >= ``rows`` with ``headroom`` spare, rounded up to ``quantum`` (at least one quantum)."""
    rows = int(rows)
    if rows < 0:
        raise ValueError(f"Expected `rows` >= 0, got {rows}")
    want = math.ceil(rows * (1.0 + headroom))
    return max(quantum, -(-want // quantum) * quantum)


class UpdateTooLarge(BadSlice):
    """A slice whose update would exceed `MAX_UPDATE_BYTES`: refused before its rows are built."""


def update_bytes(data) -> int:
    """The bytes a slice's update carries (rows at `ROW_BYTES`, a smooth surface's 12 per point and
    12 per triangle), before any is built: what `check_update_size` holds to the cap."""
    n = rows_needed(data) * ROW_BYTES
    if data.normals is not None:
        n += 12 * (len(data.points) + len(data.triangles))
    return n


def check_update_size(data, *, volume=None, name: str = "the source") -> None:
    """`UpdateTooLarge` when a slice's update (with the binary parts of a ``volume`` message that
    travels with it: atlas, boxes, colour table) would exceed `MAX_UPDATE_BYTES`; the message
    says how large and what is allowed."""
    n = update_bytes(data) + sum(v.nbytes for v in (volume or {}).values() if isinstance(v, memoryview))
    if n > MAX_UPDATE_BYTES:
        raise UpdateTooLarge(
            f"{name}'s slice ({len(data.points):,} points, {len(data.segments):,} segments, "
            f"{len(data.triangles):,} triangles) would be a {n / 2**20:,.0f} MiB update; one update "
            f"carries at most {MAX_UPDATE_BYTES / 2**20:.0f} MiB (rot4d_widget.view.buffers.MAX_UPDATE_BYTES, "
            f"about {MAX_UPDATE_BYTES // ROW_BYTES:,} balls, bars or triangles): slice fewer points "
            "(a coarser sampling, fewer slices)")


def estimate_capacity(source, samples: int = 6, seed: int = 0, *, name: str = "the source") -> int:
    """Capacity for a source's central slices, from ``samples`` fixed-seed random orientations.

    Central slices are usually the largest; the estimate includes `HEADROOM`.
    It is a starting size, not a bound: the scene grows the table safely if a
    larger slice ever comes.  Each orientation is the source's outline
    (`rot4d_widget.sources.protocol.outline_of`: a field's box cut, its data not read; any other
    source's slice).  An outline over the update cap raises `UpdateTooLarge` at once (the other
    samples are not taken).
    """
    rng = np.random.default_rng(seed)
    most = 0
    for _ in range(int(samples)):
        data = as_slice(outline_of(source, random_rotation(rng), 0.0))
        check_update_size(data, name=name)
        most = max(most, rows_needed(data))
    return capacity_for(most)


def slice_rows(
    data, *, scale: float = 1.0, group_rgb=None, capacity: int | None = None, eye=None, single_rgb=None
) -> np.ndarray:
    """The row table of a slice (`rot4d_widget.sources.protocol.SliceData`): (capacity, 20) float32, C-contiguous.

    Parameters
    ----------
    data : slice object
        ``points`` (n, 3), ``segments`` (m, 2), ``triangles`` (k, 3),
        ``groups`` (k,), ``convex`` and ``show_points`` (both optional).
    scale : float
        Positions are multiplied by it.
    group_rgb : (G, 3) array of floats in [0, 1], optional
        Colour of each group (default `group_palette` of enough groups).
    capacity : int, optional
        Rows of the result (default ``rows_needed(data)``); must be at least that.
    eye : 3 floats, optional
        Where the scene is seen from (in the scaled coordinates).  If given,
        translucent triangles are put in an order that blends back to front:
        for a convex slice (``data.convex``) the triangles facing away from
        the eye first, then those facing it (a ray crosses at most one of
        each: exact); otherwise sorted by the distance of their centroid from
        the eye, farthest first (the usual approximation).  A triangle faces
        the eye when the eye is on the outer side of its plane (corners
        counter-clockwise seen from outside).
    single_rgb : 3 floats in [0, 1], optional
        One colour for every triangle instead of the group colours.
    """
    v = np.asarray(data.points, dtype=np.float64)
    e = np.asarray(data.segments, dtype=np.intp)
    t = np.asarray(data.triangles, dtype=np.intp)
    tc = np.asarray(data.groups, dtype=np.intp)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"Expected `points` to have shape (n, 3), got {v.shape}")
    if e.ndim != 2 or e.shape[1] != 2:
        raise ValueError(f"Expected `segments` to have shape (m, 2), got {e.shape}")
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"Expected `triangles` to have shape (k, 3), got {t.shape}")
    if tc.shape != (len(t),):
        raise ValueError(f"Expected `groups` to have shape ({len(t)},), got {tc.shape}")
    shown = _shown(data) if data.show_points else np.zeros(len(v), dtype=bool)
    if shown is not None and shown.shape != (len(v),):
        raise ValueError(f"Expected `corner_only` to have one flag per point ({len(v)}), got {shown.shape}")
    nv = len(v) if shown is None else int(shown.sum())
    ne, nt = len(e), len(t)
    need = max(nv, ne, nt)
    if capacity is None:
        capacity = need
    if capacity < need:
        raise ValueError(f"Expected `capacity` >= {need} (rows this slice needs), got {capacity}")
    if single_rgb is not None:
        packed = pack_rgb([single_rgb])
        tc = np.zeros(nt, dtype=np.intp)
    else:
        if group_rgb is None:
            group_rgb = group_palette(int(tc.max()) + 1 if nt else 1)
        packed = pack_rgb(group_rgb)
        if nt and tc.max() >= len(packed):
            raise ValueError(f"Expected `group_rgb` to have a colour for group {int(tc.max())}, "
                             f"got {len(packed)} colours")

    if eye is not None:
        try:
            o = np.asarray(eye, dtype=np.float64)
        except (TypeError, ValueError):
            o = None
        if o is None or o.shape != (3,) or not np.all(np.isfinite(o)):
            raise ValueError(f"Expected `eye` to be three finite numbers, got {eye!r}")

    p = v * float(scale)
    if eye is not None and nt:
        corners = p[t]  # (k, 3, 3)
        if data.convex:
            a = corners[:, 0]
            normal = np.cross(corners[:, 1] - a, corners[:, 2] - a)
            facing = np.einsum("ij,ij->i", normal, o - a) > 0.0
            order = np.argsort(facing, kind="stable")  # away-facing (False) first
        else:
            d = corners.sum(axis=1) / 3.0 - o
            order = np.argsort(-np.einsum("ij,ij->i", d, d), kind="stable")  # farthest first
        t, tc = t[order], tc[order]

    out = np.zeros((capacity, ROW_FLOATS), dtype=np.float32)
    out[:nv, 0:3] = p if shown is None else p[shown]  # the balls, in point order (no fill corner)
    out[:nv, 3] = 1.0
    out[:ne, 4:7] = p[e[:, 0]]
    out[:ne, 7:10] = p[e[:, 1]]
    out[:nt, 10:19] = p[t].reshape(nt, 9)
    out[:nt, 19] = packed[tc]
    return out


class _NoTriangles:
    """A slice's points and segments only (its triangles go to the surface layer)."""

    __slots__ = ("points", "segments", "triangles", "groups", "convex", "show_points")
    normals = corner_only = None  # the surface layer has the normals; the rows every point

    def __init__(self, data):
        self.points = data.points
        self.segments = data.segments
        self.triangles = np.zeros((0, 3), dtype=np.intp)
        self.groups = np.zeros(0, dtype=np.intp)
        self.convex = False
        self.show_points = data.show_points


def without_triangles(data):
    """The slice with its triangles left out: what the row table carries for a smooth surface."""
    return _NoTriangles(data)


#: Quantisation of a surface update: positions in the surface's box, normals, colours.
POSITION_LEVELS = 65535
NORMAL_LEVELS = 127


def surface_arrays(data, *, scale: float = 1.0, group_rgb=None, eye=None, single_rgb=None) -> dict:
    """A smooth surface (triangles with per-point ``normals``) as the companion uploads it.

    Only the points the triangles use travel, renumbered.  Returns numpy arrays and the
    box: ``position`` (n, 3) uint16 -- ``lo + position / 65535 * span`` is the scaled
    point, off by at most ``span / 131070``; ``normal`` (n, 3) int8 (the unit normal
    times 127, rounded); ``rgb`` (n, 3) uint8 (the colour of the group of the first
    triangle that uses the point: a point belongs to one level's surface); ``index``
    (3k,) uint32, triangles farthest first from ``eye`` by centroid (translucent
    surfaces blend back to front); ``lo``, ``span`` (3,) floats.  12 bytes per
    point and 12 per triangle.
    """
    v = np.asarray(data.points, dtype=np.float64) * float(scale)
    t = np.asarray(data.triangles, dtype=np.intp)
    g = np.asarray(data.groups, dtype=np.intp)
    nrm = np.asarray(data.normals, dtype=np.float64)
    if nrm.shape != v.shape:
        raise ValueError(f"Expected `normals` with the shape of `points` {v.shape}, got {nrm.shape}")
    if len(t) == 0:
        z3 = np.zeros((0, 3))
        return {"position": z3.astype(np.uint16), "normal": z3.astype(np.int8), "rgb": z3.astype(np.uint8),
                "index": np.zeros(0, dtype=np.uint32), "lo": [0.0, 0.0, 0.0], "span": [1.0, 1.0, 1.0]}
    if single_rgb is not None:
        palette = np.asarray([single_rgb], dtype=np.float64)
        g = np.zeros(len(t), dtype=np.intp)
    else:
        palette = np.asarray(group_palette(int(g.max()) + 1) if group_rgb is None else group_rgb, dtype=np.float64)
        if g.max() >= len(palette):
            raise ValueError(f"Expected `group_rgb` to have a colour for group {int(g.max())}, "
                             f"got {len(palette)} colours")
    if eye is not None:
        o = np.asarray(eye, dtype=np.float64)
        d = v[t].sum(axis=1) / 3.0 - o
        order = np.argsort(-np.einsum("ij,ij->i", d, d), kind="stable")  # farthest first
        t, g = t[order], g[order]
    used = np.zeros(len(v), dtype=bool)
    used[t.ravel()] = True
    keep = np.flatnonzero(used)
    new = np.full(len(v), -1, dtype=np.int64)
    new[keep] = np.arange(len(keep))
    p = v[keep]
    lo = p.min(axis=0)
    span = np.maximum(p.max(axis=0) - lo, 1e-12)
    position = np.rint((p - lo) / span * POSITION_LEVELS).astype(np.uint16)
    normal = np.rint(np.clip(nrm[keep], -1.0, 1.0) * NORMAL_LEVELS).astype(np.int8)
    vertex_group = np.empty(len(v), dtype=np.intp)
    vertex_group[t[::-1].ravel()] = np.repeat(g[::-1], 3)  # the first triangle's group wins
    rgb = np.rint(np.clip(palette[vertex_group[keep]], 0.0, 1.0) * 255.0).astype(np.uint8)
    return {"position": position, "normal": normal, "rgb": rgb, "index": new[t].astype(np.uint32).ravel(),
            "lo": [float(x) for x in lo], "span": [float(x) for x in span]}


def surface_message(arrays: dict, opacity) -> dict:
    """`surface_arrays` as the synced dict (the scene's ``_rot4d_surface``): arrays as little-endian
    bytes (binary buffers)."""
    n, k = len(arrays["position"]), len(arrays["index"])
    return {
        "n_vertices": int(n),
        "n_indices": int(k),
        "lo": list(arrays["lo"]),
        "span": list(arrays["span"]),
        "opacity": 1.0 if opacity is None else float(opacity),
        **{name: memoryview(np.ascontiguousarray(arrays[name]).astype(arrays[name].dtype.newbyteorder("<")).tobytes())
           for name in ("position", "normal", "rgb", "index")},
    }


# -- colours (the palette itself lives in rot4d_widget.core.colours) -----------------


def pack_rgb(rgb) -> np.ndarray:
    """(n, 3) floats in [0, 1] -> (n,) float32 holding the integer 0xRRGGBB exactly."""
    a = np.asarray(rgb, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"Expected colours with shape (n, 3), got {a.shape}")
    if not np.all(np.isfinite(a)) or a.size and (a.min() < 0.0 or a.max() > 1.0):
        raise ValueError("Expected colour components to be finite floats in [0, 1]")
    b = np.rint(a * 255.0).astype(np.int64)
    return (b[:, 0] * 65536 + b[:, 1] * 256 + b[:, 2]).astype(np.float32)


def unpack_rgb(packed) -> np.ndarray:
    """Inverse of `pack_rgb` (as the face shader does it): (n,) -> (n, 3) uint8."""
    p = np.asarray(packed, dtype=np.float64)
    r = np.floor(p / 65536.0)
    g = np.floor((p - r * 65536.0) / 256.0)
    b = p - r * 65536.0 - g * 256.0
    return np.stack([r, g, b], -1).astype(np.uint8)


# -- fixed shapes, built once -----------------------------------------------


def quad_template() -> np.ndarray:
    """Billboard square for sphere impostors: two triangles, (6, 3) float32, corners (+-1, +-1, 0)."""
    return np.array(
        [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32
    )


def triangle_template() -> np.ndarray:
    """Barycentric weights of a triangle's corners: the (3, 3) float32 identity."""
    return np.eye(3, dtype=np.float32)
