"""Lazy data that fit the memory budget are read whole, once, in the background (issue 35).

`Field4D.prepare` (a live widget calls it) reads a chunked or lazy array in one pass: the coarse
copy, and -- when the array fits ``memory_budget`` -- the whole array, after which steps run on
it in memory (`Field4D.resident`) and read nothing.  Bigger data keep the coarse copy only.  The
pass is counted by a `Progress`: the kernel's bar goes to the caller's cell (made there, hidden
until due) and a widget shows it on its own bar, above its readout, while it runs.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from rot4d_widget.core import progress as core_progress
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.field.coarse import MEMORY_BUDGET
from rot4d_widget.sources.field.container import Field4D, slice_field

NW, NS, CW, CS = 17, 16, 4, 8  # w samples, spatial samples, chunk sizes: 5 x 2 x 2 x 2 = 40 chunks
CHUNKS = 40
BLOCKS = 2  # the coarse copy is made from the array in memory in blocks of 16 a side: 2 x 1 x 1 x 1


class Counted:
    """A chunked 4-D array (f[w, z, y, x]) counting its reads; ``gate``, when set, holds reads
    made on threads other than the one that made the array (the background read) until it opens."""

    def __init__(self, a, chunks=(CW, CS, CS, CS)):
        self.a, self.chunks = a, chunks
        self.shape, self.ndim, self.dtype = a.shape, a.ndim, a.dtype
        self.reads = 0
        self.gate = None
        self.pause = 0.0  # seconds each read on another thread takes (a slow disk)
        self._main = threading.get_ident()

    def __getitem__(self, key):
        if threading.get_ident() != self._main:
            if self.gate is not None:
                self.gate.wait(20)
            time.sleep(self.pause)
        out = self.a[key]
        self.reads += out.size > 0
        return out


def _values(dtype=np.float64):
    w = np.linspace(-1.0, 1.0, NW)[:, None, None, None]
    g = np.linspace(-1.0, 1.0, NS)
    r2 = g[None, :, None, None] ** 2 + g[None, None, :, None] ** 2 + g[None, None, None, :] ** 2
    return (1.0 - r2 - 0.5 * w * w).astype(dtype)


def _field(**kwargs):
    arr = Counted(_values())
    return arr, Field4D(arr, axes="wzyx", extent=[(-1.0, 1.0)] * 4, **kwargs)


def test_data_within_the_budget_are_read_once_and_then_stepped_in_memory():
    arr, field = _field()
    assert field.fits_in_memory and field.resident is None and field.memory_budget == MEMORY_BUDGET
    m = random_rotation(np.random.default_rng(3))
    first = field.slice(m, 0.05)  # the first picture: the cut's chunks only
    assert 0 < arr.reads < CHUNKS
    arr.reads = 0
    counter = field.prepare(progress=False)
    assert counter is not None and counter.total == CHUNKS + BLOCKS
    field.coarse()  # waits for the read
    assert arr.reads == CHUNKS  # every chunk once: the whole array, then the coarse copy from it in memory
    assert counter.closed and counter.count == CHUNKS + BLOCKS
    whole = field.resident
    assert isinstance(whole, np.ndarray) and not whole.flags.writeable
    np.testing.assert_array_equal(whole, _values())
    assert field.data_range_source == "data" and field.data_range == (_values().min(), _values().max())
    arr.reads = 0
    again = field.slice(m, 0.05)
    for k in range(3):
        field.slice(random_rotation(np.random.default_rng(k)), 0.1)
        slice_field(field, random_rotation(np.random.default_rng(k)), 0.1, 0.3)
    assert arr.reads == 0  # steps run in memory now
    ref = Field4D(_values(), axes="wzyx", extent=[(-1.0, 1.0)] * 4, levels=field.levels)
    ref._stat.set_statistics(field._statistics())  # the same caps' scale: the same numbers
    np.testing.assert_allclose(again.points, ref.slice(m, 0.05).points, atol=1e-12, rtol=0)
    assert len(again.triangles) == len(first.triangles) > 100
    assert field.prepare(progress=False) is None  # nothing left to read


def test_data_over_the_budget_keep_the_coarse_copy_and_read_chunks():
    arr, field = _field(memory_budget=_values().nbytes - 1)
    assert not field.fits_in_memory
    counter = field.prepare(progress=False)
    assert counter.total == CHUNKS and "coarse copy" in counter.description
    field.coarse()
    assert field.resident is None and field.coarse_ready and field.data_range_source == "coarse copy"
    arr.reads = 0
    field.slice(random_rotation(np.random.default_rng(1)), 0.05)
    assert 0 < arr.reads < CHUNKS  # a full step reads the chunks its samples touch


def test_what_fits_is_counted_in_the_type_the_step_uses():
    a32 = Counted(_values(np.float32))
    f32 = Field4D(a32, axes="wzyx", memory_budget=a32.a.nbytes)
    assert f32.fits_in_memory
    f32.memory_budget = a32.a.nbytes - 1
    assert not f32.fits_in_memory
    ints = Counted(np.zeros((NW, NS, NS, NS), dtype=np.int16))  # integers are stepped as float64
    assert not Field4D(ints, axes="wzyx", memory_budget=ints.a.size * 8 - 1).fits_in_memory
    assert Field4D(ints, axes="wzyx", memory_budget=ints.a.size * 8).fits_in_memory
    with pytest.raises(ValueError, match="memory_budget"):
        Field4D(a32, axes="wzyx", memory_budget=-1)
    with pytest.raises(TypeError, match="memory_budget"):
        Field4D(a32, axes="wzyx", memory_budget="1 GB")
    assert Field4D(_values(), axes="wzyx").fits_in_memory  # in memory already
    assert Field4D.from_function(lambda x, y, z, w: x, [(-1, 1)] * 4).prepare() is None
    small = Field4D(_values(), axes="wzyx")  # in memory and no bigger than a coarse copy: its own
    assert small.prepare() is None and small.coarse() is small


def test_an_array_in_memory_gets_its_coarse_copy_in_the_background_with_the_same_numbers():
    a = np.random.default_rng(0).normal(size=(60, 20, 22, 50))
    field = Field4D(a, axes="xyzw")
    counter = field.prepare(progress=False)
    assert counter is not None and counter.total == 4 * 2 * 2 * 4  # blocks of 16 a side
    c = field.coarse()
    lazy = Field4D(Counted(a, (7, 20, 11, 50)), axes="xyzw", memory_budget=0).coarse()
    np.testing.assert_allclose(c.values, lazy.values, rtol=1e-12, atol=1e-14)
    assert field.resident is a or np.shares_memory(field.resident, a)


def test_the_kernel_bar_is_made_in_the_caller_s_cell_and_shown_from_the_read(monkeypatch):
    made = []

    class Bar:
        def __init__(self, total, description):
            made.append(("new", threading.get_ident(), total, description))

        def show(self, count, text):
            made.append(("show", count))

        def close(self, done):
            made.append(("close", done))

    monkeypatch.setattr(core_progress, "in_kernel", lambda: True)
    monkeypatch.setattr(core_progress, "_widget_bar", Bar)
    arr, field = _field()
    arr.gate = threading.Event()
    field.prepare()  # progress=True: the kernel's bar
    try:
        assert made and made[0][:3] == ("new", threading.get_ident(), CHUNKS + BLOCKS)  # here, before it returns
        assert "reading" in made[0][3] and "into memory" in made[0][3]
    finally:
        arr.gate.set()
    field.coarse()
    assert made[-1] == ("close", True)


def test_a_widget_shows_the_read_on_its_own_bar_while_it_runs(make, monkeypatch):
    from rot4d_widget.sources.field import coarse

    monkeypatch.setattr(coarse, "CHUNK_BATCH", 4)  # the read counts every 4 chunks
    arr, field = _field()
    w = make(field)
    assert not w.progress_bar.visible and w.progress_bar.box in w._side_box.children
    arr.pause = 0.1  # 40 chunks: 4 s
    w.progress_bar.follow(field)  # what a live widget does when it is made
    t0 = time.monotonic()
    seen = None
    while time.monotonic() - t0 < 20 and not field.coarse_ready:
        if w.progress_bar.visible:  # shown after a second
            seen = (w.progress_bar.label.value, w.progress_bar.bar.value, w.progress_bar.bar.max)
            break
        time.sleep(0.02)
    assert seen is not None, "the bar never showed during the read"
    assert seen[0].startswith("reading") and "into memory" in seen[0] and 0 < seen[1] < seen[2] == CHUNKS + BLOCKS
    field.coarse()
    t0 = time.monotonic()
    while w.progress_bar.visible and time.monotonic() - t0 < 10:
        time.sleep(0.02)
    assert not w.progress_bar.visible and field.resident is not None
    assert w.progress_bar.follow(field) is None  # nothing left to read: no bar
