"""sample_field: the cut's values on a regular 3-D grid, against closed forms.

A linear field's grid values are its closed form at the nodes' data points (computed here from the
grid's origin and spacing, not through the package); a 4-ball's cut counts as much as its 3-volume;
nodes outside the data's box are NaN.  Orientations are seeded random rotations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.field.grid import FieldGrid
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.grid import sample_field

EXTENT = ((-1.0, 2.0), (0.0, 1.5), (-0.5, 0.5), (3.0, 5.0))
A = np.array([0.7, -1.3, 2.1, 0.4])
B = 0.25


def nodes(extent, shape):
    return np.meshgrid(*[np.linspace(a, b, n) for (a, b), n in zip(extent, shape)], indexing="ij")


def linear_array_field():
    X = nodes(EXTENT, (13, 9, 7, 11))
    a = sum(A[j] * X[j] for j in range(4)) + B
    return Field4D(a, axes="xyzw", extent=EXTENT, w_per_unit=0.8, name="lin", units="K")


def linear_function_field():
    return Field4D.from_function(lambda x, y, z, w: A[0] * x + A[1] * y + A[2] * z + A[3] * w + B, EXTENT,
                                 w_per_unit=0.8, name="lin", units="K")


def node_points(grid):
    """(nx, ny, nz, 3) slice coordinates of the grid's nodes, from origin and spacing."""
    idx = np.stack(np.indices(grid.values.shape), axis=-1).astype(np.float64)
    return grid.origin + grid.spacing * idx


def data_points(field, m, c0, p):
    """Data coordinates of slice points p (..., 3): centre + (m.T @ (p, d)) * unit, written out."""
    centre = np.array([(a + b) / 2 for a, b in EXTENT])
    unit = np.array([1.0, 1.0, 1.0, field.w_per_unit])
    d = (c0 - centre[3]) / field.w_per_unit
    p4 = np.concatenate([p, np.full(p.shape[:-1] + (1,), d)], axis=-1)
    return centre + (p4 @ m) * unit


def inside_box(q, margin=0.0):
    lo = np.array([a for a, _ in EXTENT])
    hi = np.array([b for _, b in EXTENT])
    return np.all((q >= lo + margin) & (q <= hi - margin), axis=-1)


@pytest.mark.parametrize("make", [linear_array_field, linear_function_field], ids=["array", "function"])
def test_a_linear_field_gives_its_closed_form_at_the_nodes(make):
    field = make()
    rng = np.random.default_rng(3)
    for c0 in (4.0, 3.8, 4.25):
        m = random_rotation(rng)
        grid = sample_field(field, m, c0, 24)
        assert isinstance(grid, FieldGrid) and not grid.empty
        q = data_points(field, m, c0, node_points(grid))
        expected = q @ A + B
        inside = inside_box(q, margin=1e-9)
        v = grid.values.astype(np.float64)
        assert inside.sum() > 100
        np.testing.assert_allclose(v[inside], expected[inside], rtol=1e-6, atol=1e-5)


def test_the_result_is_frozen_float32_with_its_frame():
    field = linear_array_field()
    m = random_rotation(np.random.default_rng(5))
    g = sample_field(field, m, 4.0, 20)
    assert g.values.dtype == np.float32 and g.values.ndim == 3
    assert not g.values.flags.writeable and not g.origin.flags.writeable
    with pytest.raises(ValueError):
        g.values[0, 0, 0] = 1.0
    with pytest.raises(AttributeError):
        g.spacing = 2.0
    assert g.name == "lin" and g.units == "K"
    assert g.data_range == pytest.approx(field.data_range)
    for a in range(3):  # extent: first and last node
        assert g.extent[a][0] == pytest.approx(g.origin[a])
        assert g.extent[a][1] == pytest.approx(g.origin[a] + g.spacing * (g.values.shape[a] - 1))
        np.testing.assert_allclose(g.axes[a][[0, -1]], g.extent[a])
    # resolution nodes along the longest side of the cut's bounding box, plus one of padding each side
    assert max(g.values.shape) == 20 + 2


def test_nodes_outside_the_box_are_nan_and_inside_finite():
    field = linear_array_field()
    rng = np.random.default_rng(7)
    for _ in range(3):
        m = random_rotation(rng)
        g = sample_field(field, m, 4.2, 20)
        q = data_points(field, m, 4.2, node_points(g))
        margin = 1e-7
        assert np.all(np.isnan(g.values[~inside_box(q, -margin)]))
        assert np.all(np.isfinite(g.values[inside_box(q, margin)]))
        assert np.isnan(g.values).any() and np.isfinite(g.values).any()


def test_a_four_ball_cut_counts_its_three_volume():
    R = 0.8
    box = ((-1.0, 1.0),) * 4
    field = Field4D.from_function(lambda x, y, z, w: x * x + y * y + z * z + w * w, box)
    rng = np.random.default_rng(11)
    for c0 in (0.0, 0.3, -0.5):
        m = random_rotation(rng)
        g = sample_field(field, m, c0, 96)
        r3 = math.sqrt(R * R - c0 * c0)
        count = int(np.sum(g.values <= R * R))
        assert count * g.spacing**3 == pytest.approx(4 / 3 * math.pi * r3**3, rel=0.02)


def test_coarse_and_the_field_method_agree_with_sample_field():
    field = linear_array_field()
    m = random_rotation(np.random.default_rng(13))
    a = field.sample(m, 4.0)
    b = sample_field(field, m, 4.0, field.resolution)
    np.testing.assert_array_equal(a.values, b.values)
    c = field.sample(m, 4.0, coarse=True)
    assert max(c.values.shape) == field.coarse_resolution + 2
    np.testing.assert_array_equal(c.values, sample_field(field, m, 4.0, field.coarse_resolution, coarse=True).values)


def test_a_cut_that_misses_the_box_is_empty():
    field = linear_array_field()
    g = sample_field(field, np.eye(4), 9.0, 16)
    assert g.empty and g.values.shape == (0, 0, 0)


def test_bad_input_is_named():
    field = linear_array_field()
    with pytest.raises(TypeError, match="Field4D"):
        sample_field(np.zeros((3, 3, 3, 3)), np.eye(4), 0.0)
    with pytest.raises(ValueError, match="resolution"):
        sample_field(field, np.eye(4), 4.0, 1)
    with pytest.raises(ValueError, match="matrix"):
        sample_field(field, np.ones((4, 4)), 4.0)
