"""A field keeps xarray's ``long_name`` (CF's descriptive name) for its colour bar: from
`Field4D.from_xarray`, from `Field4D.open` (netCDF and zarr), and through a state file, which
reopens the file and so reads it again; None when the attribute is absent or blank."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

xr = pytest.importorskip("xarray")

from rot4d_widget.core.state import RotationState  # noqa: E402
from rot4d_widget.keep.statefile import load_state, save_state  # noqa: E402
from rot4d_widget.sources.field.container import Field4D  # noqa: E402

LONG = "Sea surface temperature"


def _da(attrs):
    t = np.arange(4.0)
    x = np.linspace(0.0, 3.0, 5)
    X, Y, Z, T = np.meshgrid(x, x, x, t, indexing="ij")
    f = 280.0 + X + Y - Z + 0.5 * T
    return xr.DataArray(f.transpose(3, 2, 1, 0), dims=("time", "z", "y", "x"), name="sst", attrs=attrs,
                        coords={"time": ("time", t, {"units": "s"}), "z": x, "y": x, "x": x})


def test_from_xarray_keeps_long_name_and_units():
    field = Field4D.from_xarray(_da({"long_name": LONG, "units": "K"}))
    assert (field.long_name, field.name, field.units) == (LONG, "sst", "K")


@pytest.mark.parametrize("attrs", [{}, {"units": "K"}, {"long_name": ""}, {"long_name": "   "}])
def test_long_name_is_none_when_absent_or_blank(attrs):
    assert Field4D.from_xarray(_da(attrs)).long_name is None


def test_other_fields_have_none_and_may_be_given_one():
    f = Field4D(np.zeros((3, 3, 3, 3)), axes="xyzw", name="f")
    assert f.long_name is None
    f.long_name = "my variable"
    assert f.long_name == "my variable" and Field4D(np.zeros((3, 3, 3, 3)), axes="xyzw").long_name is None


@pytest.mark.parametrize("kind", ["netcdf", "zarr"])
def test_open_keeps_it_and_a_state_file_reopens_it(tmp_path, kind):
    pytest.importorskip("scipy" if kind == "netcdf" else "zarr")
    da = _da({"long_name": LONG, "units": "K"})
    path = tmp_path / ("sst.nc" if kind == "netcdf" else "sst.zarr")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zarr: consolidated metadata, v3 notes
        da.to_dataset().to_netcdf(path) if kind == "netcdf" else da.to_dataset().to_zarr(path)
        field = Field4D.open(path, "sst", w="time")
    assert (field.long_name, field.units) == (LONG, "K")
    # what a state file keeps of the field: its origin (the file), name and units; the long name
    # comes back with the file
    saved = save_state(tmp_path / "view.json", RotationState(), field)
    assert saved["source"]["name"] == "sst" and saved["source"]["units"] == "K"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        loaded = load_state(tmp_path / "view.json")
    assert isinstance(loaded.source, Field4D)
    assert (loaded.source.long_name, loaded.source.name, loaded.source.units) == (LONG, "sst", "K")


def test_the_colour_bar_says_long_name_and_units():
    from rot4d_widget import Rot4DWidget

    w = Rot4DWidget(Field4D.from_xarray(_da({"long_name": LONG, "units": "K"})), _autotick=False)
    try:
        assert f"{LONG} [K]" in w.readout.value
    finally:
        w.close()
    w = Rot4DWidget(Field4D.from_xarray(_da({"units": "K"})), _autotick=False)
    try:
        assert "sst [K]" in w.readout.value and LONG not in w.readout.value  # without it: the variable's name
    finally:
        w.close()
