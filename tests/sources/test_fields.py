"""Field4D and slice_field: geometry against closed forms, backends against each other,
chunk reads counted, the interpolation against scipy, bad input named.

Orientations are seeded random rotations (rot4d_widget.core.rotation.random_rotation).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter, map_coordinates

from rot4d_widget.sources.field.container import Field4D, slice_field
from rot4d_widget.sources.field.surface import FieldSlice
from rot4d_widget.sources.field.slicing import box_slice, slice_samples
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.protocol import SliceData, as_source

BOX = ((-1.0, 1.0),) * 4


def nodes(extent, shape):
    return np.meshgrid(*[np.linspace(a, b, n) for (a, b), n in zip(extent, shape)], indexing="ij")


def at(field, d):
    """The c0 (the field's data w) of the hyperplane d slice units from the box's centre."""
    origin, per = field.w_frame
    return origin + per * d


def sphere_fn(R):
    return lambda x, y, z, w: R * R - (x * x + y * y + z * z + w * w)


def signed_volume(s):
    v = s.vertices
    a, b, c = v[s.triangles[:, 0]], v[s.triangles[:, 1]], v[s.triangles[:, 2]]
    return float(np.einsum("ij,ij->", a, np.cross(b, c))) / 6


# ---------------------------------------------------------------- the 3-sphere
@pytest.mark.parametrize("kind", ["callable", "array"])
def test_three_sphere_slices_to_a_sphere(kind):
    R = 0.8
    if kind == "callable":
        field = Field4D.from_function(sphere_fn(R), BOX)
        tol_r, tol_v = 0.002, 0.02
    else:
        X = nodes(BOX, (40,) * 4)
        field = Field4D((R * R - sum(x * x for x in X)).astype(np.float32), axes="xyzw", extent=BOX)
        tol_r, tol_v = 0.01, 0.03
    rng = np.random.default_rng(1)
    for c0 in (0.0, 0.35, -0.6):
        m = random_rotation(rng)
        s = slice_field(field, m, c0, 0.0, 64)
        r0 = math.sqrt(R * R - c0 * c0)
        r = np.linalg.norm(s.vertices, axis=1)
        assert np.abs(r - r0).max() < tol_r
        exact = 4 / 3 * math.pi * r0**3
        assert abs(s.volume - exact) < tol_v * exact
        assert s.volume == pytest.approx(signed_volume(s))  # positive: CCW seen from outside
        assert s.area == pytest.approx(4 * math.pi * r0 * r0, rel=tol_v)
        # unit normals pointing out of {f >= level}
        assert np.allclose(np.linalg.norm(s.normals, axis=1), 1.0)
        assert np.all(np.einsum("ij,ij->i", s.normals, s.vertices) > 0.9 * r)
    assert slice_field(field, random_rotation(rng), 0.85, 0.0).empty  # |c0| > R
    # the widget's slice turned in 3-D keeps points on the sphere and normals radial
    from rot4d_widget.core.rotation import simple_rotation

    field.levels = 0.0
    t = (simple_rotation("xz", 0.7) @ simple_rotation("xy", -0.4))[:3, :3]
    d = field.slice(m, 0.35).turned(t)
    n = len(d.levels[0].vertices)
    p, nrm = d.points[:n], d.normals[:n]
    assert np.abs(np.linalg.norm(p, axis=1) - math.sqrt(R * R - 0.35**2)).max() < tol_r
    assert np.all(np.einsum("ij,ij->i", nrm, p / np.linalg.norm(p, axis=1, keepdims=True)) > 0.99)
    # w squashed: one unit of slice space is 2 units of data w; c0 stays the data's w (at rest
    # c0 = 0.4 cuts the data at w = 0.4), and the gauge's range is the data's w range
    field.w_per_unit = 2.0
    assert field.half_widths == (1.0, 1.0, 1.0, 0.5) and field.w_range(np.eye(4)) == (-1.0, 1.0)
    assert field.w_frame == (0.0, 2.0) and field.offset(0.4) == 0.2
    s = slice_field(field, np.eye(4), 0.4, 0.0, 64)
    assert np.abs(np.linalg.norm(s.vertices, axis=1) - math.sqrt(R * R - 0.4**2)).max() < tol_r


# ---------------------------------------------------------------- the 4-D ellipsoid
def random_ellipsoid(rng):
    """A = Q diag(1/a^2) Q^T, semi-axes a between a third and two thirds of the box's half-width 1."""
    q = random_rotation(rng)
    return q @ np.diag(1 / rng.uniform(1 / 3, 2 / 3, 4) ** 2) @ q.T


def ellipsoid_slice_volume(A, m, c0):
    """Slice coordinates p = m q: the slice is {x: x'B11 x + 2 c0 b'x + beta c0^2 <= 1}, B = m A m^T,
    an ellipsoid of volume 4/3 pi (1 - c0^2 (beta - b'B11^-1 b))^(3/2) / sqrt(det B11)."""
    B = m @ A @ m.T
    B11, b, beta = B[:3, :3], B[:3, 3], B[3, 3]
    s = 1 - c0 * c0 * (beta - b @ np.linalg.solve(B11, b))
    return 0.0 if s <= 0 else 4 / 3 * math.pi * s**1.5 / math.sqrt(np.linalg.det(B11))


def quadric(A):
    return lambda x, y, z, w: 1 - np.einsum("i...,ij,j...->...", np.stack([x, y, z, w]), A, np.stack([x, y, z, w]))


def test_ellipsoid_callable_converges_at_second_order():
    rng = np.random.default_rng(5)
    for _ in range(3):
        A, m, c0 = random_ellipsoid(rng), random_rotation(rng), rng.uniform(-0.2, 0.2)
        exact = ellipsoid_slice_volume(A, m, c0)
        field = Field4D.from_function(quadric(A), BOX)
        e64 = slice_field(field, m, c0, 0.0, 64).volume / exact - 1
        e128 = slice_field(field, m, c0, 0.0, 128).volume / exact - 1
        assert abs(e64) < 0.02 and abs(e128) < 0.005, (e64, e128)
        assert 3.0 < e64 / e128 < 5.5  # about fourfold per doubling


def test_ellipsoid_from_a_48_array_at_96():
    rng = np.random.default_rng(11)
    X = np.stack(nodes(BOX, (48,) * 4))
    for _ in range(2):
        A, m, c0 = random_ellipsoid(rng), random_rotation(rng), rng.uniform(-0.2, 0.2)
        a = (1 - np.einsum("i...,ij,j...->...", X, A, X)).astype(np.float32)
        v = slice_field(Field4D(a, axes="xyzw", extent=BOX), m, c0, 0.0, 96).volume
        assert v == pytest.approx(ellipsoid_slice_volume(A, m, c0), rel=0.02)


# ---------------------------------------------------------------- Cavalieri
def trapezoid_count(a, level, extent):
    """4-volume of {f >= level} from node samples: each node weighted by its share of the
    cells around it (1/2 per axis on a face), times the cell volume."""
    w = np.ones(a.shape)
    for ax, n in enumerate(a.shape):
        t = np.ones(n)
        t[[0, -1]] = 0.5
        w = w * t.reshape([-1 if k == ax else 1 for k in range(4)])
    cell = np.prod([(hi - lo) / (n - 1) for (lo, hi), n in zip(extent, a.shape)])
    return float((w * (a >= level)).sum() * cell)


def cavalieri(field, m, level, n_c0=33, res=40):
    lo, hi = field.w_range(m)
    c = np.linspace(lo, hi, n_c0)
    return float(np.trapezoid([slice_field(field, m, ci, level, res).volume for ci in c], c))


@pytest.mark.parametrize("case", ["smooth", "fills the box"])
def test_cavalieri_slice_volumes_integrate_to_the_4_volume(case):
    rng = np.random.default_rng(7)
    extent = ((-1, 1), (-0.8, 0.9), (-1, 1), (-0.6, 0.6))
    shape = (22, 20, 22, 14)
    if case == "smooth":
        a = gaussian_filter(rng.standard_normal(shape), 3, mode="wrap")
        a /= a.std()
        level = 0.3
    else:  # a ball bigger than the box: caps dominate
        a = 1 - sum(x * x for x in nodes(extent, shape)) / 1.3**2
        level = 0.0
    field = Field4D(a, axes="xyzw", extent=extent)
    assert cavalieri(field, random_rotation(rng), level) == pytest.approx(trapezoid_count(a, level, extent), rel=0.03)


def open_edges(s) -> int:
    """Edges not shared by exactly two triangles (0 for a closed surface)."""
    t = s.triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    return int((np.unique(e, axis=0, return_counts=True)[1] != 2).sum())


def test_constant_field_slices_fill_the_box():
    extent = ((-1, 1), (-0.8, 0.9), (-1, 1), (-0.6, 0.6))
    field = Field4D(np.full((12, 12, 12, 8), 2.0), axes="xyzw", extent=extent)
    m = random_rotation(3)
    for c0 in (0.0, 0.5):
        s = slice_field(field, m, c0, 1.0, 48)
        assert s.volume == pytest.approx(box_slice(field, m, c0).volume, rel=0.01)  # caps ON the faces
    for m, c0 in ((np.eye(4), 0.0), (np.eye(4), 0.6 - 1e-9), (random_rotation(4), 0.3)):  # faces on grid planes too
        s = slice_field(field, m, c0, 1.0, 33)
        assert len(s.triangles) and open_edges(s) == 0
        assert s.volume == pytest.approx(box_slice(field, m, c0).volume, rel=0.02)
    total = cavalieri(field, m, 1.0, res=32)
    assert total == pytest.approx(np.prod([hi - lo for lo, hi in extent]), rel=0.01)


# ---------------------------------------------------------------- the interpolation
def grid_index_points(field, m, c0, s):
    """Index coordinates (array order) of every grid point of step ``s``, derived independently."""
    n = s.f.shape
    p = np.indices(n).reshape(3, -1).T * s.spacing + s.origin
    q = np.column_stack([p, np.full(len(p), c0)]) @ m  # slice coordinates about the centre
    data = q * np.array([1, 1, 1, field.w_per_unit]) + np.mean(field.extent, axis=1)
    idx = np.empty_like(data)
    for j, c in enumerate("xyzw"):
        lo, hi = field.extent[j]
        idx[:, field.axes.index(c)] = (data[:, j] - lo) / (hi - lo) * (field.shape[j] - 1)
    return idx.T


def test_interpolation_equals_map_coordinates_order_1():
    rng = np.random.default_rng(2)
    a = rng.standard_normal((13, 9, 11, 7))
    field = Field4D(a, axes="wzxy", extent=((-1, 2), (0, 1), (-0.5, 0.5), (3, 5)), w_per_unit=2.5)
    for _ in range(3):
        m, c0 = random_rotation(rng), rng.uniform(-0.3, 0.3)
        s = slice_samples(field, m, c0, 24)
        idx = grid_index_points(field, m, c0, s)
        ref = map_coordinates(a, idx, order=1, prefilter=False, mode="nearest")
        inside = s.g.ravel() >= 0
        assert 0.05 < inside.mean() < 1
        np.testing.assert_allclose(s.f.ravel()[inside], ref[inside], rtol=1e-12, atol=1e-12)
        # g: the distance within the slice to the planes where the box's faces cut it
        q = (np.column_stack([np.indices(s.f.shape).reshape(3, -1).T * s.spacing + s.origin,
                              np.full(inside.size, c0)]) @ m)
        g = ((np.array(field.half_widths) - np.abs(q)) / np.linalg.norm(m[:3], axis=0)).min(axis=1)
        np.testing.assert_allclose(s.g.ravel(), g, atol=1e-12)


def test_uneven_coordinates_interpolate_exactly_a_multilinear_function():
    xr = pytest.importorskip("xarray")
    rng = np.random.default_rng(4)
    coords = {"time": np.cumsum(rng.uniform(0.5, 1.5, 9)), "z": np.linspace(-1, 1, 8),
              "y": np.linspace(-1, 1, 10), "x": np.sort(rng.uniform(-1, 1, 11))}
    coords["x"][[0, -1]] = (-1, 1)
    T, Z, Y, X = np.meshgrid(*coords.values(), indexing="ij")

    def f(x, y, z, t):  # multilinear in data coordinates: reproduced exactly by the interpolation
        return 0.3 * x - 0.5 * y + 0.2 * z * x + 0.1 * (t - 6) + 0.05

    da = xr.DataArray(f(X, Y, Z, T), dims=("time", "z", "y", "x"), coords=coords, name="g")
    field = Field4D.from_xarray(da, w_per_unit=4.0)
    assert field.axes == "wzyx" and field._coords[0] is not None and field._coords[3] is not None
    ext = field.extent
    ref = Field4D.from_function(f, ext, w_per_unit=4.0)
    ref._stat.set_statistics(field._statistics())  # the same K for the caps (K comes from each field's own probe)
    m = random_rotation(rng)
    a, b = slice_field(field, m, at(field, 0.1), 0.02, 40), slice_field(ref, m, at(ref, 0.1), 0.02, 40)
    assert len(a.triangles) > 100
    np.testing.assert_allclose(a.vertices, b.vertices, atol=1e-9)
    # decreasing coordinates are read reversed: the same field
    flipped = Field4D.from_xarray(da.isel(x=slice(None, None, -1)), w_per_unit=4.0)
    np.testing.assert_allclose(slice_field(flipped, m, at(flipped, 0.1), 0.02, 40).vertices, a.vertices, atol=1e-12)


# ---------------------------------------------------------------- backends and chunk reads
class CountingArray:
    """A 4-D array-like that counts the blocks read from it (what dask's getter calls)."""

    def __init__(self, a):
        self.a, self.shape, self.ndim, self.dtype, self.reads = a, a.shape, a.ndim, a.dtype, 0

    def __getitem__(self, key):
        self.reads += 1
        return self.a[key]


def blob_array(shape=(24, 20, 22, 32)):
    """f[x, y, z, t]: a blob travelling along x as t grows."""
    x, y, z, t = nodes(((-1, 1), (-1, 1), (-1, 1), (0, 1)), shape)
    return np.exp(-((x - (t - 0.5)) ** 2 + y * y + z * z) / 0.2).astype(np.float32)


def test_numpy_dask_xarray_zarr_give_the_same_surface_and_read_few_chunks():
    da_ = pytest.importorskip("dask.array")
    xr = pytest.importorskip("xarray")
    zarr = pytest.importorskip("zarr")
    from zarr.storage import MemoryStore, WrapperStore

    a = blob_array()
    ext = ((-1, 1), (-1, 1), (-1, 1), (0, 1))
    tzyx = np.ascontiguousarray(a.transpose(3, 2, 1, 0))  # f[t, z, y, x]
    chunks = (4, 22, 20, 24)  # one chunk per 4 time steps: 8 chunks

    class Counting(WrapperStore):
        reads = 0

        async def get(self, key, prototype, byte_range=None):
            if key.startswith("c/"):
                Counting.reads += 1
            return await self._store.get(key, prototype, byte_range)

    store = Counting(MemoryStore())
    z = zarr.create_array(store, shape=tzyx.shape, chunks=chunks, dtype="f4")
    z[:] = tzyx
    counting = CountingArray(tzyx)
    coords = {"t": np.linspace(0, 1, 32), "z": np.linspace(-1, 1, 22), "y": np.linspace(-1, 1, 20),
              "x": np.linspace(-1, 1, 24)}
    kw = dict(extent=ext, w_per_unit=0.5, memory_budget=0)  # big data: never read whole (chunks are counted)
    fields = {
        "numpy": Field4D(a, axes="xyzw", **kw),
        "numpy wzyx": Field4D(tzyx, axes="wzyx", **kw),
        "dask": Field4D(da_.from_array(counting, chunks=chunks, asarray=False), axes="wzyx", **kw),
        "zarr": Field4D(z, axes="wzyx", **kw),
        "xarray": Field4D.from_xarray(xr.DataArray(tzyx, dims=tuple(coords), coords=coords), w_per_unit=0.5),
        "xarray dask": Field4D.from_xarray(
            xr.DataArray(da_.from_array(tzyx, chunks=chunks), dims=tuple(coords), coords=coords), w_per_unit=0.5),
    }
    assert fields["xarray dask"]._kind == "dask"  # stays lazy
    from rot4d_widget.core.rotation import double_rotation

    m = double_rotation("xw,yz", 0.12, 0.4)  # tilted a little into w: the cut spans few time steps
    ref = slice_field(fields["numpy"], m, at(fields["numpy"], 1 / 64), 0.5, 40)
    assert len(ref.triangles) > 200
    for f in fields.values():  # the coarse copy (data range, cap scale K) is the one pass over every chunk
        f.coarse()
    Counting.reads = 0
    counting.reads = 0
    for name, f in fields.items():
        s = slice_field(f, m, at(f, 1 / 64), 0.5, 40)
        np.testing.assert_allclose(s.vertices, ref.vertices, atol=1e-5, err_msg=name)
        np.testing.assert_array_equal(s.triangles, ref.triangles, err_msg=name)
    # 8 chunks of 4 time steps; the cut has |q_w| <= (1/64 + sin 0.12) / cos 0.12 = 0.136 of the half-width 1:
    # data t in 0.432 ... 0.568, samples 13.4 ... 17.6, chunks 3 and 4 (plus a neighbour within one sample)
    assert 2 <= counting.reads <= 3, counting.reads
    assert Counting.reads == counting.reads  # zarr: the same chunks, counted in its store
    assert fields["dask"]._reader.reads == counting.reads
    # the same step again comes from the chunk cache
    before = counting.reads
    slice_field(fields["dask"], m, at(fields["dask"], 1 / 64), 0.5, 40)
    assert counting.reads == before
    # a cut through the last cell of a chunk needs the first sample of the next one (identity, c0 = 0.5:
    # data t = 0.5, sample 15.5, between chunk 3 (12-15) and chunk 4 (16-19))
    for name in ("dask", "zarr"):
        np.testing.assert_allclose(slice_field(fields[name], np.eye(4), 0.5, 0.5, 40).vertices,
                                   slice_field(fields["numpy"], np.eye(4), 0.5, 0.5, 40).vertices, atol=1e-5)
    before = counting.reads
    # a general orientation still reads each touched chunk once, never more than there are
    slice_field(fields["dask"], random_rotation(0), 0.5, 0.5, 40)
    assert counting.reads - before <= 8


def test_dask_field_under_a_distributed_client():
    da_ = pytest.importorskip("dask.array")
    distributed = pytest.importorskip("distributed")
    a = blob_array((16, 16, 16, 16))
    ext = ((-1, 1), (-1, 1), (-1, 1), (0, 1))
    m = random_rotation(8)
    ref = slice_field(Field4D(a, axes="xyzw", extent=ext), m, 0.1, 0.5, 32)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                                  timeout=30) as cluster, distributed.Client(cluster, timeout=30):
        field = Field4D(da_.from_array(a, chunks=(16, 16, 16, 4)), axes="xyzw", extent=ext)
        field.coarse()  # first: the caps' scale then comes from the coarse copy, as the array's does
        s = slice_field(field, m, 0.1, 0.5, 32)  # (before it, a full step takes it from its own cut)
    np.testing.assert_allclose(s.vertices, ref.vertices, atol=1e-5)


def test_coarse_copy_is_small_in_memory_and_spans_the_same_box():
    da_ = pytest.importorskip("dask.array")
    a = blob_array((60, 20, 22, 32))
    counting = CountingArray(a)
    field = Field4D(da_.from_array(counting, chunks=(30, 20, 22, 8), asarray=False), axes="xyzw", extent=((-1, 1),) * 3 + ((0, 1),))
    c = field.coarse()
    assert c is field.coarse() and c._kind == "numpy" and c.values.shape == (48, 20, 22, 32)
    assert c.extent == field.extent and c.size == field.size
    assert not c.values.flags.writeable
    reads = counting.reads
    m = random_rotation(9)
    s = slice_field(field, m, 0.0, 0.5, 32, coarse=True)
    assert counting.reads == reads  # a coarse step reads nothing
    full = slice_field(Field4D(a, axes="xyzw", extent=field.extent), m, 0.0, 0.5, 32)
    assert s.volume == pytest.approx(full.volume, rel=0.05)
    lo, hi = field.data_range
    assert lo == pytest.approx(a.min(), abs=0.05) and hi == pytest.approx(a.max(), abs=0.05)
    small = Field4D(np.zeros((5, 5, 5, 5)), axes="xyzw")
    assert small.coarse() is small


# ---------------------------------------------------------------- the source
def test_field_is_a_source():
    a = blob_array((20, 18, 16, 12))
    field = Field4D(a, axes="xyzw", name="density", units="kg/m3")
    assert as_source(field) is field
    # default extent: longest spatial side 2, cubic voxels, w in samples
    h = 2 / 19
    assert field.extent[0] == pytest.approx((-1, 1)) and field.extent[1] == pytest.approx((-17 / 2 * h, 17 / 2 * h))
    assert field.extent[3] == (0, 11) and field.w_per_unit == pytest.approx(1 / h)
    assert field.half_widths[3] == pytest.approx(11 / 2 * h)
    assert field.size == pytest.approx(np.linalg.norm(field.half_widths))
    m = random_rotation(12)
    lo, hi = field.w_range(m)  # in the data's w (samples here), about the middle sample
    reach = float(np.abs(m[3]) @ np.array(field.half_widths)) * field.w_per_unit
    assert (lo, hi) == (pytest.approx(5.5 - reach), pytest.approx(5.5 + reach)) and field.w_frame[0] == 5.5
    field.levels = (0.3, 0.6)
    assert field.n_groups == 2
    d = field.slice(m, 5.5 + 0.1 * field.w_per_unit)  # c0 in samples: 0.1 slice units past the middle
    assert isinstance(d, SliceData) and not d.show_points and not d.convex and d.volume is None
    levels = d.levels
    assert [s.level for s in levels] == [0.3, 0.6]
    assert np.bincount(d.groups).tolist() == [len(s.triangles) for s in levels]
    assert levels[0].volume > levels[1].volume > 0  # nested
    box = box_slice(field, m, 0.1)
    assert len(d.segments) == len(box.edges) and len(d.points) == sum(len(s.vertices) for s in levels) + len(box.vertices)
    rows = dict(d.readout)
    assert rows["field"] == "density [kg/m3]" and rows["levels"].startswith("0.3, 0.6 of ")
    assert "sample" in rows["w cut"] and rows["w per unit"].startswith(f"{1 / h:.4g} sample")
    # the w the slice cuts, in data units, from the box's cut
    p = np.column_stack([box.vertices, np.full(len(box.vertices), 0.1)]) @ m
    w = p[:, 3] * field.w_per_unit + 5.5
    assert rows["w cut"].startswith(f"{w.min():.4g} \u2026 {w.max():.4g} sample")
    json.dumps(field.describe())
    assert field.describe()["array"] == "in-memory numpy (not recordable)"
    fn = Field4D.from_function(sphere_fn(0.5), BOX)
    assert fn.describe()["function"].endswith("sphere_fn.<locals>.<lambda>")
    json.dumps(fn.describe())
    # o / i move the levels by 1/50 of the data range, and stay within a step beyond it
    field.levels = 0.5
    step = (a.max() - a.min()) / 50
    field.actions["o"].run(1)
    assert field.levels[0] == pytest.approx(0.5 + step, rel=1e-3)
    field.actions["i"].run(1)
    field.actions["i"].run(-1)  # Shift+i: up
    assert field.levels[0] == pytest.approx(0.5 + step, rel=1e-3)
    for _ in range(100):
        field.actions["o"].run(1)
    # held up: it stops at the last step inside one step beyond the range (refused, not clamped,
    # so that i undoes every step o made)
    top = field.data_range[1] + field.level_step
    assert top - field.level_step < field.levels[0] <= top
    assert field.actions["o"].run(1) is False
    above = field.slice(m, at(field, 0.0))
    assert len(above.triangles) == 0 and "above the max: empty" in dict(above.readout)["level"]
    for _ in range(200):
        field.actions["i"].run(1)
    below = field.slice(m, at(field, 0.0))
    assert "the whole box" in dict(below.readout)["level"]
    assert below.volume == pytest.approx(box_slice(field, m, 0.0).volume, rel=0.03)
    assert field.slice(m, at(field, 0.0), coarse=True).readout[-1] == ("resolution", "32 (coarse copy)")
    # turned in 3-D = sliced at the turned orientation (what the widget shows at rest without resampling)
    from rot4d_widget.core.rotation import simple_rotation

    field.levels = 0.5
    t = simple_rotation("xy", 0.4) @ simple_rotation("yz", -1.1)
    c = at(field, 0.1)
    turned, direct = field.slice(m, c).turned(t[:3, :3]), field.slice(t @ m, c)
    assert turned.volume == pytest.approx(direct.volume, rel=0.03)
    np.testing.assert_allclose(np.sort(np.linalg.norm(turned.points[-len(box.vertices):], axis=1)),
                               np.sort(np.linalg.norm(direct.points[-len(box.vertices):], axis=1)))
    np.testing.assert_allclose(turned.levels[0].vertices.mean(axis=0),
                               direct.levels[0].vertices.mean(axis=0), atol=0.02)
    assert not turned.points.flags.writeable
    assert dict(field.slice(m, at(field, 5 * field.size)).readout)["w cut"].startswith("none")


def test_nan_constant_and_empty_are_not_errors():
    X = nodes(BOX, (16,) * 4)
    a = 0.64 - sum(x * x for x in X)
    a[X[0] > 0.3] = np.nan  # a NaN half-space: counts as below every level
    m = np.eye(4)
    s = slice_field(Field4D(a, axes="xyzw", extent=BOX), m, 0.0, 0.0, 48)
    assert not s.empty and s.vertices[:, 0].max() < 0.3 + 2 / 15 + 1e-9
    assert np.all(np.isfinite(s.vertices)) and np.all(np.isfinite(s.normals))
    nan = Field4D(np.full((4, 4, 4, 4), np.nan), axes="xyzw")
    assert math.isnan(nan.data_range[0]) and nan.levels == (0.0,)
    assert nan.slice(m, 0.0).triangles.shape == (0, 3)
    const = Field4D(np.ones((4, 4, 4, 4)), axes="xyzw")
    assert const.levels == (1.0,) and const.level_step == pytest.approx(0.02)
    assert slice_field(const, m, 0.0, 2.0).empty
    many = slice_field(const, m, 0.0, [0.5, 2.0])
    assert isinstance(many, tuple) and not many[0].empty and many[1].empty
    assert slice_field(const, m, 10.0, 0.5).empty  # the hyperplane misses the box


def test_returned_arrays_are_read_only():
    s = slice_field(Field4D.from_function(sphere_fn(0.5), BOX), random_rotation(1), 0.0, 0.0, 24)
    assert isinstance(s, FieldSlice)
    for arr in (s.vertices, s.triangles, s.normals):
        with pytest.raises(ValueError):
            arr[0] = 0
        assert not arr.base.flags.writeable if arr.base is not None else True
    e = slice_field(Field4D.from_function(sphere_fn(0.5), BOX), np.eye(4), 0.9, 0.0)
    with pytest.raises(ValueError):
        e.vertices.resize((3, 3))


# ---------------------------------------------------------------- bad input
def test_bad_input_is_named():
    ok = np.zeros((4, 4, 4, 4))
    with pytest.raises(ValueError, match="4-D"):
        Field4D(np.zeros((4, 4, 4)), axes="xyzw")
    with pytest.raises(ValueError, match="permutation of 'xyzw'"):
        Field4D(ok, axes="xyzt")
    with pytest.raises(ValueError, match="min < max .* y"):
        Field4D(ok, axes="xyzw", extent=((0, 1), (1, 1), (0, 1), (0, 1)))
    with pytest.raises(ValueError, match="finite"):
        Field4D(ok, axes="xyzw", extent=((0, 1), (0, np.inf), (0, 1), (0, 1)))
    with pytest.raises(ValueError, match=r"shape \(4, 2\)"):
        Field4D(ok, axes="xyzw", extent=((0, 1),) * 3)
    with pytest.raises(TypeError, match="real numbers"):
        Field4D(ok.astype(complex), axes="xyzw")
    with pytest.raises(ValueError, match="at least 2 samples"):
        Field4D(np.zeros((4, 1, 4, 4)), axes="xyzw")
    with pytest.raises(TypeError, match="array-like"):
        Field4D(object(), axes="xyzw")
    f = Field4D(ok, axes="xyzw")
    with pytest.raises(ValueError, match="finite"):
        slice_field(f, np.eye(4), 0.0, math.nan)
    with pytest.raises(ValueError, match="finite"):
        f.levels = [0.0, math.inf]
    with pytest.raises(TypeError, match="level"):
        slice_field(f, np.eye(4), 0.0, [])
    with pytest.raises(ValueError, match=">= 2"):
        slice_field(f, np.eye(4), 0.0, 0.0, 1)
    with pytest.raises(ValueError, match=r"would need up to .*GiB.*limit"):
        slice_field(f, np.eye(4), 0.0, 0.0, 1000)
    with pytest.raises(TypeError, match="int"):
        slice_field(f, np.eye(4), 0.0, 0.0, 64.0)
    with pytest.raises(ValueError, match="orthogonal"):
        slice_field(f, np.eye(4) * 2, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"shape \(4, 4\)"):
        slice_field(f, np.eye(3), 0.0, 0.0)
    with pytest.raises(ValueError, match="finite"):
        f.slice(np.eye(4), math.nan)
    with pytest.raises(TypeError, match="Field4D"):
        slice_field(ok, np.eye(4), 0.0, 0.0)
    with pytest.raises(ValueError, match=r"one value per point, shape \(\d+(, \d+)+\), got \(\)"):
        slice_field(Field4D.from_function(lambda x, y, z, w: 1.0, BOX), np.eye(4), 0.0, 0.0)
    with pytest.raises(TypeError, match="real numbers"):
        slice_field(Field4D.from_function(lambda x, y, z, w: x + 1j, BOX), np.eye(4), 0.0, 0.0)
    with pytest.raises(TypeError, match="callable"):
        Field4D.from_function(3.0, BOX)
    with pytest.raises(ValueError, match="w_per_unit"):
        Field4D(ok, axes="xyzw", w_per_unit=0)
    with pytest.raises(ValueError, match="coarse_resolution"):
        f.coarse_resolution = 1


def test_bad_xarray_input_is_named():
    xr = pytest.importorskip("xarray")
    da = xr.DataArray(np.zeros((3, 4, 5, 6)), dims=("a", "b", "c", "d"))
    with pytest.raises(ValueError, match=r"Cannot map the dims \('a', 'b', 'c', 'd'\).*x='lon'"):
        Field4D.from_xarray(da)
    f = Field4D.from_xarray(da, x="d", y="c", z="b", w="a")
    assert f.axes == "wzyx" and f.shape == (6, 5, 4, 3)
    with pytest.raises(ValueError, match="not a dim"):
        Field4D.from_xarray(da, x="lon")
    with pytest.raises(ValueError, match="distinct"):
        Field4D.from_xarray(da, x="a", y="a")
    with pytest.raises(ValueError, match="4-D"):
        Field4D.from_xarray(da.isel(a=0))
    bad = xr.DataArray(np.zeros((3, 4, 5, 6)), dims=("time", "z", "y", "x"),
                       coords={"time": [0.0, 2.0, 1.0]})
    with pytest.raises(ValueError, match="'time' to be strictly monotonic"):
        Field4D.from_xarray(bad)
    named = xr.DataArray(np.zeros((3, 4, 5, 6)), dims=("time", "z", "y", "x"), name="T",
                         attrs={"units": "K"}, coords={"time": np.array(["2020-01-01", "2020-01-02", "2020-01-04"],
                                                                        dtype="datetime64[ns]")})
    f = Field4D.from_xarray(named)
    assert (f.name, f.units, f.w_units, f.extent[3]) == ("T", "K", "s", (0.0, 3 * 86400.0))


def test_a_chunked_full_step_never_assembles_the_array(tmp_path):
    """A full step on a zarr array reads chunks into small tables, never a block of the whole cut:
    the memory it allocates (tracemalloc sees numpy's buffers) stays far below the array's size."""
    zarr = pytest.importorskip("zarr")
    import tracemalloc

    n = 80  # 164 MB of float32
    z = zarr.create_array(store=str(tmp_path / "big.zarr"), shape=(n,) * 4, chunks=(16,) * 4, dtype="float32")
    g = np.linspace(-1.0, 1.0, n, dtype=np.float32)
    for i in range(0, n, 16):
        gi = g[i:i + 16]
        z[i:i + 16] = 0.5 - (gi[:, None, None, None] ** 2 + g[None, :, None, None] ** 2
                             + g[None, None, :, None] ** 2 + g[None, None, None, :] ** 2)
    f = Field4D(z, axes="xyzw", extent=[(-1.0, 1.0)] * 4, levels=[0.0], chunk_cache_bytes=1 << 22, resolution=40)
    m = random_rotation(np.random.default_rng(5))
    f.slice(m, 0.1, coarse=True)  # the coarse copy is built first (it reads every chunk once)
    tracemalloc.start()
    try:
        full = f.slice(m, 0.1)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    r = math.sqrt(0.5 - 0.1**2)
    assert full.volume == pytest.approx(4 / 3 * math.pi * r**3, rel=0.03)
    nbytes = n**4 * 4
    assert peak < 0.4 * nbytes, f"a full step allocated {peak / 2**20:.0f} MiB for a {nbytes / 2**20:.0f} MiB array"
