"""Parallel slices spread over the record, their spacing in the data's w units, every slice labelled
with its time (issue 37, problem 3).

A flame-like field recorded over 1-4 ms: five slices of the default spacing sit at 1.3, 1.9, 2.5,
3.1 and 3.7 ms (one fifth of the record each, about its middle), none outside it; the spacing is
set and shown in seconds like c0.  The default is spread again along the current w when N changes
(n) -- the record's extent along x after 90 degrees in x-w -- never by a turn alone and never over
a spacing the user set.  A state file and a recording written before (state format 2: the spacing
in drawn units) load with the spacing converted by the source's w per unit of space.  Every slice
carries its time in the page's labels and the static picture, and a slice outside the data says so.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_labels import flame, turned

from rot4d_widget.keep.statefile import load_state

pytestmark = pytest.mark.usefixtures("recording_comms")

MS = 1e-3


def test_five_slices_spread_over_the_record_and_the_spacing_is_in_seconds(make):
    w = make(flame(), slices=5, arrangement="grid")
    np.testing.assert_allclose(w.source.cuts_at(w.c0), np.array([1.3, 1.9, 2.5, 3.1, 3.7]) * MS, rtol=1e-12)
    assert w.spacing == pytest.approx(0.6 * MS)
    w.spacing = 0.5 * MS  # set in seconds, like c0
    np.testing.assert_allclose(np.diff(w.source.cuts_at(w.c0)), 0.5 * MS, rtol=1e-9)
    assert "\u0394 = 0.0005 s" in w.readout.value


def test_the_default_follows_n_never_a_turn_and_never_a_set_spacing(make):
    f = flame()
    w = make(f, slices=5)
    before = w.spacing
    w.state.matrix = turned().matrix  # 90 degrees in x-w: the current w is the data's x
    w.refresh()
    assert w.spacing == before  # a turn alone never moves the slices apart
    w.press("n")  # N changes: spread again along the current w, the record's extent along x in seconds
    lo, hi = f.w_range(w.state.matrix)
    assert w.slices == 6 and w.spacing == pytest.approx((hi - lo) / 6)
    cuts = w.source.cuts_at(w.c0)
    assert lo < cuts.min() and cuts.max() < hi
    w.spacing = 0.4 * MS
    w.press("n")
    assert w.slices == 7 and w.spacing == pytest.approx(0.4 * MS)  # the user's spacing stays
    w.spacing = None  # back to the default: spread now
    assert w.spacing == pytest.approx((hi - lo) / 7)


def test_the_default_is_spread_when_n_changes_not_when_first_read():
    """The soak's replay (seed 20240) ended on another spacing than the live view: ``b`` made N = 1
    at one orientation, and the default was spread only when next read -- at once by the live view's
    readout, but in the replay by the next ``g``, after turns.  Spread when N changes, both agree."""
    from rot4d_widget.sources.tomography import StackSource

    f = flame()
    stack = StackSource(f, slices=2)
    stack.note_matrix(turned().matrix)  # told before the action that changes N, as the widget does
    stack.slices = 1
    spread = (lambda lo, hi: hi - lo)(*f.w_range(turned().matrix))
    stack.note_matrix(np.eye(4))  # turns after it, before anything reads the spacing
    assert stack.spacing == pytest.approx(spread)


def test_every_slice_carries_its_time_and_one_outside_the_data_says_so(make):
    w = make(flame(), slices=5, arrangement="grid")
    labels = w.scene.buffer.labels
    assert [lab["kind"] for lab in labels] == ["slice"] * 5
    assert [lab["text"] for lab in labels] == ["w 0.0013 s", "w 0.0019 s", "w 0.0025 s", "w 0.0031 s", "w 0.0037 s"]
    w.c0 = 0.9 * MS  # the lowest slices now lie before the record
    texts = [lab["text"] for lab in w.scene.buffer.labels]
    assert texts[0] == "w -0.0003 s (outside the data)" and texts[2] == "w 0.0009 s (outside the data)", texts
    assert texts[3] == "w 0.0015 s", texts
    assert "w -0.0003 s (outside the data)" in w.readout.value
    fig = w.render(size=(600, 500), dpi=100)
    drawn = sorted(t.get_text() for t in fig.axes[0].texts if t.get_gid() == "label")
    assert drawn == sorted(texts), drawn  # the static picture labels every slice the same way


def _written_before(tmp_path, w):
    """``w``'s state file as a version before the spacing followed the data's w units wrote it:
    state format 2, the spacing (its settings' and its stack's) in drawn units."""
    path = tmp_path / "view.json"
    with pytest.warns(Warning):  # an in-memory array: described, not rebuildable
        w.save_state(path)
    doc = json.loads(path.read_text())
    drawn = w.spacing / w.source.w_frame[1]
    doc["state"]["format"] = 2
    doc["settings"]["spacing"] = drawn
    doc["source"]["spacing"] = drawn
    path.write_text(json.dumps(doc))
    return path


def test_a_state_file_from_before_loads_with_the_spacing_converted(make, tmp_path):
    f = flame()
    w = make(f, slices=3, spacing=0.8 * MS)
    path = _written_before(tmp_path, w)
    loaded = load_state(path, source=w.source)
    assert loaded.settings["spacing"] == pytest.approx(0.8 * MS)
    again = make(flame(), slices=3)
    again.load_state(path)
    assert again.spacing == pytest.approx(0.8 * MS)
    np.testing.assert_allclose(again.source.cuts_at(again.c0), w.source.cuts_at(w.c0))


def test_a_recording_from_before_replays_with_the_spacing_converted(make):
    from rot4d_widget.keep.recorder import Recording, SourceSetting

    f = flame()
    w = make(f, slices=3)
    w.spacing = 0.8 * MS
    d = w.recording.to_dict()
    d["initial"]["format"] = 2
    per = w.source.w_frame[1]
    for e in d["events"]:
        if e.get("source") == "spacing":
            e["value"] = e["value"] / per  # drawn units, as then
    rec = Recording.from_dict(d)
    assert any(isinstance(e, SourceSetting) for e in rec.events)
    again = make(flame(), slices=3)
    again.replay(rec)
    assert again.spacing == pytest.approx(0.8 * MS)
