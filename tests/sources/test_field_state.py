"""A field opened from a file keeps through a state file (the scientist's path, trustworthy).

`Rot4DWidget.from_state("view.json")` used to raise "pass it, from_state(path, source=...)" for
any field read with xarray unless it was opened with `open_field`, and a loaded field lost its
``inside`` and ``caps``.  Here a small netCDF file (scipy engine) and a zarr store are written in
tmp_path, opened lazily and chunked, with a selection, saved with `save_state` and loaded with
`load_state`: the rebuilt field must slice exactly as the saved one and keep its levels, inside,
caps, w_per_unit and resolution.  A file written in today's version-1 format (by hand, as the old
code wrote it) still loads.

The data range: from the variable's metadata (``actual_range``, ``valid_min``/``valid_max``)
without a single read; from the whole array when it is in memory; from the coarse copy for
chunked data, and then the readout says so.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import warnings

import numpy as np
import pytest

from rot4d_widget.keep.rebuild import SourceNotRebuildable
from rot4d_widget.keep.statefile import load_state, save_state
from rot4d_widget.sources.field.coarse import COARSE_SAMPLES
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.core.state import RotationState

xr = pytest.importorskip("xarray")
pytest.importorskip("scipy")

NT = 12
G = np.linspace(-1.0, 1.0, 9)
M = random_rotation(np.random.default_rng(7))


def _values():
    t = np.linspace(0.0, 1.0, NT)[:, None, None, None]
    r2 = G[None, None, None, :] ** 2 + G[None, None, :, None] ** 2 + G[None, :, None, None] ** 2
    return 0.9 - r2 + 0.4 * t + np.random.default_rng(1).normal(0.0, 0.01, (NT, 9, 9, 9))


def _dataset():
    return xr.Dataset({"T": (("time", "z", "y", "x"), _values(), {"units": "K"}),
                       "other": (("time", "z", "y", "x"), -_values())},
                      coords={"time": np.linspace(0.0, 5.5, NT), "z": G, "y": G, "x": G})


def _has(module):
    try:
        __import__(module)
    except ImportError:
        return False
    return True


@pytest.fixture
def data(tmp_path):
    """A folder holding run.nc (netCDF3, scipy) and, with zarr, run.zarr."""
    d = tmp_path / "data"
    d.mkdir()
    ds = _dataset()
    ds.to_netcdf(d / "run.nc", engine="scipy")
    if _has("zarr"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zarr 3: consolidated metadata is not in the spec
            ds.to_zarr(d / "run.zarr", mode="w")
    return d


def _state():
    return RotationState(0.05, c0=0.1)


def _tune(field):
    field.levels = (0.3, 0.55)
    field.inside = "below"
    field.caps = False
    field.w_per_unit = 0.7
    field.resolution = 20
    return field


def _assert_same_field(back, field):
    assert isinstance(back, Field4D)
    assert back.levels == field.levels and back.inside == field.inside and back.caps == field.caps
    assert back.w_per_unit == field.w_per_unit and back.resolution == field.resolution
    assert back.axes == field.axes and back.extent == field.extent and back.shape == field.shape
    assert back.name == field.name and back.units == field.units and back.w_units == field.w_units
    origin, per = field.w_frame
    assert back.w_frame == (origin, per)
    for d in (0.0, 0.15):  # the box's centre, and 0.15 slice units past it, in the data's w
        c0 = origin + per * d
        a, b = field.slice(M, c0), back.slice(M, c0)
        assert len(a.triangles) > 0
        np.testing.assert_array_equal(b.points, a.points)
        np.testing.assert_array_equal(b.triangles, a.triangles)
        for sa, sb in zip(a.levels, b.levels):
            np.testing.assert_array_equal(sb.vertices, sa.vertices)
            assert sb.volume == sa.volume or (np.isnan(sb.volume) and np.isnan(sa.volume))


OPENINGS = {
    "netcdf lazy": dict(path="run.nc", engine="scipy"),
    "netcdf chunked": dict(path="run.nc", engine="scipy", chunks={}),
    "netcdf isel": dict(path="run.nc", engine="scipy", isel={"time": slice(2, 10)}),
    "netcdf loaded": dict(path="run.nc", engine="scipy", load=True),
    "zarr lazy": dict(path="run.zarr"),
    "zarr chunked sel": dict(path="run.zarr", chunks={}, sel={"time": slice(1.0, 4.5)}),
}


@pytest.mark.parametrize("how", list(OPENINGS))
def test_a_field_opened_from_a_file_is_rebuilt_by_a_state_file(data, tmp_path, how):
    kw = dict(OPENINGS[how])
    if "zarr" in how and not _has("zarr"):
        pytest.skip("zarr is not installed")
    if "chunks" in kw:
        pytest.importorskip("dask")
    field = _tune(Field4D.open(data / kw.pop("path"), "T", w="time", **kw))
    if "isel" in kw or "sel" in kw:
        assert field.shape[3] < NT
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # rebuildable: no SourceNotRebuildable, on saving or loading
        save_state(tmp_path / "view.json", _state(), field, {"levels": list(field.levels)})
        state, back, settings = load_state(tmp_path / "view.json")
    doc = json.loads((tmp_path / "view.json").read_text())
    origin = doc["source"]["origin"]
    assert origin["path"] == os.path.abspath(field.origin["path"]) and origin["variable"] == "T"
    assert origin["kwargs"]["w"] == "time" and doc["source"]["inside"] == "below" and doc["source"]["caps"] is False
    assert doc["version"] == 2  # inside="below" and caps=False: a version-1 reader would drop them
    assert settings == {"levels": [0.3, 0.55]}
    np.testing.assert_array_equal(state.matrix, _state().matrix)
    _assert_same_field(back, field)
    assert back.values.shape == field.values.shape
    assert type(back.values) is type(field.values)  # lazy stays lazy, chunked chunked, loaded in memory


def test_the_widget_from_state_rebuilds_a_file_field(data, tmp_path, make):
    """The README's `Rot4DWidget.from_state("view.json")`, for a field read from a netCDF file."""
    from rot4d_widget import Rot4DWidget

    field = Field4D.open(data / "run.nc", w="time", engine="scipy", variable="T")
    w = make(field, levels=[0.4])
    w.press("4")
    w.save_state(tmp_path / "view.json")
    w2 = Rot4DWidget.from_state(tmp_path / "view.json", _autotick=False)
    try:
        assert isinstance(w2.source, Field4D) and w2.levels == (0.4,)
        np.testing.assert_array_equal(w2.state.matrix, w.state.matrix)
        np.testing.assert_array_equal(w2.slice.points, w.slice.points)
    finally:
        w2.close()


def test_the_state_file_keeps_a_path_relative_to_itself_when_the_data_sit_beside_it(data, tmp_path):
    field = _tune(Field4D.open(data / "run.nc", "T", w="time", engine="scipy"))
    save_state(data / "view.json", _state(), field)
    doc = json.loads((data / "view.json").read_text())
    assert doc["source"]["origin"]["relative_path"] == "run.nc"
    moved = tmp_path / "moved"
    shutil.move(data, moved)  # the folder moved, data and state file together: the absolute path is gone
    _, back, _ = load_state(moved / "view.json")
    assert back.origin["path"] == str(moved / "run.nc")
    _assert_same_field(back, field)
    # a state file in a folder the data are not in keeps the absolute path only
    (tmp_path / "other").mkdir()
    save_state(tmp_path / "other" / "view.json", _state(), back)
    assert "relative_path" not in json.loads((tmp_path / "other" / "view.json").read_text())["source"]["origin"]
    save_state(tmp_path / "above.json", _state(), back)  # a folder above the data: a path down to them
    assert json.loads((tmp_path / "above.json").read_text())["source"]["origin"]["relative_path"] == "moved/run.nc"
    os.remove(moved / "run.nc")
    with pytest.warns(SourceNotRebuildable, match="not found at .*run.nc.*Field4D.open"):
        _, gone, _ = load_state(moved / "view.json")
    assert gone is None


def test_a_rewritten_file_is_refused_not_read_as_the_saved_field(data, tmp_path):
    field = Field4D.open(data / "run.nc", "T", w="time", engine="scipy")
    save_state(tmp_path / "view.json", _state(), field)
    _dataset().isel(time=slice(0, 6)).to_netcdf(data / "run2.nc", engine="scipy")
    os.replace(data / "run2.nc", data / "run.nc")
    with pytest.warns(SourceNotRebuildable, match="no longer holds the saved field: its shape"):
        _, back, _ = load_state(tmp_path / "view.json")
    assert back is None


def test_from_xarray_records_the_path_xarray_s_encoding_gives(data, tmp_path):
    """The netCDF4 and h5netcdf engines put the file's path in ``da.encoding["source"]`` (scipy
    and zarr do not: set here by hand, as netCDF4 does); `from_xarray` records it."""
    da = xr.open_dataset(data / "run.nc", engine="scipy")["T"]
    da.encoding["source"] = str(data / "run.nc")
    field = _tune(Field4D.from_xarray(da, w="time"))
    assert field.origin["path"] == str(data / "run.nc") and field.origin["variable"] == "T"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        save_state(tmp_path / "view.json", _state(), field)
        _, back, _ = load_state(tmp_path / "view.json")
    _assert_same_field(back, field)
    # a selection xarray's encoding shows (original_shape) is not taken for the whole variable
    part = da.isel(time=slice(0, 5))
    part.encoding["original_shape"] = da.shape
    assert Field4D.from_xarray(part, w="time").origin is None


def test_a_zarr_field_from_xarray_says_to_use_field4d_open(data, tmp_path):
    if not _has("zarr"):
        pytest.skip("zarr is not installed")
    field = Field4D.from_xarray(xr.open_dataset(data / "run.zarr", engine="zarr")["T"], w="time")
    assert field.origin is None  # xarray keeps no path for a zarr store
    with pytest.warns(SourceNotRebuildable, match=r"Field4D.open\(path, variable"):
        save_state(tmp_path / "view.json", _state(), field)


#: The README's xarray route (issue 35): the Dataset as xarray opened it, and the variable's name.
XARRAY_OPENINGS = {
    "netcdf scipy lazy": lambda d: xr.open_dataset(d / "run.nc", engine="scipy"),
    "netcdf xarray's engine": lambda d: xr.open_dataset(d / "run.nc"),  # scipy here: netCDF4 is not a dependency
    "netcdf chunked": lambda d: xr.open_dataset(d / "run.nc", engine="scipy", chunks={}),
    "netcdf loaded": lambda d: xr.open_dataset(d / "run.nc", engine="scipy").load(),
    "zarr open_zarr": lambda d: xr.open_zarr(d / "run.zarr"),
    "zarr open_zarr lazy": lambda d: xr.open_zarr(d / "run.zarr", chunks=None),
}


@pytest.mark.parametrize("how", list(XARRAY_OPENINGS))
def test_the_readme_xarray_route_is_reopened_by_a_state_file_alone(data, tmp_path, how):
    """`Field4D.from_xarray(xarray.open_dataset(path), "T", w="time")` -- any engine, the scipy one
    xarray picks when netCDF4 is absent included -- or `open_zarr`: saved without a warning and
    rebuilt from the state file alone, the same field, lazy staying lazy.  Before, a Dataset was
    refused and `ds["T"]` from these engines kept no path (saving warned, loading gave no source)."""
    if "zarr" in how and not _has("zarr"):
        pytest.skip("zarr is not installed")
    if "chunked" in how or how == "zarr open_zarr":
        pytest.importorskip("dask")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=RuntimeWarning)  # zarr: no consolidated metadata
        ds = XARRAY_OPENINGS[how](data)
    field = _tune(Field4D.from_xarray(ds, "T", w="time"))
    assert field.origin is not None and field.origin["variable"] == "T"
    with warnings.catch_warnings():
        warnings.simplefilter("error", category=SourceNotRebuildable)
        save_state(tmp_path / "view.json", _state(), field)
        state, back, _ = load_state(tmp_path / "view.json")
    _assert_same_field(back, field)
    assert type(back.values) is type(field.values)  # lazy stays lazy, chunked chunked, loaded in memory
    doc = json.loads((tmp_path / "view.json").read_text())
    assert doc["source"]["rebuild"] is True and os.path.exists(doc["source"]["origin"]["path"])
    ds.close()


def test_the_widget_from_state_alone_reopens_a_field_from_the_readme_xarray_route(data, tmp_path, make):
    from rot4d_widget import Rot4DWidget

    ds = xr.open_dataset(data / "run.nc", engine="scipy")
    w = make(Field4D.from_xarray(ds, "T", w="time"), levels=[0.4])
    w.press("4")
    with warnings.catch_warnings():
        warnings.simplefilter("error", category=SourceNotRebuildable)
        w.save_state(tmp_path / "view.json")
        w2 = Rot4DWidget.from_state(tmp_path / "view.json", _autotick=False)
    try:
        np.testing.assert_array_equal(w2.state.matrix, w.state.matrix)
        np.testing.assert_array_equal(w2.slice.points, w.slice.points)
    finally:
        w2.close()


def test_what_the_xarray_route_cannot_keep_is_said_when_saving(data, tmp_path):
    """A DataArray from the scipy engine names no file, and a selection made on the Dataset after
    opening would reopen as the whole variable: both are saved with a warning that says why and
    what keeps them (the Dataset and a name; `Field4D.open` with isel= / sel=)."""
    ds = xr.open_dataset(data / "run.nc", engine="scipy")
    da_field = Field4D.from_xarray(ds["T"], w="time")
    with pytest.warns(SourceNotRebuildable, match=r"DataArray does not say which file.*scipy.*"
                                                  r"Field4D.from_xarray\(ds, 'T', w=...\)"):
        save_state(tmp_path / "a.json", _state(), da_field)
    part = Field4D.from_xarray(ds.isel(time=slice(2, 10)), "T", w="time")
    assert part.origin is None
    with pytest.warns(SourceNotRebuildable, match=r"a selection of 'T' in .*run.nc.*Field4D.open\(path, 'T', isel="):
        save_state(tmp_path / "b.json", _state(), part)
    mem = Field4D.from_xarray(_dataset(), "T", w="time")  # made in memory: no file
    assert mem.origin is None and "no encoding['source']" in mem.describe()["rebuild"]


def test_a_version_1_state_file_still_loads(data, tmp_path):
    """A file as the code before version 2 wrote it (open_field's origin, no inside/caps)."""
    field = Field4D.open(data / "run.nc", "T", w="time", engine="scipy", levels=(0.35,))
    d = field.describe()
    for key in ("inside", "caps"):
        d.pop(key)
    d.update(resolution=32, coarse_resolution=24, w_units=None, rebuild=True,
             origin={"kind": "xarray", "path": str(data / "run.nc"), "variable": "T", "engine": "scipy",
                     "kwargs": {"w": "time"}},
             array=f"read from {str(data / 'run.nc')!r} (reopened from there)")
    doc = {"format": "rot4d_widget state", "version": 1, "state": _state().to_dict(), "source": d,
           "settings": {"levels": [0.35]}, "rot4d_widget": "0.1.0"}
    (tmp_path / "old.json").write_text(json.dumps(doc))
    _, back, settings = load_state(tmp_path / "old.json")
    assert back.levels == (0.35,) and back.inside == "above" and back.caps is True and back.resolution == 32
    _assert_same_field(back, Field4D.open(data / "run.nc", "T", w="time", engine="scipy", levels=(0.35,),
                                          resolution=32))


@pytest.mark.parametrize("origin, match", [
    ({"kwargs": {"_function": "os:system"}}, "'kwargs' to name only"),
    ({"engine": "../evil"}, "xarray engine's name"),
    ({"isel": {"time": {"slice": [0, 3, None], "x": 1}}}, "slice"),
    ({"isel": {"time": [{"a": 1}]}}, "numbers, strings or slices"),
])
def test_a_state_file_origin_is_data_only(data, tmp_path, origin, match):
    """An origin names a file, a variable, an xarray engine, a selection and from_xarray's own
    keywords -- nothing else is taken from it (a file stays data: allow_code is not needed)."""
    field = Field4D.open(data / "run.nc", "T", w="time", engine="scipy")
    save_state(tmp_path / "view.json", _state(), field)
    doc = json.loads((tmp_path / "view.json").read_text())
    doc["source"]["origin"].update(origin)
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=match):
        load_state(tmp_path / "bad.json")


def test_inside_and_caps_of_a_function_field_are_restored(tmp_path):
    from test_export import ball_minus_w

    f = Field4D.from_function(ball_minus_w, [(-1, 1)] * 4, resolution=24, levels=(0.2,))
    f.inside, f.caps = "below", False
    save_state(tmp_path / "f.json", _state(), f)
    _, back, _ = load_state(tmp_path / "f.json", function=ball_minus_w)
    assert back.inside == "below" and back.caps is False
    a, b = f.slice(M, 0.1), back.slice(M, 0.1)
    np.testing.assert_array_equal(b.points, a.points)


# ----------------------------------------------------------------------------- the data range
#: Reads of the data behind `_lazy_dataarray`, counted in a module global (xarray or dask may copy
#: the array objects they are handed; a global is the same one in every copy).
READS = {"n": 0}


def _read(values, key):
    READS["n"] += 1
    return values[key]


def _lazy_dataarray(values, attrs, encoding=None):
    """A DataArray over a lazily indexed backend array (as netCDF or zarr opened without chunks)
    whose reads are counted in `READS`."""
    from xarray.backends import BackendArray
    from xarray.core import indexing

    class Backend(BackendArray):
        shape, dtype = values.shape, values.dtype

        def __getitem__(self, key):
            return indexing.explicit_indexing_adapter(key, self.shape, indexing.IndexingSupport.BASIC,
                                                      lambda k: _read(values, k))

    var = xr.Variable(("time", "z", "y", "x"), indexing.LazilyIndexedArray(Backend()), attrs=attrs)
    da = xr.DataArray(var, coords={"time": np.arange(NT, dtype=float), "z": G, "y": G, "x": G}, name="T")
    da.encoding.update(encoding or {})
    READS["n"] = 0
    return da


@pytest.mark.parametrize("attrs, encoding, want, where", [
    ({"valid_min": -2.0, "valid_max": 2.5}, None, (-2.0, 2.5), "valid_min/valid_max"),
    ({"valid_range": np.array([-1.0, 1.5])}, None, (-1.0, 1.5), "valid_range"),
    ({"actual_range": [-0.5, 1.25], "valid_min": -9.0, "valid_max": 9.0}, None, (-0.5, 1.25), "actual_range"),
    ({"valid_min": np.int16(0), "valid_max": np.int16(1000)}, {"scale_factor": 0.01, "add_offset": -5.0},
     (-5.0, 5.0), "valid_min/valid_max"),  # packed bounds, unpacked as xarray unpacks the data
])
def test_the_data_range_comes_from_metadata_without_a_read(attrs, encoding, want, where):
    da = _lazy_dataarray(_values(), attrs, encoding)
    field = Field4D.from_xarray(da, w="time")
    assert field.data_range == pytest.approx(want) and field.data_range_source == where
    assert field.levels == pytest.approx(((want[0] + want[1]) / 2,))
    assert READS["n"] == 0
    rows = dict(field.slice(M, 0.0).readout)  # a slice reads, and names the range's source
    assert READS["n"] > 0 and rows["level"].endswith(f"({where})")


@pytest.mark.parametrize("attrs, dtype", [
    ({"valid_min": -1e308, "valid_max": 1e308}, "f8"),  # a step of 1/50 of the span overflowed: o made it inf
    ({"valid_range": np.array([-1e307, 1e307])}, "f4"),  # beyond what float32 data hold
    ({"actual_range": [1.0, 1.0]}, "f8"),  # o / i had nowhere to go, and said nothing
])
def test_metadata_that_is_no_range_to_step_through_is_ignored_and_the_keys_move_the_level(attrs, dtype, make):
    """Issue 33, item 4: each case failed before (the level became inf, or stayed put)."""
    da = _lazy_dataarray(_values().astype(dtype), attrs)
    field = Field4D.from_xarray(da, w="time")
    assert field.data_range_source not in ("actual_range", "valid_range", "valid_min/valid_max")
    lo, hi = field.data_range
    assert math.isfinite(lo) and math.isfinite(hi) and lo < hi
    w = make(field)
    before = field.levels
    for _ in range(3):
        w.press("o")
    assert all(math.isfinite(v) for v in field.levels) and field.levels[0] > before[0]
    for _ in range(3):
        w.press("i")
    assert field.levels == pytest.approx(before)
    assert w.errors.outputs == ()


def test_a_level_step_never_overflows_on_data_that_reach_the_float_limits():
    a = np.zeros((NT, 6, 6, 6))
    a[0, 0, 0, 0], a[-1, -1, -1, -1] = -1e308, 1e308
    field = Field4D(a, axes="wzyx")
    assert math.isfinite(field.level_step) and field.level_step > 0
    for _ in range(60):
        field.step_levels(1)
    assert all(math.isfinite(v) for v in field.levels)


def test_the_data_range_of_a_lazy_field_without_metadata_is_the_coarse_copy_s_and_says_so():
    da = _lazy_dataarray(_values(), {})
    field = Field4D.from_xarray(da, w="time", memory_budget=0)  # bigger than its budget: never read whole
    rng = field.data_range
    assert READS["n"] > 0 and rng == field.coarse().data_range
    assert field.data_range_source == "coarse copy"
    assert dict(field.slice(M, 0.0).readout)["level"].endswith("(coarse copy)")


def test_an_array_in_memory_has_the_range_of_all_its_samples_not_the_coarse_copy_s():
    n = 2 * COARSE_SAMPLES + 3
    a = np.zeros((n, 6, 6, 6))
    a[:, 2:4, 2:4, 2:4] = np.linspace(0.0, 0.5, n)[:, None, None, None]
    a[7, 3, 3, 3] = 0.53  # a peak between two of the coarse copy's nodes
    field = Field4D(a, axes="wzyx")
    assert field.coarse().data_range[1] < 0.53
    assert field.data_range == (0.0, 0.53) and field.data_range_source == "data"
    assert field.levels == (0.265,)
    level = dict(field.slice(M, 0.0).readout)["level"]
    assert level.endswith("of 0 \u2026 0.53"), level
    dask = pytest.importorskip("dask.array")
    lazy = Field4D(dask.from_array(a, chunks=(8, 6, 6, 6)), axes="wzyx", memory_budget=0)  # never read whole
    assert lazy.data_range == field.coarse().data_range and lazy.data_range_source == "coarse copy"
    assert dict(lazy.slice(M, 0.0).readout)["level"].endswith("(coarse copy)")
    fits = Field4D(dask.from_array(a, chunks=(8, 6, 6, 6)), axes="wzyx")  # read whole in the coarse copy's pass
    assert fits.data_range == (0.0, 0.53) and fits.data_range_source == "data" and fits.resident is not None


def test_a_plain_zarr_array_s_own_attributes_give_the_range_without_a_read():
    zarr = pytest.importorskip("zarr")
    z = zarr.create_array(zarr.storage.MemoryStore(), shape=(NT, 6, 6, 6), chunks=(2, 6, 6, 6), dtype="f4")
    z[:] = np.linspace(-1.0, 1.0, NT * 216, dtype=np.float32).reshape(z.shape)
    z.attrs["actual_range"] = [-1.0, 1.0]
    field = Field4D(z, axes="wzyx")
    assert field.data_range == (-1.0, 1.0) and field.data_range_source == "actual_range"
    assert field._reader is None or field._reader.reads == 0  # nothing read for it
    z2 = zarr.create_array(zarr.storage.MemoryStore(), shape=(NT, 6, 6, 6), chunks=(2, 6, 6, 6), dtype="f4")
    z2[:] = z[:]
    assert Field4D(z2, axes="wzyx").data_range_source != "actual_range"  # without the attribute: from the data
