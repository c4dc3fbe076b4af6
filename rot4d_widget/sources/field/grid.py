"""A field's cut on a regular 3-D grid: `sample_field` (the grid companion of `slice_field`).

Volume rendering, maximum intensity projections and colour-mapped sections need the values of
the cut itself, not a surface through it.  `sample_field` reuses one step's resampling
(`rot4d_widget.sources.field.slicing.slice_samples_raw`: the same grid, the same kernels, the same
numbers as the isosurfaces) and hands back a frozen `FieldGrid`: float32 values, read-only, NaN
outside the data's box, with the grid's origin, spacing and extent in slice coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core import tolerances as tol
from ...core._arrays import sealed
from ...core.rotation import as_rotation_matrix
from .checks import check_resolution
from .slicing import box_slice, slice_samples_raw

__all__ = ["FieldGrid", "sample_field", "field_sample"]


@dataclass(frozen=True)
class FieldGrid:
    """The cut w = c0 of a field sampled on a regular 3-D grid (`sample_field`'s result).

    values : (nx, ny, nz) float32, read-only
        f at the grid's nodes; NaN outside the data's box (and where the data is NaN).
    origin : (3,) float64, read-only
        Slice coordinates of node ``values[0, 0, 0]``.
    spacing : float
        Distance between neighbouring nodes, the same along x, y and z (slice units).
    extent : ((x0, x1), (y0, y1), (z0, z1))
        Slice coordinates of the first and last node along each axis (the cut's bounding box
        with one spacing of padding on every side).
    name, units : str or None
        The field's name and the units of its values.
    data_range : (lo, hi)
        The field's data range (`Field4D.data_range`), for a colour scale shared by every cut.

    outline : ((P, 3) float64, (S, 2) intp), read-only
        The cut of the data's box: its corners and edges in slice coordinates (what the live
        view draws as bars around a volume rendering); empty arrays when the cut misses it.

    A cut that misses the box is empty: ``values`` of shape (0, 0, 0), ``spacing`` 0.
    Node (i, j, k) is at ``origin + spacing * (i, j, k)``; the data point there is
    ``centre + (matrix.T @ (p, d)) * unit`` (`Field4D.to_data`).
    """

    values: np.ndarray
    origin: np.ndarray
    spacing: float
    extent: tuple
    name: str | None
    units: str | None
    data_range: tuple
    outline: tuple = (sealed(np.zeros((0, 3))), sealed(np.zeros((0, 2), dtype=np.intp)))

    @property
    def empty(self) -> bool:
        """True when the cut missed the data's box (no nodes)."""
        return self.values.size == 0

    @property
    def axes(self) -> tuple:
        """(x, y, z): the nodes' slice coordinates along each axis, three (n,) float64 arrays."""
        return tuple(self.origin[a] + self.spacing * np.arange(self.values.shape[a]) for a in range(3))


def sample_field(field, matrix, c0, resolution: int = 64, *, coarse: bool = False) -> FieldGrid:
    """The values of ``field``'s cut w = ``c0`` after ``matrix`` on a regular 3-D grid.

    Parameters
    ----------
    field : Field4D
    matrix : (4, 4) rotation (validated: orthogonal, det +1), as in `slice_field`
    c0 : float -- the hyperplane w = c0, in the data's w units (`Field4D.w_frame`)
    resolution : int -- nodes along the longest side of the bounding box of the box's cut
        (padding not counted), the same spacing on all three axes: `slice_field`'s grid
    coarse : bool -- sample ``field.coarse()`` instead (for held keys)

    Returns
    -------
    `FieldGrid`: values (nx, ny, nz) float32 read-only, NaN outside the data's box (a node on a
    face counts as inside); origin, spacing and extent in slice coordinates; the field's name,
    units and data range (`Field4D.known_range`: of chunked data, the chunks read so far until the
    coarse copy is ready).  The values are `slice_field`'s samples: multilinear interpolation of
    an array (order 1, no prefilter), a function evaluated exactly at the nodes.  Of chunked data,
    only the chunks the samples touch are read.
    """
    if not all(hasattr(field, a) for a in ("half_widths", "offset", "coarse")):  # plain members: nothing is read
        raise TypeError(f"Expected `field` to be a Field4D, got {type(field).__name__}")
    d = field.offset(c0)
    m = as_rotation_matrix(matrix)
    res = check_resolution(resolution)
    src = field.coarse() if coarse else field
    box = box_slice(field, m, d)
    outline = (sealed(np.asarray(box.vertices, dtype=np.float64).reshape(-1, 3).copy()),
               sealed(np.asarray(box.edges, dtype=np.intp).reshape(-1, 2).copy()))
    s = slice_samples_raw(src, m, d, res, box=box)
    name, units = field.name, field.units
    rng = tuple(float(v) for v in field.known_range)  # never a full read of chunked data for it
    if s is None:
        return FieldGrid(sealed(np.zeros((0, 0, 0), dtype=np.float32)), sealed(np.zeros(3)), 0.0,
                         ((0.0, 0.0),) * 3, name, units, rng, outline)
    spacing = float(s.spacing)
    with np.errstate(invalid="ignore"):
        v = np.where(np.asarray(s.g) >= -tol.ON_HYPERPLANE * spacing, np.asarray(s.f), np.nan)
    values = np.ascontiguousarray(v, dtype=np.float32)
    origin = np.asarray(s.origin, dtype=np.float64).copy()
    extent = tuple((float(origin[a]), float(origin[a] + spacing * (values.shape[a] - 1))) for a in range(3))
    return FieldGrid(sealed(values), sealed(origin), spacing, extent, name, units, rng, outline)


def field_sample(field, matrix, c0, resolution=None, *, coarse: bool = False) -> FieldGrid:
    """``Field4D.sample``: the cut w = ``c0`` (data w units) after ``matrix`` on a regular 3-D grid,
    `sample_field` at ``resolution`` nodes along the longest side (default the field's
    ``resolution``, or its ``coarse_resolution`` with ``coarse``)."""
    if resolution is None:
        resolution = field.coarse_resolution if coarse else field.resolution
    return sample_field(field, matrix, c0, resolution, coarse=coarse)
