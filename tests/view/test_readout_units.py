"""The readout in the data's own units (issue 19, item 6, the widget's part): a field's slice
volume in its space units cubed (not "as drawn" in the view's scale), parallel slices labelled
by the data's w (a time in seconds), numbers without rounding noise."""

from __future__ import annotations

import math
import re

import pytest

from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.core.text import number_text

pytestmark = pytest.mark.usefixtures("recording_comms")

R = 1.5  # metres


def ball(**kw):
    f = Field4D.from_function(lambda x, y, z, w: R * R - (x * x + y * y + z * z), extent=[(-2, 2)] * 3 + [(0, 60)],
                              w_per_unit=15.0, w_units="s", levels=0.0, resolution=48, **kw)
    f.space_units = "m"
    return f


def test_the_volume_readout_is_the_slice_s_volume_in_cubic_metres(make):
    w = make(ball())
    text = w.readout.value
    true = 4 / 3 * math.pi * R ** 3  # the cylinder R over every t: each cut a ball of radius R
    shown = float(text.split("<td>volume</td><td>")[1].split(" ")[0])
    assert shown == pytest.approx(w.slice.volume, rel=1e-3)
    assert shown == pytest.approx(true, rel=0.03) and "m\u00b3" in text
    assert "counted at" not in text  # at rest nothing of w is in the volume
    w.press("4")
    assert "w counted at 15 s per m" in w.readout.value


def test_parallel_slices_are_labelled_in_seconds(make):
    w = make(ball(), slices=3, spacing=15.0)  # in seconds, as c0 (issue 37)
    legend = re.search(r"colours</td><td>(.*?)</td>", w.readout.value).group(1)
    labels = [t.strip() for t in re.findall(r"&nbsp;([^<]*)", legend)]
    assert labels == ["w 15 s", "w 30 s", "w 45 s"]


def test_numbers_for_people():
    assert number_text(-2.132e-14, 73.3) == "0"
    assert number_text(0.50671234) == "0.5067"


def test_inside_and_caps_are_traits_recorded_replayed_and_saved(make, tmp_path):
    """Issue 19: the field's new settings behave like every trait (recorded, replayed, saved)."""
    from rot4d_widget import Rot4DWidget

    w = make(ball())
    assert (w.inside, w.caps) == ("above", True)
    w.inside = "below"
    w.caps = False
    assert (w.source.inside, w.source.caps) == ("below", False)
    w.press("4")
    again = make(ball())
    again.replay(w.recording)
    assert (again.inside, again.caps) == ("below", False) and (again.source.inside, again.source.caps) == ("below", False)
    with pytest.raises((TypeError, ValueError)):
        w.inside = "sideways"
    assert w.inside == "below"
    poly = make("5-cell")
    with pytest.raises(TypeError, match="field"):
        poly.caps = False
    path = tmp_path / "view.json"
    w.save_state(path)
    back = make(ball())
    back.load_state(path)
    assert (back.inside, back.caps) == ("below", False)


def test_from_xarray_takes_the_space_units_and_the_readout_gives_cubic_metres(make, tmp_path):
    xr = pytest.importorskip("xarray")
    import numpy as np

    from rot4d_widget import Rot4DWidget

    x = np.linspace(-2, 2, 17)
    t = np.linspace(0.0, 60.0, 9)
    f = R * R - (x[None, None, None, :] ** 2 + x[None, None, :, None] ** 2 + x[None, :, None, None] ** 2)
    f = np.broadcast_to(f, (len(t), 17, 17, 17)).copy()
    da = xr.DataArray(f, dims=("time", "z", "y", "x"), name="f",
                      coords={"time": ("time", t, {"units": "s"}), "z": ("z", x, {"units": "m"}),
                              "y": ("y", x, {"units": "m"}), "x": ("x", x, {"units": "m"})})
    field = Field4D.from_xarray(da, w="time", levels=0.0)
    assert field.space_units == "m" and field.describe()["space_units"] == "m"
    w = make(field)
    assert "m\u00b3" in w.readout.value
    path = tmp_path / "f.nc"
    da.to_netcdf(path, engine="scipy")
    opened = Field4D.open(str(path), "f", w="time", levels=0.0)
    w2 = make(opened)
    w2.save_state(tmp_path / "v.json")
    back = Rot4DWidget.from_state(tmp_path / "v.json", _autotick=False)
    try:
        assert back.source.space_units == "m"
    finally:
        back.close()
