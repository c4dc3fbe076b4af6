"""Big stores: a fresh chunked field's first picture reads only the chunks its hyperplane touches
(the range and default level from them, "first cut"); the coarse copy is built in the background
(`prepare`), chunk by chunk, and held keys meanwhile slice at full resolution."""

import threading

import numpy as np
import pytest

from rot4d_widget.sources.field.container import Field4D

NW, NS, CW, CS = 17, 16, 4, 8  # w samples, spatial samples, chunk sizes


class Counted:
    """A chunked 4-D array (f[w, z, y, x]) counting its reads; ``gate`` can hold reads back."""

    def __init__(self, a, chunks):
        self.a, self.chunks = a, chunks
        self.shape, self.ndim, self.dtype = a.shape, a.ndim, a.dtype
        self.reads = 0
        self.gate = None

    def __getitem__(self, key):
        if self.gate is not None:
            self.gate.wait(10)
        out = self.a[key]
        self.reads += out.size > 0  # dask's empty probe for the dtype is no read
        return out


def _values():
    w = np.linspace(-1.0, 1.0, NW)[:, None, None, None]
    g = np.linspace(-1.0, 1.0, NS)
    r2 = g[None, :, None, None] ** 2 + g[None, None, :, None] ** 2 + g[None, None, None, :] ** 2
    return (1.0 - r2 - 0.5 * w * w).astype(np.float64)


def _field(memory_budget=0):
    """A store bigger than its memory budget (0: never read whole), unless one is given."""
    arr = Counted(_values(), (CW, CS, CS, CS))
    return arr, Field4D(arr, axes="wzyx", extent=[(-1.0, 1.0)] * 4, memory_budget=memory_budget)


def _touched_at_rest():
    """Chunks whose w index range holds the cut at rest (index (NW-1)/2, and its cell's upper
    node), times every spatial chunk: computed from the chunk grid, not by the reader."""
    wi = (NW - 1) / 2
    i0 = min(int(np.floor(wi)), NW - 2)
    wchunks = {i0 // CW, (i0 + 1) // CW}
    return len(wchunks) * (NS // CS) ** 3


def test_the_first_picture_reads_only_the_chunks_its_cut_touches():
    arr, field = _field()
    total = -(-NW // CW) * (NS // CS) ** 3
    data = field.slice(np.eye(4), 0.0)
    assert arr.reads <= _touched_at_rest() < total
    assert not field.coarse_ready
    assert field.data_range_source == "first cut"
    a = _values()
    touched = a[8:12]  # the one w chunk that holds index 8 and 9
    assert field.data_range == pytest.approx((touched.min(), touched.max()))
    assert field.levels == pytest.approx(((touched.min() + touched.max()) / 2,))
    assert dict(data.readout)["level"].endswith("(first cut)")
    assert len(data.triangles) > 100


def test_levels_before_any_slice_read_only_the_cut_at_rest():
    arr, field = _field()
    field.levels  # what the widget asks first
    assert arr.reads <= _touched_at_rest() and not field.coarse_ready


def test_the_background_build_returns_at_once_and_held_keys_slice_at_full_resolution():
    arr, field = _field()
    field.slice(np.eye(4), 0.0)
    gate = threading.Event()
    arr.gate = gate  # the build waits here until released
    field.prepare(progress=False)
    assert not field.coarse_ready
    held = field.slice(np.eye(4), 0.1, coarse=True)  # reads through the gate too: release it first
    gate.set()
    rows = dict(held.readout)
    assert "coarse copy is being built" in rows["resolution"] or field.coarse_ready
    c = field.coarse()  # waits for the build
    assert field.coarse_ready and c is field.coarse()
    ref = Field4D(_values(), axes="wzyx", extent=[(-1.0, 1.0)] * 4).coarse()
    np.testing.assert_allclose(np.asarray(c.values), np.asarray(ref.values), rtol=1e-12, atol=1e-12)
    assert field.data_range_source == "coarse copy"
    assert field.coarse_progress == (field.coarse_progress[1], -(-NW // CW) * (NS // CS) ** 3)
    assert dict(field.slice(np.eye(4), 0.1, coarse=True).readout)["resolution"].endswith("(coarse copy)")


def test_held_keys_during_the_build_do_not_wait_for_it():
    arr, field = _field()
    field.slice(np.eye(4), 0.0)
    gate = threading.Event()
    orig = arr.__class__.__getitem__
    main = threading.get_ident()

    class Slow(Counted):
        def __getitem__(self, key):
            if threading.get_ident() != main:
                gate.wait(10)  # only the build is held back
            return orig(self, key)

    arr.__class__ = Slow
    try:
        field.prepare(progress=False)
        held = field.slice(np.eye(4), 0.05, coarse=True)
        assert not field.coarse_ready
        assert "coarse copy is being built" in dict(held.readout)["resolution"]
    finally:
        gate.set()
    field.coarse()
    assert field.coarse_ready


def test_a_dask_field_s_first_picture_reads_the_touched_chunks_only():
    da = pytest.importorskip("dask.array")
    arr = Counted(_values(), None)
    field = Field4D(da.from_array(arr, chunks=(CW, CS, CS, CS), asarray=False), axes="wzyx",
                    extent=[(-1.0, 1.0)] * 4)
    field.slice(np.eye(4), 0.0)
    assert arr.reads <= _touched_at_rest() and not field.coarse_ready


@pytest.mark.parametrize("how", ["zarr-like", "dask", "fits the budget"])
def test_a_widget_s_first_picture_reads_only_the_chunks_of_its_cut(make, how):
    """Building the view reads the chunks of its first cut and no others (issue 35: a 2 GB store
    took 10-16 s to its first picture): its buffers and ball radius come from the cut of the box
    (the source's outline), and the first cut that sets the default level is the first picture's,
    read once.  The level colours take the range known so far (a field that fits its budget, with
    its own levels, had the whole store read for them before the first picture: 12 s on a slow
    disk, and the page's progress bar never showed)."""
    if how == "dask":
        da = pytest.importorskip("dask.array")
        arr = Counted(_values(), None)
        field = Field4D(da.from_array(arr, chunks=(CW, CS, CS, CS), asarray=False), axes="wzyx",
                        extent=[(-1.0, 1.0)] * 4)
    elif how == "fits the budget":  # read whole in the background later, not for the first picture
        arr = Counted(_values(), (CW, CS, CS, CS))
        field = Field4D(arr, axes="wzyx", extent=[(-1.0, 1.0)] * 4, levels=[0.3])
    else:
        arr, field = _field()
    w = make(field)
    assert arr.reads <= _touched_at_rest(), f"building the view read {arr.reads} chunks"
    assert not field.coarse_ready and field.data_range_source == "first cut"
    assert len(w.slice.triangles) > 100
    before = arr.reads
    w.press("l")  # a step at rest reads only the new cut's chunks: here, the same ones (cached)
    assert arr.reads - before <= _touched_at_rest()
