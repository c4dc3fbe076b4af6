"""What used to pass in silence is said (issue 37, problem 5).

* ``Rot4DWidget(dataarray)`` names `Field4D.from_xarray` (a Dataset: with the variable's name; an
  array: `Field4D(a, axes=...)`).
* A block of NaN in w (a failed write: whole time steps) is reported once, as a `NonFiniteWarning`
  and in the readout's "missing" row, with its time range and the fraction of samples -- for data in
  memory at first need, for lazy data when the read over all of it (the coarse copy's pass, the
  widget's background read) finds it; a mask every step shares and a stray NaN stay silent.
* Missing units are warned of once, naming the attribute to set.
* datetime64 times are shown as dates and times (box labels, the readout's c0 and w cut, slice
  labels) and c0 steps in seconds.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.checks import NonFiniteWarning

xr = pytest.importorskip("xarray")
pytestmark = pytest.mark.usefixtures("recording_comms")


def flame_da(n=12, nt=12, units=True):
    x = np.linspace(0.01, 0.05, n)
    t = np.linspace(0.001, 0.004, nt)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    T = np.empty((nt, n, n, n), np.float32)
    for k, tk in enumerate(t):
        r = np.sqrt((X - 0.03) ** 2 + (Y - 0.03) ** 2 + (Z - 0.03) ** 2)
        T[k] = (300 + 1700 / (1 + np.exp((r - 0.004 - 4 * (tk - 0.001)) / 0.0015))).transpose(2, 1, 0)
    u = (lambda v: {"units": v}) if units else (lambda v: {})
    return xr.DataArray(T, dims=("time", "z", "y", "x"), name="T", attrs=u("K"),
                        coords={"time": ("time", t, u("s")), "z": ("z", x, u("m")), "y": ("y", x, u("m")),
                                "x": ("x", x, u("m"))})


def readout_rows(w):
    html = str(w._painter.readout_html())
    return {re.sub("<[^>]*>", "", k): re.sub("<[^>]*>", "", v)
            for k, v in re.findall(r"<tr><td>(.*?)</td><td>(.*?)</td></tr>", html)}


def test_a_dataarray_given_to_the_widget_names_from_xarray(make):
    da = flame_da(6, 4)
    with pytest.raises(TypeError, match=r"Field4D\.from_xarray\(da\)"):
        make(da)
    with pytest.raises(TypeError, match=r"Field4D\.from_xarray\(ds, 'T'\)"):
        make(da.to_dataset())
    with pytest.raises(TypeError, match=r"Field4D\(a, axes='wzyx'\)"):
        make(da.values)


def test_a_block_of_nan_is_reported_once_with_its_times_and_share(make):
    da = flame_da()
    da[5:8] = np.nan  # three whole steps lost
    field = Field4D.from_xarray(da)
    want = r"NaN in time 0\.002364 \u2026 0\.002909 s \(3 of 12 steps\), 25 % of the samples"
    with pytest.warns(NonFiniteWarning, match=want):
        w = make(field)
    for rendering in ("surface", "mip", "volume", "sections"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # once
            w.rendering = rendering
        assert readout_rows(w)["missing"] == ("NaN in time 0.002364 \u2026 0.002909 s (3 of 12 steps), 25 % of the "
                                              "samples"), rendering


def test_a_shared_mask_and_a_stray_nan_stay_silent(make):
    da = flame_da()
    da[:, :2, :, :] = np.nan  # the same samples missing at every step: a mask
    da[3, 5, 5, 5] = np.nan  # one stray sample
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w = make(Field4D.from_xarray(da))
    assert "missing" not in readout_rows(w)


@pytest.mark.parametrize("budget", [0, None])
def test_lazy_data_report_the_block_when_the_read_over_them_finds_it(make, budget):
    dask = pytest.importorskip("dask.array")
    da = flame_da()
    da[9:] = np.nan
    lazy = da.copy(data=dask.from_array(da.values, chunks=(3, 6, 6, 6)))
    kw = {} if budget is None else {"memory_budget": budget}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing read yet: nothing to say
        field = Field4D.from_xarray(lazy, **kw)
        w = make(field)
    assert field.missing is None and "missing" not in readout_rows(w)
    with pytest.warns(NonFiniteWarning, match=r"NaN in time 0\.003455 \u2026 0\.004 s \(3 of 12 steps\)"):
        field.coarse()  # the read over all of it (the widget's background read does the same)
        w._painter.data_read()  # what the widget does when that read ends: draw again
    assert readout_rows(w)["missing"].startswith("NaN in time 0.003455 \u2026 0.004 s (3 of 12 steps)")


def test_missing_units_are_warned_once_naming_the_attribute():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Field4D.from_xarray(flame_da(6, 4))  # all given: silent
    with pytest.warns(UserWarning) as got:
        Field4D.from_xarray(flame_da(6, 4, units=False))
    texts = [str(r.message) for r in got if type(r.message).__name__ == "UnitsWarning"]
    assert len(texts) == 1, texts
    for attr in ("da.attrs['units']", "da['x'].attrs['units']", "da['time'].attrs['units']", "units=",
                 "space_units=", "w_units="):
        assert attr in texts[0], (attr, texts[0])


def test_datetime64_times_are_dates_and_c0_steps_in_seconds(make):
    import pandas as pd

    da = flame_da().assign_coords(time=pd.date_range("2021-03-04T12:00", periods=12, freq="5min"))
    field = Field4D.from_xarray(da)
    w = make(field, c0=1800.0)
    corner = w.scene.buffer.labels[0]["text"]
    assert corner.endswith("time 2021-03-04 12:30:00"), corner
    rows = readout_rows(w)
    assert rows["c0"].startswith("2021-03-04 12:30:00 (c0 = 1800 s)"), rows["c0"]
    assert rows["w cut"].startswith("2021-03-04 12:30:00 \u2026 2021-03-04 12:30:00 (data 2021-03-04 12:00:00 \u2026 "
                                    "2021-03-04 12:55:00)"), rows["w cut"]
    w.slices = 3
    w.spacing = 600.0  # seconds
    assert [lab["text"] for lab in w.scene.buffer.labels] == [
        "time 2021-03-04 12:20:00", "time 2021-03-04 12:30:00", "time 2021-03-04 12:40:00"]
    step = w.state.c0_step  # seconds: l / h move c0 by it
    w.press("h")
    assert abs(w.c0 - 1800.0) == pytest.approx(step) and 1.0 < step < 3300.0
