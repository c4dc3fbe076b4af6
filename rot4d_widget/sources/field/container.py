"""4-D scalar fields as sources: resample on the rotated hyperplane, then isosurfaces.

A `Field4D` holds samples f[x, y, z, w] on the nodes of a regular (or, from
xarray, unevenly spaced) 4-D grid -- a numpy array or memmap, a dask array, a
zarr array -- or a vectorised function f(x, y, z, w).  Each step
(`slice_field`):

1. the data's 4-D box is cut by w = c0 after the rotation (the exact polytope
   slicer on the box, an 8-cell scaled to the extent); c0 is in the data's w
   units (`Field4D.w_frame`): the hyperplane lies d = (c0 - w_centre) / w_per_unit
   slice units from the box's centre along the turned w axis, so that at rest
   c0 = 30 cuts the data at w = 30;
2. a 3-D grid of ``resolution`` samples along the longest side of that cut's
   bounding box (same spacing on all three axes, one sample of padding) is
   pulled back into the data, ``q = matrix.T @ (x, y, z, d) + centre``, and
   the array is interpolated there, multilinearly (order 1, no prefilter),
   by a numba kernel that walks the affine grid (base + i a + j b + k c in
   index space) -- a function is evaluated exactly at those points instead;
3. ``v = min(f - level, K * g)`` with g the signed distance, within the
   slice, to the planes where the box's faces cut it (positive inside; linear
   along a grid line near a face, so the zero of its linear interpolation lies
   ON the face) and K a typical |grad f|; outside the box v is K g alone; NaN
   counts as below every level;
4. scikit-image's marching cubes (Lewiner) at v = 0 for each level, vertices
   mapped from index space to slice coordinates, wound counter-clockwise seen
   from where f < level.

Coordinates.  *Data coordinates* are the field's own (``extent`` or xarray
coordinates).  *Slice coordinates* (what the widget draws) are data
coordinates about the box's centre, with w divided by ``w_per_unit`` (how
much data-w one unit of space is): a data point q is drawn at
``matrix @ (q - centre)`` with its w so scaled.

Chunked data (dask, zarr, anything with ``chunks``) and lazily read files: a
full-resolution step reads only the chunks its samples' cells touch (the whole
4-D bounding block is never read); recently read chunks are kept up to
``chunk_cache_bytes``.  ``field.coarse()`` is an in-memory copy with at most
`COARSE_SAMPLES` nodes per axis over the same box (built once, the only time
every chunk is read) for the held-key steps and for the data range.  Data that
fit ``memory_budget`` (`MEMORY_BUDGET`, 1 GiB) are read whole in that same pass
(`prepare`: in the background, with a progress bar; the widget starts it), after
which steps run on the array in memory (`resident`).

Shapes: vertices (n, 3) float64, triangles (k, 3) intp, normals (n, 3)
float64; everything returned is read-only.

Scale: the box's half widths (slice units) and the ends of ``extent`` must lie
in `rot4d_widget.geometry.mesh.COORDINATE_RANGE` (1e-150 to 1e150; else a
ValueError naming it).  Within it a field scaled by ``s`` (extent times s, the
same samples) slices as the unscaled one at ``c0 / s`` (extent's w scaled too), its surfaces scaled by
s: the box cut is the exact slicer's (normalised), the resampling works in
index units, and marching cubes runs with unit spacing, its vertices, volume
and area scaled afterwards in float64.  Only a volume or area beyond float64
itself becomes inf (or 0); `Field4D.slice` then gives the widget no volume.
"""

from __future__ import annotations

import numbers

import numpy as np

from ...core.rotation import as_rotation_matrix
from ...geometry.mesh import check_scale
from ..protocol import SourceBase
from .checks import (
    AXES,
    as_levels,
    check_extent,
    check_positive,
    check_resolution,
    real_number,
)
from .chunks import ChunkReader, chunked_values
from .coarse import MEMORY_BUDGET, CoarseCopy
from .grid import field_sample
from .inputs import as_array, metadata_range, open_dataarray, xarray_arguments, zarr_attrs
from .kernels import resample_points
from .levels import FieldLevels
from .memory import FieldMemory
from .readout import describe_field, field_readout, order_text, outline_readout
from .slicing import LastCut, box_slice, slice_offset, slice_samples
from .stats import FieldStatistics
from .surface import CutFrame, FieldSliceData, empty_slice, level_surface

__all__ = ["Field4D", "slice_field"]

#: Order a step's points by the chunk their cell starts in before cutting them into passes
#: (benchmarks/chunk_fetches.py flips it to compare both orders: fewer chunk fetches when the cache is small)
_SORT_PASSES = True


class Field4D(FieldLevels, FieldMemory, SourceBase):
    """A scalar field on a 4-D box: a source for `Rot4DWidget` and the input of `slice_field`.

    Parameters
    ----------
    values : 4-D array-like
        numpy array or memmap, dask array, zarr array or anything with ``shape``,
        ``ndim``, ``dtype`` and slicing; real numbers (NaN allowed: below every level).
        Chunked/lazy arrays are never read whole except once for `coarse`.  An xarray
        DataArray goes through `from_xarray` (a Dataset: pick a variable, ``ds["T"]``).
        +inf / -inf samples are allowed but reported once, by a `NonFiniteWarning` naming
        how many (and, in memory, where) when the data range is first needed: they sit
        above / below every level, and an interpolated point whose cell holds one is +-inf,
        or NaN (below every level) where its weight is 0 -- mask them (``np.where(np.isfinite(a), a, np.nan)``) or clip.
    axes : str
        Which of x, y, z, w each array axis is, a permutation of ``"xyzw"``:
        ``"wzyx"`` for ``f[t, z, y, x]`` (the usual time-first layout), ``"xyzw"``
        for ``f[x, y, z, t]``.  Required for an array (TypeError without it: a guess
        cannot tell time from x); `repr` and the readout name the order
        (``f[w, z, y, x]``).  `from_xarray` takes it from the dims.
    extent : ((xmin, xmax), (ymin, ymax), (zmin, zmax), (wmin, wmax)), optional
        Data coordinates of the first and last node along each axis (samples sit
        on the nodes).  Default: x, y, z span ``[-(n-1)/2, (n-1)/2] * h`` with one
        spacing ``h = 2 / (longest spatial n - 1)`` (the longest spatial side is
        2, voxels are cubes), and w is the sample index ``0 .. nw-1``.
    name, units : str, optional
        Shown in the readout.
    w_per_unit : float, optional
        How much data-w one unit of slice space is.  Default: 1 when ``extent``
        is given (taken literally), else ``1 / h`` (one w sample is as long as
        one spatial sample: voxels are cubes in 4-D).  Larger values squash time.
    w_units : str, optional
        Unit of w for the readout (default ``"sample"`` with the default extent).
    space_units : str, optional
        Unit of x, y and z (e.g. ``"m"``): the readout gives a slice's volume in it, cubed.
        `from_xarray` takes it from the coordinates' ``units`` when x, y and z agree.
    resolution, coarse_resolution : int
        Samples along the longest side of a full step (default 64) and of a
        coarse step (default ``max(24, resolution // 2)``).
    levels : float or sequence of floats, optional
        Iso levels (default: one, midway between the min and max of `data_range`: for a chunked
        array, of the first slice's chunks until `coarse` is ready -- the first picture never
        reads the whole array; `prepare` builds the copy in the background).
    inside : "above" or "below"
        Which side of each level the surface encloses: ``"above"`` {f >= level} (a density,
        a phase field), ``"below"`` {f <= level} (a signed distance, negative inside: the ball,
        not the box around it).  NaN is never enclosed.
    caps : bool
        True (default): the surface is closed on the box's faces (the enclosed part of each face
        is drawn; ``volume`` is the enclosed 3-volume).  False: only {f = level} itself, open where
        it meets a face (its edge within one sample of it) -- for fields that fill the box, e.g.
        periodic ones, whose caps would hide the inside; ``volume`` is then NaN (not closed).
    chunk_cache_bytes : int
        Recently read chunks of a chunked array kept in memory (default 128 MiB: with the
        rest of a full step, a 4 GB store stays under 1 GB resident; docs/performance.md).
    memory_budget : int
        Bytes a chunked or lazy array may take in memory (float32 kept, other types as
        float64) to be read whole when the coarse copy is made (`prepare`, `coarse`); default
        `MEMORY_BUDGET` (1 GiB); 0: never.  Bigger data keep the coarse copy and read, for a full
        step, only the chunks its samples touch.
    """

    def __init__(self, values, *, axes=None, extent=None, name=None, units=None,
                 w_per_unit=None, w_units=None, space_units=None, resolution: int = 64, coarse_resolution=None,
                 levels=None, chunk_cache_bytes: int = 128 * 1024**2, inside: str = "above", caps: bool = True,
                 memory_budget: int = MEMORY_BUDGET, _coords=None, _function=None, _copy_of=None, _w_epoch=None):
        self._function = _function
        self._dims = None  # the array's dim names (from_xarray), for the readout
        self.axes_given = axes is not None
        if _function is None:
            self._values, self._kind, self._axis_of, self.shape = as_array(values, axes)
            self.axes = axes
        else:
            self._values = None
            self._kind = "function"
            self.axes = AXES
            self._axis_of = (0, 1, 2, 3)
            self.shape = None

        if extent is None:
            if _function is not None:
                raise ValueError("A function field needs an `extent`")
            h = 2.0 / (max(self.shape[:3]) - 1)
            ext = [(-(n - 1) / 2 * h, (n - 1) / 2 * h) for n in self.shape[:3]] + [(0.0, float(self.shape[3] - 1))]
            self.extent = tuple((float(a), float(b)) for a, b in ext)
            wpu = 1.0 / h if w_per_unit is None else w_per_unit
            self.w_units = "sample" if w_units is None else str(w_units)
        else:
            self.extent = check_extent(extent)
            wpu = 1.0 if w_per_unit is None else w_per_unit
            self.w_units = None if w_units is None else str(w_units)
        self._coords = (None,) * 4 if _coords is None else tuple(_coords)
        self.w_epoch = None if _w_epoch is None else np.datetime64(_w_epoch)  #: w = 0's date, from datetime64
        self.name = None if name is None else str(name)
        self.units = None if units is None else str(units)
        self.space_units = None if space_units is None else str(space_units)
        e = np.array(self.extent)
        self._centre = (e[:, 0] + e[:, 1]) / 2
        self._centre.flags.writeable = False
        #: (lo, hi, where) from the data's metadata (`from_xarray`: actual_range, valid_min/valid_max;
        #: a zarr array's own attributes likewise)
        meta = metadata_range(zarr_attrs(self._values), None, self._values.dtype) if self._kind == "zarr" else None
        self._stat = FieldStatistics(self, meta)
        self._coarse_copy = CoarseCopy(self, self._stat.counted)
        if _copy_of is not None:  # a coarse copy is its own, and its infinities are the field's to report
            self._coarse_copy.copy = self
            self._stat.infinite_reported = True
        self.w_per_unit = wpu
        self.resolution = resolution
        self.coarse_resolution = max(24, self.resolution // 2) if coarse_resolution is None else coarse_resolution
        self.chunk_cache_bytes = int(chunk_cache_bytes)
        self.memory_budget = memory_budget
        self._reader = None
        #: the last cut sampled from chunked data (`rot4d_widget.sources.field.slicing.LastCut`)
        self.last_cut = LastCut()
        self._levels = None if levels is None else as_levels(levels)
        self.inside = inside
        self.caps = caps
        #: Where the values come from, for a state file to reopen them (`Field4D.open`; `from_xarray`
        #: of a Dataset, or of a DataArray when xarray's encoding names the file): a JSON-able dict, or
        #: None (not reopenable)
        self.origin = None
        #: Why `from_xarray` found no origin (said when a state file is saved), or None
        self.origin_missing = None

    # -- constructors ---------------------------------------------------------
    @classmethod
    def from_function(cls, f, extent, *, name=None, units=None, w_per_unit=None, w_units=None, **kwargs) -> "Field4D":
        """A field given by ``f(x, y, z, w)``, vectorised over arrays of one shape and
        returning real values of that shape, evaluated exactly at each sample point
        (no grid, no interpolation).  ``extent`` is required (its box is the field's)."""
        if not callable(f):
            raise TypeError(f"Expected `f` to be callable as f(x, y, z, w), got {type(f).__name__}")
        if name is None:
            name = getattr(f, "__name__", None)
        return cls(None, extent=extent, name=name, units=units, w_per_unit=w_per_unit, w_units=w_units,
                   _function=f, **kwargs)

    @classmethod
    def from_xarray(cls, data, variable=None, *, x=None, y=None, z=None, w=None, w_per_unit=None,
                    **kwargs) -> "Field4D":
        """A field from a 4-D ``xarray.DataArray``, or ``variable`` of an ``xarray.Dataset`` (dims by
        name; extents from coordinates).  ``from_xarray(xarray.open_dataset("run.nc"), "T", w="time")``
        (or ``open_zarr``): the Dataset knows its file whatever the engine, so a state file reopens
        the field (``origin``); ``variable`` may be omitted when there is one.  A DataArray names its
        file only with the netCDF4 and h5netcdf engines, and a selection made after opening is not
        kept (`open` keeps ``isel=`` / ``sel=``): saving such a field warns, saying why.

        Dims named ``x``, ``y``, ``z`` (any case) are found by themselves and the one left over is w
        (``("time", "z", "y", "x")``); otherwise name them with ``x=, y=, z=, w=``.  Coordinates may
        be unevenly spaced (each maps to a fractional index) and decreasing (read reversed, lazily);
        not monotonic -> ValueError.  datetime64 coordinates become seconds since their first value.
        A dask-backed array stays lazy.  ``w_per_unit`` defaults to the mean w spacing over the mean
        spatial spacing (voxels are cubes).
        """
        values, args, dims, meta_range, (origin, why), long_name = xarray_arguments(
            data, variable, x, y, z, w, w_per_unit, kwargs)
        field = cls(values, **args, **kwargs)
        field._dims, field.long_name = dims, long_name
        field._stat.meta_range = meta_range
        field.origin = origin
        field.origin_missing = why
        return field

    @classmethod
    def open(cls, path, variable=None, *, x=None, y=None, z=None, w=None, engine=None, chunks=None,
             isel=None, sel=None, load: bool = False, **kwargs) -> "Field4D":
        """`from_xarray` of ``variable`` in the netCDF file or zarr store at ``path``, remembering
        where it came from (``field.origin``), so that a state file reopens it
        (`rot4d_widget.keep.statefile.save_state`, `Rot4DWidget.save_state` / ``from_state``).

        ``variable`` may be omitted when the file has one data variable.  ``engine`` goes to
        ``xarray.open_dataset`` (None: xarray's guess; a directory opens with ``"zarr"``).
        ``chunks``: None reads lazily, block by block, as needed; ``{}`` (the store's own chunks),
        ``"auto"`` or ``{"time": 10}`` make it a dask array.  ``isel`` / ``sel`` select a 4-D part
        before `from_xarray` (``isel={"member": 0}``, ``sel={"time": slice("2020-01", "2020-06")}``;
        isel first): integers, labels (numbers, strings) and slices of them, kept in the origin.
        ``load=True`` reads the selected part into memory now (a numpy array).
        ``x=, y=, z=, w=`` name the dims as in `from_xarray`; other keywords go to it
        (``w_per_unit=``, ``levels=``, ``inside=``, ``caps=``, ``resolution=`` ...).

        Opening reads the file's metadata and coordinates, not its data.
        """
        da, record = open_dataarray(path, variable, engine, chunks, isel, sel, load)
        field = cls.from_xarray(da, x=x, y=y, z=z, w=w, **kwargs)
        field.origin = {**record, "kwargs": dict(zip(field.axes, field._dims)), "load": bool(load)}
        field.origin_missing = None
        return field

    # -- geometry and resolution ------------------------------------------------
    @property
    def w_per_unit(self) -> float:
        """How much data-w one unit of slice space is (settable: larger squashes w, smaller stretches it)."""
        return self._w_per_unit

    @w_per_unit.setter
    def w_per_unit(self, value) -> None:
        wpu = check_positive(value, "w_per_unit")
        e = np.array(self.extent)
        unit = np.array([1.0, 1.0, 1.0, wpu])  # data units per slice unit
        with np.errstate(over="ignore", under="ignore"):
            hw = (e[:, 1] - e[:, 0]) / 2 / unit
        check_scale(float(hw[3]), f"With `w_per_unit` = {wpu:.3g}, the box's half width along w in slice units")
        self._w_per_unit, self._unit, self._hw = wpu, unit, hw
        self.half_widths = tuple(float(v) for v in self._hw)
        self._unit.flags.writeable = False
        self._stat.forget_k()  # K is per slice unit
        c = self._coarse_copy.copy
        if c is not None and c is not self:
            c.w_per_unit = value

    # -- source protocol --------------------------------------------------------
    @property
    def size(self) -> float:
        """Circumradius of the 4-D box about its centre, in slice units."""
        return float(np.linalg.norm(self._hw))

    @property
    def n_groups(self) -> int:
        return len(self.levels)

    @property
    def values(self):
        """The array as given (None for a function field)."""
        return self._values

    @property
    def data_range(self) -> tuple:
        """(min, max) of the finite values; (nan, nan) if there are none.  Where it comes from
        (`data_range_source`): the metadata of a variable from xarray (``actual_range``, else
        ``valid_range`` or ``valid_min``/``valid_max``), read without touching the data; else an
        array in memory, whole; a chunked or lazy array's `coarse` copy (which may miss a peak
        between its nodes), or, until the coarse copy is ready, the chunks a slice has read so far
        (``"first cut"``: a fresh field's first slice reads only the chunks its hyperplane touches
        and takes the default level from them); a function's probe grid.  Asked before any slice
        and before the coarse copy is ready, it builds (or waits for) the coarse copy."""
        return self._stat.range_info()[0]

    @property
    def data_range_source(self) -> str:
        """Where `data_range` comes from: ``"data"``, ``"coarse copy"``, ``"first cut"`` (the
        chunks read so far, until the coarse copy is ready), ``"probe grid"``,
        ``"actual_range"``, ``"valid_range"`` or ``"valid_min/valid_max"``."""
        return self._stat.range_info()[1]

    @property
    def known_range(self) -> tuple:
        """`data_range` as far as it is known without reading every chunk: the same, except for a
        chunked or lazy array whose coarse copy is not ready, whose range is then the first cut's
        (the chunks read so far; the cut at rest is read when nothing was).  What a full step's
        grid (`sample_field`) reports, so that it never triggers a full read."""
        return self._stat.range_info(first_cut=True)[0]

    def _statistics(self):
        """((min, max), K): `data_range` and a typical |grad f| (level units per slice unit)."""
        return self._stat.statistics()

    def cap_scale(self, samples=None, first_cut: bool = False) -> float:
        """K, a typical |grad f| (level units per slice unit): how steeply the caps on the box's faces
        rise, for one step's ``samples`` (`rot4d_widget.sources.field.stats.FieldStatistics.cap_scale`)."""
        return self._stat.cap_scale(samples, first_cut)

    @property
    def w_frame(self) -> tuple:
        """``(origin, per_unit)`` = (the data's w at the box's centre, `w_per_unit`): c0 =
        origin + per_unit * d, d the hyperplane's offset from the box's centre along the turned
        w axis in slice units (the source protocol's ``w_frame``)."""
        return float(self._centre[3]), float(self._w_per_unit)

    def offset(self, c0) -> float:
        """d, the offset in slice units of the hyperplane w = ``c0`` (data w units): ``(c0 -
        origin) / w_per_unit`` (`w_frame`)."""
        return (real_number(c0, "c0") - float(self._centre[3])) / float(self._w_per_unit)

    def w_range(self, matrix) -> tuple:
        """(lowest, highest) c0, in the data's w units, at which w = c0 touches the rotated box."""
        m = as_rotation_matrix(matrix)
        s = float(np.abs(m[3]) @ self._hw) * float(self._w_per_unit)
        origin = float(self._centre[3])
        return origin - s, origin + s

    def to_data(self, points, matrix, c0) -> np.ndarray:
        """(n, 4) float64: the data coordinates (x, y, z, w in the field's own units) of the
        slice points ``points`` (n, 3) of the cut w = ``c0`` (data w units) after ``matrix``:
        ``centre + (matrix.T @ (p, d)) * (1, 1, 1, w_per_unit)``, d = `offset` (c0)."""
        m = as_rotation_matrix(matrix)
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        q = np.column_stack([p, np.full(len(p), self.offset(c0))]) @ m  # rows of (m.T @ (p, d))
        return self._centre + q * self._unit

    def slice(self, matrix, c0, coarse: bool = False):
        """The slice as the widget draws it (`SliceData`): the isosurface of every level
        (group = level index) and the cut of the data's box as bars.  ``coarse``:
        the in-memory coarse copy at `coarse_resolution` (for held keys).  ``c0`` in the data's w
        units (`w_frame`).  Its ``frame`` (a `CutFrame`) records the cut and the field's frame then
        (``matrix``, ``d`` the offset in slice units, ``centre``, ``unit``: a point p is at data
        ``centre + (matrix.T @ (p, d)) * unit``, as `to_data`)."""
        m = as_rotation_matrix(matrix)  # validated once: what follows takes it as it is
        c0 = self.offset(c0)  # slice units from here on
        meanwhile = bool(coarse) and self._coarse_copy.building()
        box = box_slice(self, m, c0)
        # held keys while the coarse copy is built: the full data sampled at the coarse resolution
        # (the chunks the cut touches, kept by the reader's cache; the build goes on)
        res = self.coarse_resolution if coarse else self.resolution
        if coarse and not meanwhile:
            slices = slice_offset(self, m, c0, self.levels, res, coarse=True, box=box)
        else:  # read first: a fresh chunked field takes its range and level from this cut's chunks
            s = slice_samples(self, m, c0, check_resolution(res), first_cut=True, box=box)
            levels = self.levels
            slices = (tuple(empty_slice(lv, 0.0) for lv in levels) if s is None
                      else tuple(level_surface(s, lv, self.inside, self.caps) for lv in levels))
        readout = field_readout(self, m, c0, slices, box, coarse and not meanwhile)
        if meanwhile:
            done, total = self._coarse_copy.progress or (0, 0)
            readout = readout + (("resolution", f"{res} (from the full data: the coarse copy is being built, "
                                                f"{done}/{total} chunks)"),)
        return FieldSliceData.assemble(slices, box, readout, CutFrame(m, c0, self._centre, self._unit))

    def outline(self, matrix, c0) -> "FieldSliceData":
        """The slice's bars without its surface, and the readout rows that do not depend on it: the
        cut of the data's box at w = ``c0`` after ``matrix``, read from nothing (the source protocol's
        ``outline``: the widget sizes its buffers and ball radius from it, reading no chunk)."""
        m, d = as_rotation_matrix(matrix), self.offset(c0)
        return FieldSliceData.assemble((empty_slice(0.0, 0.0),), box := box_slice(self, m, d),
                                       outline_readout(self, m, d, box), CutFrame(m, d, self._centre, self._unit))

    sample = field_sample  # the cut on a regular 3-D grid, a FieldGrid (defined in grid)
    long_name = None  # the colour bar's label: xarray's attrs["long_name"] (from_xarray, open; inputs._long_name)

    def describe(self) -> dict:
        """A JSON-able description (the source protocol's ``describe()``): the frame, levels, surface
        and resolutions, where the values come from, and ``"rebuild"``: True (a module-level
        function, or a file `open` read) or why a state file cannot rebuild the field (an array held
        in memory, a lambda)."""
        return describe_field(self)

    # -- read-only views for the step's functions ----------------------------------
    @property
    def kind(self) -> str:
        """What holds the values: "numpy", "dask", "zarr", "lazy" (another sliceable array) or "function"."""
        return self._kind

    @property
    def function(self):
        """f(x, y, z, w) of a function field (None for an array)."""
        return self._function

    @property
    def centre(self) -> np.ndarray:
        """(4,) float64, read-only: the box's centre in data coordinates."""
        return self._centre

    @property
    def unit(self) -> np.ndarray:
        """(4,) float64, read-only: data units per slice unit, (1, 1, 1, `w_per_unit`)."""
        return self._unit

    @property
    def coords(self) -> tuple:
        """Per data axis x, y, z, w: the nodes' coordinates (read-only (n,) float64) when unevenly
        spaced (from xarray), else None."""
        return self._coords

    @property
    def axis_of(self) -> tuple:
        """The array axis of x, y, z and w."""
        return self._axis_of

    @property
    def dims(self):
        """The array's dim names (`from_xarray`), or None."""
        return self._dims

    @property
    def reader(self):
        """The chunk reader of a chunked or lazy array once a step read from it, else None."""
        return self._reader

    def values_at(self, idx, inside) -> np.ndarray:
        """(N,) float64: quadrilinear values at the (N, 4) array-index coordinates ``idx`` (clamped
        into the array) where ``inside``, 0 elsewhere; a chunked or lazy array is read chunk by chunk
        (its chunk reader and cache), never assembled."""
        resident = self.resident
        if resident is not None:
            return resample_points(resident, idx, inside)
        if self._reader is None:
            self._reader = ChunkReader(self._values, self.chunk_cache_bytes)
        return chunked_values(self._reader, idx, inside, _SORT_PASSES)

    def __repr__(self) -> str:
        if self._kind == "function":
            what = "function f(x, y, z, w)"
        else:
            kind = "array" if self._kind == "numpy" else f"{self._kind} array"
            what = f"{kind} {tuple(int(n) for n in self._values.shape)} {order_text(self)}"
        return f"Field4D({self.name or ''!s}{' ' if self.name else ''}{what}, axes={self.axes!r}, extent={self.extent})"



def slice_field(field, matrix, c0, level, resolution: int = 64, *, coarse: bool = False):
    """Isosurfaces of ``field`` (a `Field4D`) in the slice w = ``c0`` after the rotation ``matrix``.

    Parameters
    ----------
    field : Field4D
    matrix : (4, 4) rotation (validated: orthogonal, det +1); a data point q is at
        ``matrix @ (q - centre)`` (w scaled by ``1 / field.w_per_unit``)
    c0 : float -- the hyperplane w = c0, in the data's w units (`Field4D.w_frame`: at rest
        c0 = 30 cuts the data at w = 30)
    level : float or sequence of floats -- the surface closes {f >= level} (``field.inside``
        "above", the default) or {f <= level} ("below"); capped on the box's faces unless
        ``field.caps`` is False
    resolution : int -- samples along the longest side of the bounding box of the
        box's cut (padding not counted), same spacing on all three axes
    coarse : bool -- resample ``field.coarse()`` instead (for held keys)

    Returns
    -------
    `FieldSlice`, or a tuple of them (one per level, sharing one resampling) when
    ``level`` is a sequence.
    """
    if not isinstance(field, Field4D):
        raise TypeError(f"Expected `field` to be a Field4D, got {type(field).__name__}")
    d = field.offset(c0)
    m = as_rotation_matrix(matrix)
    many = not isinstance(level, (numbers.Real, np.integer, np.floating)) or isinstance(level, (bool, np.bool_))
    levels = as_levels(level)
    res = check_resolution(resolution)
    out = slice_offset(field, m, d, levels, res, coarse=coarse)
    return out if many else out[0]
