"""The scientist's path into Field4D: files opened every way xarray opens them, the axis order
named (never guessed silently), bad input named, non-finite data reported.

Each xarray test writes its own small files (tmp_path): 60 times (more than COARSE_SAMPLES, so
the coarse copy resamples time) on an 8 x 8 x 8 grid, and compares every way of opening them with
the same numbers given as a numpy array.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

from rot4d_widget.sources.field.coarse import COARSE_SAMPLES
from rot4d_widget.sources.field.container import Field4D, slice_field
from rot4d_widget.core.rotation import random_rotation

NT = 60
assert NT > COARSE_SAMPLES


def tzyx_array():
    """f[t, z, y, x]: a ball whose radius grows with t, plus a little noise."""
    t = np.linspace(0.0, 1.0, NT)[:, None, None, None]
    g = np.linspace(-1.0, 1.0, 8)
    r2 = g[None, None, None, :] ** 2 + g[None, None, :, None] ** 2 + g[None, :, None, None] ** 2
    noise = np.random.default_rng(0).normal(0.0, 0.01, (NT, 8, 8, 8))
    return (0.2 + 0.6 * t - r2 + noise).astype(np.float64)


def dataset(xr):
    a = tzyx_array()
    g = np.linspace(-1.0, 1.0, 8)
    return xr.Dataset({"T": (("time", "z", "y", "x"), a, {"units": "K"})},
                      coords={"time": np.linspace(0.0, 5.9, NT), "z": g, "y": g, "x": g})


OPENINGS = {
    "netcdf open_dataset": lambda xr, d: xr.open_dataset(d / "run.nc", engine="scipy"),
    "netcdf open_dataset chunks={}": lambda xr, d: xr.open_dataset(d / "run.nc", engine="scipy", chunks={}),
    "netcdf load": lambda xr, d: xr.open_dataset(d / "run.nc", engine="scipy").load(),
    "zarr open_zarr": lambda xr, d: xr.open_zarr(d / "run.zarr"),
    "zarr open_zarr chunks=None": lambda xr, d: xr.open_zarr(d / "run.zarr", chunks=None),
    "zarr open_dataset engine=zarr": lambda xr, d: xr.open_dataset(d / "run.zarr", engine="zarr"),
    "zarr open_dataset engine=zarr load": lambda xr, d: xr.open_dataset(d / "run.zarr", engine="zarr").load(),
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    xr = pytest.importorskip("xarray")
    d = tmp_path_factory.mktemp("run")
    ds = dataset(xr)
    pytest.importorskip("scipy")
    ds.to_netcdf(d / "run.nc", engine="scipy")  # netCDF3
    if _has("zarr"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zarr 3: consolidated metadata is not in the spec
            ds.to_zarr(d / "run.zarr", mode="w")
    return d


def _has(module):
    try:
        __import__(module)
    except ImportError:
        return False
    return True


def _same_slices(a, b, tol=1e-9):
    assert len(a.vertices) == len(b.vertices) and len(a.triangles) == len(b.triangles)
    assert np.allclose(a.vertices, b.vertices, atol=tol * 10, rtol=0)
    assert a.volume == pytest.approx(b.volume, rel=tol, abs=tol)


@pytest.mark.parametrize("how", list(OPENINGS))
def test_the_readme_xarray_line_works_however_the_file_is_opened(files, how):
    """`Field4D.from_xarray(open(...)["T"], w="time")` for netCDF3 and zarr, chunked or not, lazy or
    loaded: the same slices (full and coarse, at a turned matrix) as the numpy array.  Before, a
    lazily indexed backend array went into dask as a DataArray: without pyarrow a
    ModuleNotFoundError from dask.dataframe, with it a ValueError from np.gradient (the coarse copy's
    neighbouring takes aligned by label and lost samples)."""
    xr = pytest.importorskip("xarray")
    if "zarr" in how and not _has("zarr"):
        pytest.skip("zarr is not installed")
    if "chunks={}" in how or how == "zarr open_zarr":
        pytest.importorskip("dask")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=FutureWarning)
        ds = OPENINGS[how](xr, files)
    field = Field4D.from_xarray(ds["T"], w="time")
    assert field.axes == "wzyx" and field.shape == (8, 8, 8, NT) and field.units == "K"
    ref = Field4D(tzyx_array(), axes="wzyx", extent=field.extent, w_per_unit=field.w_per_unit)
    # in memory, or chunked or lazy and within the memory budget (read whole with the coarse copy,
    # which the range asks for): the whole array's range
    assert field.data_range_source == "data" and field.resident is not None
    assert field.data_range == pytest.approx(ref.data_range)
    np.testing.assert_array_equal(field.resident, tzyx_array())
    level = 0.25
    rng = np.random.default_rng(3)
    origin, per = field.w_frame
    for c0 in (origin, origin + 0.2 * per):  # c0 in the data's time: the middle, and 0.2 slice units on
        m = random_rotation(rng)
        for coarse in (False, True):
            _same_slices(slice_field(field, m, c0, level, 24, coarse=coarse),
                         slice_field(ref, m, c0, level, 24, coarse=coarse))
        d = field.slice(m, c0)
        assert len(d.triangles) > 0
    ds.close()


def test_a_lazily_opened_file_never_reaches_dask_dataframe(files):
    """The netCDF file opened without chunks goes through every step (coarse copy, statistics, a
    full step) without importing dask.dataframe -- the module that needs pyarrow -- so the line
    works with and without pyarrow installed (a fresh interpreter: nothing imported it before)."""
    pytest.importorskip("xarray")
    code = f"""
import sys, numpy as np, xarray as xr
from rot4d_widget import Field4D
f = Field4D.from_xarray(xr.open_dataset({str(files / "run.nc")!r}, engine="scipy")["T"], w="time")
m = np.linalg.qr(np.random.default_rng(1).normal(size=(4, 4)))[0]
m = m if np.linalg.det(m) > 0 else m[:, [1, 0, 2, 3]]
f.slice(m, 0.0, coarse=True); f.slice(m, 0.0)
assert f._kind == "lazy", f._kind
print("dask.dataframe" in sys.modules)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "False"


# ---------------------------------------------------------------- the axis order, named
def test_an_array_without_axes_is_refused_naming_the_choices_and_repr_names_the_order():
    """`Field4D(f)` for the README's f[t, z, y, x] used to take x as time without a word."""
    f = np.zeros((24, 20, 20, 20))
    with pytest.raises(TypeError, match=r"needs `axes`.*axes='wzyx' for f\[t, z, y, x\].*axes='xyzw' for f\[x, y, z, t\]"):
        Field4D(f)
    m = np.eye(4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # given: no warning
        named = Field4D(f, axes="wzyx")
    assert repr(named).startswith("Field4D(array (24, 20, 20, 20) f[w, z, y, x],")
    assert dict(named.slice(m, 0.0).readout)["axes"] == "f[w, z, y, x], shape (24, 20, 20, 20)"
    assert named.shape == (20, 20, 20, 24)


def test_from_xarray_names_its_dims_in_repr_and_readout():
    xr = pytest.importorskip("xarray")
    from rot4d_widget.sources.field.checks import UnitsWarning

    da = xr.DataArray(tzyx_array(), dims=("time", "z", "y", "x"), name="T")
    with warnings.catch_warnings():
        warnings.simplefilter("error", category=UserWarning)
        warnings.simplefilter("ignore", category=UnitsWarning)  # it has none: said (issue 37)
        field = Field4D.from_xarray(da)
    assert "T[time, z, y, x] as [w, z, y, x]" in repr(field)
    assert dict(field.slice(np.eye(4), 0.0).readout)["axes"].startswith("T[time, z, y, x] as [w, z, y, x]")


# ---------------------------------------------------------------- bad input, named
def test_a_dataset_is_refused_naming_its_variables():
    xr = pytest.importorskip("xarray")
    ds = dataset(xr)
    ds["S"] = ds["T"] * 2
    with pytest.raises(ValueError, match=r"Dataset has data variables 'T', 'S'; name one: "
                                         r"Field4D.from_xarray\(ds, 'T', w='time'\)"):
        Field4D.from_xarray(ds, w="time")
    with pytest.raises(ValueError, match=r"no data variable 'U'; it has 'T', 'S'"):
        Field4D.from_xarray(ds, "U", w="time")
    with pytest.raises(TypeError, match=r"Dataset with data variables 'T', 'S'; use Field4D.from_xarray\(ds, 'T'"):
        Field4D(ds, axes="wzyx")
    with pytest.raises(TypeError, match=r"`variable` \('T'\) names a data variable of an xarray.Dataset"):
        Field4D.from_xarray(ds["T"], "T", w="time")
    assert Field4D.from_xarray(ds, "S", w="time").name == "S"
    with pytest.raises(TypeError, match=r"from_xarray\(da, w='time'\)"):
        Field4D(ds["T"], axes="wzyx")


@pytest.mark.parametrize("n", [0, 1])
def test_a_dim_with_fewer_than_two_samples_is_named(n):
    xr = pytest.importorskip("xarray")
    da = dataset(xr)["T"].isel(time=slice(0, n))
    with pytest.raises(ValueError, match=rf"at least 2 samples along every dim.*time={n} \(w\)"):
        Field4D.from_xarray(da, w="time")


def test_infinite_samples_are_reported_once_with_count_and_place():
    from rot4d_widget.sources.field.checks import NonFiniteWarning

    a = tzyx_array()
    a[3, 1, 2, 4] = np.inf
    a[5, 0, 0, 0] = np.inf
    a[7, 7, 7, 7] = -np.inf
    field = Field4D(a, axes="wzyx")
    with pytest.warns(NonFiniteWarning, match=r"2 \+inf and 1 -inf of 30720 samples \(the first at index "
                                              r"\(3, 1, 2, 4\) of f\[w, z, y, x\]\)"):
        lo, hi = field.data_range
    assert math.isfinite(lo) and math.isfinite(hi)  # the range ignores them
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once
        s = field.slice(random_rotation(4), 0.0)
    assert np.isfinite(s.points).all()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NaN stays silent: below every level
        b = tzyx_array()
        b[3, 1, 2, 4] = np.nan
        Field4D(b, axes="wzyx").slice(np.eye(4), 0.0)


def test_infinite_samples_in_a_chunked_array_are_counted_with_the_coarse_copy():
    dsa = pytest.importorskip("dask.array")
    from rot4d_widget.sources.field.checks import NonFiniteWarning

    a = tzyx_array()
    a[50, 1, 2, 4] = np.inf  # beyond the coarse copy's first 48 nodes
    field = Field4D(dsa.from_array(a, chunks=(16, 8, 8, 8)), axes="wzyx", memory_budget=0)  # never read whole
    with pytest.warns(NonFiniteWarning, match=r"1 \+inf of 30720 samples\. They are kept"):
        field.slice(np.eye(4), 0.0, coarse=True)
    # read whole (it fits the default budget): counted in memory, where the first one is said
    loaded = Field4D(dsa.from_array(a, chunks=(16, 8, 8, 8)), axes="wzyx")
    with pytest.warns(NonFiniteWarning, match=r"1 \+inf of 30720 samples \(the first at index \(50, 1, 2, 4\)"):
        loaded.slice(np.eye(4), 0.0, coarse=True)
    assert loaded.resident is not None and loaded.data_range_source == "data"


# ---------------------------------------------------------------- which side is inside; caps
def _ball_distance(R, n=33):
    g = np.linspace(-1.0, 1.0, n)
    X = np.meshgrid(g, g, g, g, indexing="ij")
    return np.sqrt(sum(x * x for x in X)) - R  # signed distance, negative inside


def test_inside_below_encloses_a_signed_distance_ball():
    """A signed distance (negative inside) with inside="below" is the ball, not the box around it."""
    R = 0.6
    ball = 4 / 3 * math.pi * R**3
    sd = _ball_distance(R)
    below = Field4D(sd, axes="xyzw", extent=[(-1, 1)] * 4, inside="below", levels=[0.0])
    above = Field4D(sd, axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.0])
    assert below.inside == "below" and above.inside == "above"
    assert below.describe()["inside"] == "below" and below.describe()["caps"] is True
    s = slice_field(below, random_rotation(2), 0.0, 0.0, 64)
    assert s.volume == pytest.approx(ball, rel=0.03)
    assert np.linalg.norm(s.vertices, axis=1) == pytest.approx(R, abs=0.03)
    # the default side: the cube's cut (8 at the identity) less the ball
    assert slice_field(above, np.eye(4), 0.0, 0.0, 64).volume == pytest.approx(8 - ball, rel=0.01)
    rows = dict(below.slice(np.eye(4), 0.0).readout)
    assert rows["surface"] == "encloses f <= level"
    with pytest.raises(ValueError, match=r"'above'.*'below'.*got 'inner'"):
        Field4D(sd, axes="xyzw", inside="inner")
    with pytest.raises(ValueError, match=r"'above'.*'below'"):
        below.inside = "outside"


def _face_area(s, half=1.0, eps=1e-6):
    """Area of the triangles lying on the cube's faces |x_i| = half (slice at the identity)."""
    v = s.vertices[s.triangles]  # (k, 3, 3)
    on = np.zeros(len(v), dtype=bool)
    for i in range(3):
        on |= np.all(np.abs(np.abs(v[:, :, i]) - half) < eps, axis=1)
    cr = np.cross(v[on, 1] - v[on, 0], v[on, 2] - v[on, 0])
    return float(np.linalg.norm(cr, axis=1).sum()) / 2


def test_caps_off_leaves_a_box_filling_field_open_on_the_faces():
    g = np.linspace(-1.0, 1.0, 25)
    X = np.meshgrid(g, g, g, g, indexing="ij")
    per = np.cos(np.pi * X[0]) * np.cos(np.pi * X[1]) + np.cos(np.pi * X[2]) * np.cos(np.pi * X[3])
    capped = Field4D(per, axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.0])
    open_ = Field4D(per, axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.0], caps=False)
    a = slice_field(capped, np.eye(4), 0.1, 0.0, 48)
    b = slice_field(open_, np.eye(4), 0.1, 0.0, 48)
    assert _face_area(a) > 5.0  # about half of the six faces (24) is enclosed
    assert _face_area(b) < 0.01 * _face_area(a)
    assert b.area < a.area and math.isnan(b.volume) and not math.isnan(a.volume)
    # the open surface stays in the box, its edge within one sample of a face
    assert np.abs(b.vertices).max() <= 1 + b.spacing
    assert open_.describe()["caps"] is False
    assert "open on the box's faces" in dict(open_.slice(np.eye(4), 0.1).readout)["surface"]
    assert open_.slice(random_rotation(3), 0.1).volume is None  # the widget shows no volume
    with pytest.raises(TypeError, match="caps"):
        Field4D(per, axes="xyzw", caps="no")
