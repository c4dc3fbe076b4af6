"""`Slice` -> float32 arrays for WebGL: the only place dtypes are cast.

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

Rows ``0 .. n_vertices-1`` hold the slice's vertices (balls), rows
``0 .. n_edges-1`` its edges (bars, as end points), rows ``0 .. n_triangles-1``
its triangles (corners counter-clockwise seen from outside, and the colour of
the 4-D cell each comes from).  R, the *capacity*, is at least the largest of
the three counts; everything past a count is zero, which the shaders draw as
nothing: a ball with flag 0 is moved outside the clip volume, a bar of length
0 likewise, a triangle with three equal corners has no area.  So an all-zero
row is a hidden row, and hidden rows cost bytes but never pixels.

Positions are multiplied by the scene's ``scale`` here (the 3-D view shows
every polytope the size of the pentachoron).  A 24-bit colour packed into a
float32 is exact (float32 holds every integer below 2**24); the face shader
unpacks it with ``floor``.

Also here: the per-cell palette and the fixed template shapes (billboard
quad for the ball and bar impostors, barycentric triangle) that the scene
builds once; `cylinder_template` (a unit cylinder mesh) is no longer drawn by
the scene, kept for meshes that need real geometry.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "ROW_FLOATS",
    "ROW_BYTES",
    "COLUMNS",
    "rows_needed",
    "capacity_for",
    "estimate_capacity",
    "slice_rows",
    "cell_palette",
    "as_rgb",
    "pack_rgb",
    "unpack_rgb",
    "cylinder_template",
    "quad_template",
    "triangle_template",
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

#: capacities are multiples of this many rows
ROW_QUANTUM = 16
#: spare rows (as a fraction) when a capacity is chosen, so slightly larger
#: slices later do not force a resize
HEADROOM = 0.125


def rows_needed(slice_) -> int:
    """Rows a `Slice` needs: ``max(n_vertices, n_edges, n_triangles)``."""
    return max(len(slice_.vertices), len(slice_.edges), len(slice_.triangles))


def capacity_for(rows: int, headroom: float = HEADROOM, quantum: int = ROW_QUANTUM) -> int:
    """A capacity >= ``rows`` with ``headroom`` spare, rounded up to ``quantum`` (at least one quantum)."""
    rows = int(rows)
    if rows < 0:
        raise ValueError(f"Expected `rows` >= 0, got {rows}")
    want = math.ceil(rows * (1.0 + headroom))
    return max(quantum, -(-want // quantum) * quantum)


def estimate_capacity(polytope, samples: int = 6, seed: int = 0) -> int:
    """Capacity for ``polytope``'s central slices, from ``samples`` fixed-seed random orientations.

    Central slices are the largest; the estimate includes `HEADROOM`.  It is a
    starting size, not a bound: the scene grows the table safely if a larger
    slice ever comes.
    """
    from .slicing import slice_polytope  # numpy-only core

    rng = np.random.default_rng(seed)
    most = 0
    for _ in range(int(samples)):
        q, r = np.linalg.qr(rng.standard_normal((4, 4)))
        q = q * np.sign(np.diag(r))
        if np.linalg.det(q) < 0:
            q[:, 0] = -q[:, 0]
        most = max(most, rows_needed(slice_polytope(polytope, q, 0.0)))
    return capacity_for(most)


def slice_rows(
    slice_, *, scale: float = 1.0, cell_rgb=None, capacity: int | None = None, eye=None
) -> np.ndarray:
    """The row table of a `Slice`: (capacity, 20) float32, C-contiguous.

    Parameters
    ----------
    slice_ : Slice
        ``vertices`` (n, 3), ``edges`` (m, 2), ``triangles`` (k, 3),
        ``triangle_cells`` (k,).
    scale : float
        Positions are multiplied by it.
    cell_rgb : (C, 3) array of floats in [0, 1], optional
        Colour of each 4-D cell (default `cell_palette` of enough cells).
    capacity : int, optional
        Rows of the result (default ``rows_needed(slice_)``); must be at least that.
    eye : 3 floats, optional
        Where the scene is seen from (in the scaled coordinates).  If given,
        the triangles facing away from it come first, then those facing it,
        each group in the slice's order: drawn in row order, translucent
        faces of a convex slice then blend back to front.  A triangle faces
        the eye when the eye is on the outer side of its plane (corners
        counter-clockwise seen from outside).
    """
    v = np.asarray(slice_.vertices, dtype=np.float64)
    e = np.asarray(slice_.edges, dtype=np.intp)
    t = np.asarray(slice_.triangles, dtype=np.intp)
    tc = np.asarray(slice_.triangle_cells, dtype=np.intp)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"Expected `vertices` to have shape (n, 3), got {v.shape}")
    if e.ndim != 2 or e.shape[1] != 2:
        raise ValueError(f"Expected `edges` to have shape (m, 2), got {e.shape}")
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"Expected `triangles` to have shape (k, 3), got {t.shape}")
    if tc.shape != (len(t),):
        raise ValueError(f"Expected `triangle_cells` to have shape ({len(t)},), got {tc.shape}")
    nv, ne, nt = len(v), len(e), len(t)
    need = max(nv, ne, nt)
    if capacity is None:
        capacity = need
    if capacity < need:
        raise ValueError(f"Expected `capacity` >= {need} (rows this slice needs), got {capacity}")
    if cell_rgb is None:
        cell_rgb = cell_palette(int(tc.max()) + 1 if nt else 1)
    packed = pack_rgb(cell_rgb)
    if nt and tc.max() >= len(packed):
        raise ValueError(f"Expected `cell_rgb` to have a colour for cell {int(tc.max())}, got {len(packed)} colours")

    if eye is not None:
        try:
            o = np.asarray(eye, dtype=np.float64)
        except (TypeError, ValueError):
            o = None
        if o is None or o.shape != (3,) or not np.all(np.isfinite(o)):
            raise ValueError(f"Expected `eye` to be three finite numbers, got {eye!r}")

    p = v * float(scale)
    if eye is not None and nt:
        a = p[t[:, 0]]
        normal = np.cross(p[t[:, 1]] - a, p[t[:, 2]] - a)
        facing = np.einsum("ij,ij->i", normal, o - a) > 0.0
        order = np.argsort(facing, kind="stable")  # away-facing (False) first
        t, tc = t[order], tc[order]

    out = np.zeros((capacity, ROW_FLOATS), dtype=np.float32)
    out[:nv, 0:3] = p
    out[:nv, 3] = 1.0
    out[:ne, 4:7] = p[e[:, 0]]
    out[:ne, 7:10] = p[e[:, 1]]
    out[:nt, 10:19] = p[t].reshape(nt, 9)
    out[:nt, 19] = packed[tc]
    return out


# -- colours ---------------------------------------------------------------

_HEX = "0123456789abcdefABCDEF"


def as_rgb(color, name: str = "color") -> tuple:
    """``'#rgb'``, ``'#rrggbb'`` or (r, g, b) floats in [0, 1] -> (r, g, b) floats."""
    if isinstance(color, str):
        s = color.strip()
        if s.startswith("#") and len(s) in (4, 7) and all(ch in _HEX for ch in s[1:]):
            h = s[1:] if len(s) == 7 else "".join(ch * 2 for ch in s[1:])
            return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
    else:
        try:
            rgb = tuple(float(x) for x in color)
        except (TypeError, ValueError):
            rgb = None
        if rgb is not None and len(rgb) == 3 and all(0.0 <= x <= 1.0 for x in rgb):
            return rgb
    raise ValueError(
        f"Expected `{name}` to be '#rgb', '#rrggbb' or three floats in [0, 1], got {color!r}"
    )


def cell_palette(n_cells: int) -> np.ndarray:
    """Deterministic, distinct colours for ``n_cells`` cells: (n_cells, 3) float32 in [0, 1].

    Hue and lightness follow the R2 low-discrepancy sequence (golden-ratio
    generalisation), so any few consecutive cells differ clearly and up to
    several thousand cells get distinct 8-bit colours.
    """
    n = int(n_cells)
    if n < 0:
        raise ValueError(f"Expected `n_cells` >= 0, got {n}")
    g = 1.32471795724474602596  # plastic number: R2 sequence
    k = np.arange(n, dtype=np.float64)
    hue = np.mod(0.5 + k / g, 1.0)
    light = 0.42 + 0.30 * np.mod(0.5 + k / (g * g), 1.0)
    sat = 0.72
    # HSL -> RGB, vectorised
    c = (1.0 - np.abs(2.0 * light - 1.0)) * sat
    h6 = hue * 6.0
    x = c * (1.0 - np.abs(np.mod(h6, 2.0) - 1.0))
    sector = np.floor(h6).astype(np.intp) % 6
    zeros = np.zeros(n)
    table = np.stack(
        [
            np.stack([c, x, zeros], 1),
            np.stack([x, c, zeros], 1),
            np.stack([zeros, c, x], 1),
            np.stack([zeros, x, c], 1),
            np.stack([x, zeros, c], 1),
            np.stack([c, zeros, x], 1),
        ]
    )  # (6, n, 3)
    rgb = table[sector, np.arange(n)] + (light - c / 2.0)[:, None]
    return np.clip(rgb, 0.0, 1.0).astype(np.float32)


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


def cylinder_template(segments: int = 12) -> tuple:
    """A unit bar, non-indexed triangles: ``(position, normal)``, each (6*segments*2, 3) float32.

    ``position = (cos phi, sin phi, t)`` with t = 0 at end a and 1 at end b;
    caps have radial part 0.  ``normal`` is (cos phi, sin phi, 0) on the side,
    (0, 0, -1) / (0, 0, 1) on the caps.  The bar shader maps x, y to the two
    directions across the bar (times its radius) and t along it.
    """
    s = int(segments)
    if s < 3:
        raise ValueError(f"Expected `segments` >= 3, got {s}")
    phi = 2.0 * np.pi * np.arange(s + 1) / s
    cx, cy = np.cos(phi), np.sin(phi)
    i0, i1 = np.arange(s), np.arange(1, s + 1)
    ring0 = lambda i: np.stack([cx[i], cy[i], np.zeros(s)], 1)  # noqa: E731
    ring1 = lambda i: np.stack([cx[i], cy[i], np.ones(s)], 1)  # noqa: E731
    # side: two triangles per segment, CCW seen from outside
    side = np.stack([ring0(i0), ring0(i1), ring1(i1), ring0(i0), ring1(i1), ring1(i0)], 1)
    side_n = side.copy()
    side_n[..., 2] = 0.0
    centre0 = np.tile([0.0, 0.0, 0.0], (s, 1))
    centre1 = np.tile([0.0, 0.0, 1.0], (s, 1))
    cap0 = np.stack([centre0, ring0(i1), ring0(i0)], 1)
    cap1 = np.stack([centre1, ring1(i0), ring1(i1)], 1)
    cap0_n = np.broadcast_to([0.0, 0.0, -1.0], cap0.shape)
    cap1_n = np.broadcast_to([0.0, 0.0, 1.0], cap1.shape)
    pos = np.concatenate([side.reshape(-1, 3), cap0.reshape(-1, 3), cap1.reshape(-1, 3)])
    nrm = np.concatenate([side_n.reshape(-1, 3), cap0_n.reshape(-1, 3), cap1_n.reshape(-1, 3)])
    return np.ascontiguousarray(pos, dtype=np.float32), np.ascontiguousarray(nrm, dtype=np.float32)


def quad_template() -> np.ndarray:
    """Billboard square for sphere impostors: two triangles, (6, 3) float32, corners (+-1, +-1, 0)."""
    return np.array(
        [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32
    )


def triangle_template() -> np.ndarray:
    """Barycentric weights of a triangle's corners: the (3, 3) float32 identity."""
    return np.eye(3, dtype=np.float32)
