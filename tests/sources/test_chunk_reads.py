"""A full-resolution slice of big chunked data reads only the chunks its samples touch (issue 35).

A 64^4 float32 dask array in 8^4 chunks (4096 of them) is read through a wrapper that counts every
chunk dask fetches from it (not the package's own count).  A hyperplane in a random orientation
meets about a fifth to a third of the chunks; each of `Field4D.slice`, `slice_field` (the
documented way without a browser) and `sample_field` / `Field4D.sample` (the grid the volume
renderings draw) must read no chunk the hyperplane does not come within one node of (a sample's
cell may reach one node into the next chunk: its interpolation neighbours), and must not build the
coarse copy (which reads all 4096).  The oracle is geometric, not the reader's own list: a chunk
can be read only if the hyperplane meets its box grown by one node spacing.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.field.container import Field4D, slice_field
from rot4d_widget.sources.field.grid import sample_field

da = pytest.importorskip("dask.array")

N, C = 64, 8  # samples per axis, chunk edge: (N / C)^4 = 4096 chunks


class Counted:
    """A 4-D array that counts the chunks read from it (dask's empty probe for the dtype is no read)."""

    def __init__(self, a):
        self.a = a
        self.shape, self.ndim, self.dtype = a.shape, a.ndim, a.dtype
        self.reads = 0

    def __getitem__(self, key):
        out = self.a[key]
        self.reads += out.size > 0
        return out


def _values():
    g = np.linspace(-1.0, 1.0, N, dtype=np.float32)
    x, y, z, w = np.meshgrid(g, g, g, g, indexing="ij", sparse=True)
    return (x * x + y * y + z * z + 0.5 * w * w).astype(np.float32)


@pytest.fixture(scope="module")
def values():
    return _values()


def _field(values):
    arr = Counted(values)
    field = Field4D(da.from_array(arr, chunks=(C,) * 4, asarray=False), axes="xyzw", extent=[(-1.0, 1.0)] * 4)
    return arr, field


def _chunks_met(m, d) -> int:
    """Chunks whose box, grown by one node spacing, the hyperplane {q : (m q)_w = d} meets (slice
    coordinates = data coordinates here: extent -1 .. 1 on every axis, w_per_unit 1)."""
    h = 2.0 / (N - 1)
    starts = np.arange(0, N, C)
    lo = -1.0 + starts * h - h
    hi = -1.0 + (starts + C - 1) * h + h
    row = np.asarray(m)[3]
    n = 0
    for idx in itertools.product(range(N // C), repeat=4):
        a = np.array([lo[i] for i in idx]) * row
        b = np.array([hi[i] for i in idx]) * row
        if np.minimum(a, b).sum() <= d <= np.maximum(a, b).sum():
            n += 1
    return n


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("how", ["Field4D.slice", "slice_field", "sample_field", "Field4D.sample"])
def test_a_full_resolution_slice_reads_only_the_chunks_the_hyperplane_meets(values, how, seed):
    m = random_rotation(np.random.default_rng(seed))
    d = 0.05
    arr, field = _field(values)
    if how == "Field4D.slice":
        out = field.slice(m, d)
        assert len(out.triangles) > 100
    elif how == "slice_field":
        assert len(slice_field(field, m, d, 0.6).triangles) > 100
    elif how == "sample_field":
        assert np.isfinite(sample_field(field, m, d, 64).values).any()
    else:
        assert np.isfinite(field.sample(m, d).values).any()
    met = _chunks_met(m, d)
    total = (N // C) ** 4
    assert met < total / 2  # the oracle: a hyperplane meets a minority of the chunks
    assert not field.coarse_ready, f"{how} built the coarse copy (every one of the {total} chunks)"
    assert 0 < arr.reads <= met, f"{how} read {arr.reads} chunks; the hyperplane meets {met} of {total}"
