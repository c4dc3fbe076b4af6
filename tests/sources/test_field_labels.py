"""Labels of a field's cut box (`box_labels`): the data coordinates at the grid's origin corner and
what changes along each edge leaving it, against the field's frame written out here."""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.core.rotation import random_rotation, simple_rotation
from rot4d_widget.sources.field_labels import axis_names, box_labels
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.grid import sample_field

EXTENT = ((3.0, 12.0), (-2.0, 2.0), (0.0, 6.0), (0.0, 38.0))


def field(**kw):
    return Field4D.from_function(lambda x, y, z, w: x + y + z + w, EXTENT, space_units="mm", w_units="s", **kw)


def test_at_rest_each_edge_is_one_data_axis_from_its_first_node_to_its_last():
    f = field(w_per_unit=10.0)
    grid = sample_field(f, np.eye(4), 19.0, 16)
    labels = box_labels(f, np.eye(4), 19.0, grid)
    assert len(labels) == 4
    (p0, corner), *edges = labels
    np.testing.assert_allclose(p0, grid.origin)
    # the corner: the data coordinates at the grid's origin (its padding reaches a spacing past the box)
    q0 = f.centre + np.r_[grid.origin, 0.0]
    assert corner == f"x {q0[0]:.3g} mm, y {q0[1]:.3g} mm, z {q0[2]:.3g} mm, w 19 s"
    for a, (p, text) in enumerate(edges):
        want = np.array(grid.origin)
        want[a] = grid.extent[a][1]
        np.testing.assert_allclose(p, want)
        lo, hi = f.centre[a] + grid.extent[a][0], f.centre[a] + grid.extent[a][1]
        assert text == f"{'xyz'[a]} {lo:.3g} \u2192 {hi:.3g} mm"  # only that axis changes


def test_after_a_turn_into_time_an_edge_says_time_changes_along_it():
    f = field(w_per_unit=4.0)
    m = simple_rotation("xw", np.pi / 2)  # the picture's x is the data's w (time)
    c0 = 5.0  # data x here (w after the turn) ... in the data's w units, as Field4D.offset reads it
    grid = sample_field(f, m, c0, 16)
    labels = box_labels(f, m, c0, grid)
    q = f.to_data(np.array([p for p, _ in labels]), m, c0)
    text_x = labels[1][1]
    assert text_x.startswith("w ") and text_x.endswith(" s") and "x " not in text_x
    assert text_x == f"w {q[0, 3]:.3g} \u2192 {q[1, 3]:.3g} s"
    assert labels[2][1].startswith("y ") and labels[3][1].startswith("z ")


def test_a_random_turn_names_every_coordinate_that_changes_the_main_change_first():
    f = field()
    m = random_rotation(np.random.default_rng(4))
    c0 = 20.0
    grid = sample_field(f, m, c0, 12)
    labels = box_labels(f, m, c0, grid)
    pts = np.array([p for p, _ in labels])
    q = f.to_data(pts, m, c0)
    span = np.array([b - a for a, b in EXTENT])
    for a in range(3):
        text = labels[a + 1][1]
        parts = text.split(", ")
        change = np.abs(q[a + 1] - q[0]) / span
        moved = [c for c in np.argsort(-change, kind="stable") if change[c] > 1e-6]
        assert [p.split(" ")[0] for p in parts] == ["xyzw"[c] for c in moved]


def test_dims_names_and_no_units():
    xr = pytest.importorskip("xarray")
    da = xr.DataArray(np.zeros((4, 5, 6, 7)), dims=("time", "depth", "lat", "lon"),
                      coords={"time": np.arange(4.0), "depth": np.arange(5.0), "lat": np.arange(6.0),
                              "lon": np.arange(7.0)})
    f = Field4D.from_xarray(da, x="lon", y="lat", z="depth", w="time")
    assert axis_names(f) == ("lon", "lat", "depth", "time")
    grid = sample_field(f, np.eye(4), 1.0, 8)
    corner = box_labels(f, np.eye(4), 1.0, grid)[0][1]
    assert corner.startswith("lon ") and ", time 1" in corner
    plain = Field4D.from_function(lambda x, y, z, w: x, ((-1, 1),) * 4)
    assert axis_names(plain) == ("x", "y", "z", "w")
    corner = box_labels(plain, np.eye(4), 0.0, sample_field(plain, np.eye(4), 0.0, 8))[0][1]
    assert corner == "x -1.29, y -1.29, z -1.29, w 0"
    empty = sample_field(plain, np.eye(4), 5.0, 8)
    assert empty.empty and box_labels(plain, np.eye(4), 5.0, empty) == ()
