"""One update is bounded (issue 33, item 3): a source that returns millions of points gets a clear
error, at construction or under the readout, and no message over the cap ever leaves the kernel.

Before the cap, a user source of 3,000,000 points went to the page as one ~240 MB message (1.1 s
in the kernel per key; a frozen tab), and 30 M points took tens of seconds at construction (six
slices to size the buffer).
"""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget import SliceData
from rot4d_widget.view.buffers import MAX_UPDATE_BYTES, ROW_BYTES, UpdateTooLarge, check_update_size
from test_widget import down, up

pytestmark = pytest.mark.usefixtures("recording_comms")

OVER = MAX_UPDATE_BYTES // ROW_BYTES + 1  # one row more than the cap allows


class Cloud:
    """A user's source: ``n`` points; ``big`` points instead while c0 > 0.01."""

    size = 1.0
    n_groups = 1

    def __init__(self, n=30, big=OVER):
        rng = np.random.default_rng(0)
        self.small = rng.random((n, 3)) - 0.5
        self.large = rng.random((big, 3)) - 0.5

    def slice(self, matrix, c0):
        p = self.large if c0 > 0.01 else self.small
        return SliceData(p, np.zeros((0, 2), int), np.zeros((0, 3), int), np.zeros(0, int))

    def describe(self):
        return {"kind": "cloud"}


def test_the_cap_allows_the_largest_legitimate_update_many_times():
    assert MAX_UPDATE_BYTES >= 8 * 1.6e6  # 1.6 MB: benchmarks/update_size.py's largest (docs/performance.md)


def test_a_slice_one_row_over_the_cap_is_refused_and_one_row_under_is_not():
    p = np.zeros((OVER, 3))
    data = SliceData(p, np.zeros((0, 2), int), np.zeros((0, 3), int), np.zeros(0, int))
    with pytest.raises(UpdateTooLarge, match=r"at most 32 MiB"):
        check_update_size(data, name="Cloud")
    check_update_size(SliceData(p[:-1], np.zeros((0, 2), int), np.zeros((0, 3), int), np.zeros(0, int)))


def test_a_source_over_the_cap_is_refused_at_construction_naming_it(make):
    with pytest.raises(UpdateTooLarge, match=r"Cloud's slice \(419,431 points.*at most 32 MiB"):
        make(Cloud(n=OVER))


def test_a_slice_over_the_cap_is_an_error_under_the_readout_and_never_sent(make, recording_comms):
    w = make(Cloud())
    w.state.c0_step = 0.05
    n0 = len(recording_comms)
    down(w, "l", t=1.0)  # c0 = 0.05: the cloud's large slice
    up(w, "l", t=1.05)
    errors = "".join(o.get("text", "") for o in w.errors.outputs)
    assert "UpdateTooLarge" in errors and "at most 32 MiB" in errors
    assert max(n for _, _, n, _ in recording_comms[n0:]) < 2**20  # the readout, not the rows
    shown = w.scene.counts
    down(w, "h", t=2.0)  # back to a small slice: drawn, the error gone
    up(w, "h", t=2.05)
    assert w.errors.outputs == ()
    assert w.scene.counts[0] == 30 and shown[0] == 30
