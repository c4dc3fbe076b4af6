"""c0 in the data's own w units (issue 19): a field's c0 is its time.

The field: a ball whose radius grows with time, R(t) = 0.3 + 0.05 (t - 20) m, in a box x, y, z in
[-1, 1] m, t in [20, 30] s (not centred at 0), ``w_per_unit`` = 5 s per m.  At rest the cut w = c0
is the snapshot at t = c0, a sphere of radius R(c0): a closed form the slices are checked against.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rot4d_widget import Field4D, RotationState
from rot4d_widget.sources.field.container import slice_field
from rot4d_widget.keep.recorder import Recording, Setting, Step
from rot4d_widget.sources.protocol import data_w_text, w_frame
from rot4d_widget.sources.tomography import StackSource

EXTENT = ((-1.0, 1.0),) * 3 + ((20.0, 30.0),)
WPU = 5.0


def radius(t):
    return 0.3 + 0.05 * (np.asarray(t, dtype=float) - 20.0)


def growing(x, y, z, t):
    return radius(t) ** 2 - (x * x + y * y + z * z)


def _field(**kw):
    kw.setdefault("resolution", 32)
    return Field4D.from_function(growing, EXTENT, w_per_unit=WPU, w_units="s", space_units="m",
                                 levels=[0.0], **kw)


def _radii(data):
    return np.linalg.norm(data.levels[0].vertices, axis=1)


def test_at_rest_c0_is_the_data_s_time():
    f = _field()
    assert f.w_frame == (25.0, WPU) and w_frame(f) == (25.0, WPU)
    assert f.w_range(np.eye(4)) == (20.0, 30.0)  # the gauge's ends: the data's first and last time
    for t in (21.0, 25.0, 28.5):
        r = _radii(f.slice(np.eye(4), t))
        assert np.abs(r - radius(t)).max() < 0.02, t  # the sphere of that time
        s = slice_field(f, np.eye(4), t, 0.0)
        assert abs(s.volume / (4 / 3 * math.pi * radius(t) ** 3) - 1) < 0.03
    assert f.slice(np.eye(4), 31.0).levels[0].empty  # after the data's last time: nothing
    assert dict(f.slice(np.eye(4), 31.0).readout)["w cut"].startswith("none")


def test_a_turned_cut_puts_each_vertex_on_the_sphere_of_its_own_time():
    from rot4d_widget.core.rotation import simple_rotation

    f = _field()
    m = simple_rotation("xw", 0.3)
    data = f.slice(m, 26.0)
    p = data.levels[0].vertices
    q = f.to_data(p, m, 26.0)  # x, y, z in m and t in s of each vertex
    inside = (q[:, 3] > 20.2) & (q[:, 3] < 29.8)  # off the caps at the data's first and last time
    assert inside.mean() > 0.8
    np.testing.assert_allclose(np.linalg.norm(q[inside, :3], axis=1), radius(q[inside, 3]), atol=0.02)
    # the cut passes through the box's centre line at the time c0: q_w = c0 where x = 0
    d = f.offset(26.0)
    assert d == (26.0 - 25.0) / WPU
    np.testing.assert_allclose(f.to_data([[0.0, 0.0, 0.0]], m, 26.0)[0], m.T @ [0, 0, 0, d] * [1, 1, 1, WPU]
                               + [0, 0, 0, 25.0], atol=1e-12)


def test_the_widget_s_c0_trait_keys_and_gauge_are_in_seconds(make):
    f = _field()
    w = make(f)
    assert w.c0 == w.state.c0 == 25.0  # starts at the middle of the data's time
    size = f.size
    assert w.state.c0_step == pytest.approx(size * WPU / 64)  # 1/64 of the size, in seconds
    w.c0 = 22.0
    assert w.state.c0 == 22.0  # exactly what was set
    assert np.abs(_radii(w.slice) - radius(22.0)).max() < 0.02
    assert "22.0000 s" in w.readout.value
    w.press("l")
    assert w.c0 == pytest.approx(22.0 + size * WPU / 64)
    # l / h stay within twice the size about the centre, in seconds; refused, not clamped, beyond
    w.c0 = 25.0 + 2 * size * WPU - 0.5 * w.state.c0_step
    assert w.state.press("l") is False and w.state.press("h") is True
    assert w.state.c0_origin == 25.0 and w.state.c0_limit == pytest.approx(2 * size * WPU)
    w2 = make(f, c0=27.0, c0_step=1.0)
    w2.press("h")
    assert w2.c0 == 26.0  # one second
    far = make(f, c0=400.0)
    assert "above the object" in far.readout.value


def test_a_polytope_s_c0_is_unchanged(make):
    w = make("24-cell")
    assert w.c0 == 0.0 and w_frame(w.source) == (0.0, 1.0)
    w.press("l")
    assert w.c0 == pytest.approx(w.source.size / 64)
    assert f"{w.c0:.4f}<span class='rot4d-gauge'" in w.readout.value  # no unit after a polytope's w


def test_stack_cuts_and_labels_are_in_the_data_s_time():
    src = StackSource(_field(), slices=3, spacing=1.0)  # in the data's w units, as c0 (issue 37)
    assert w_frame(src) == (25.0, WPU)
    cuts = src.cuts_at(26.0)
    np.testing.assert_allclose(cuts, [25.0, 26.0, 27.0])  # 1 s apart
    data = src.slice(np.eye(4), 26.0)
    for k, t in enumerate(cuts):
        assert np.abs(_radii(data.slices[k]) - radius(t)).max() < 0.02
    labels = [row[0] for row in data.readout][1:4]
    assert labels == ["w 25 s", "\u25b8 w 26 s", "w 27 s"]
    assert data_w_text(src, 26.0) == "w 26 s"


def _old_state_file(tmp_path, source_desc, c0_slice, c0_step_slice):
    """A state file as a version before this change wrote it: state format 1, c0 in slice units."""
    st = RotationState(c0=c0_slice, c0_step=c0_step_slice)
    d = st.to_dict()
    d["format"] = 1
    doc = {"format": "rot4d_widget state", "version": 1, "state": d, "source": source_desc,
           "settings": {"levels": [0.0]}}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    return path


def test_a_state_file_from_before_loads_with_c0_converted(tmp_path, make):
    from rot4d_widget.keep.rebuild import describe_source
    from rot4d_widget.keep.statefile import load_state

    f = _field()
    desc = describe_source(f)
    path = _old_state_file(tmp_path, desc, 0.2, 0.05)
    loaded = load_state(path, source=f)
    assert loaded.state.c0 == 25.0 + WPU * 0.2 and loaded.state.c0_step == WPU * 0.05
    w = make(f)
    w.load_state(path)
    assert w.c0 == 26.0  # the cut the old file showed: 0.2 slice units past the centre = 26 s
    assert np.abs(_radii(w.slice) - radius(26.0)).max() < 0.02
    # a polytope's file: nothing to convert
    p = _old_state_file(tmp_path, {"kind": "polytope", "name": "5-cell"}, 0.2, 0.05)
    assert load_state(p).state.c0 == 0.2


def test_a_recording_from_before_replays_with_c0_converted(make):
    st = RotationState(c0=0.2, c0_step=0.05)
    initial = st.to_dict(initial=True)
    initial["format"] = 1
    initial["initial"]["c0"] = 0.2
    from rot4d_widget.core.keymap import Action

    rec = Recording(initial, [Setting(0.5, "c0", -0.4), Step(1.0, "l", False, Action.parse("c0+"), False)])
    f = _field()
    w = make(f)
    w.replay(rec)
    assert w.c0 == pytest.approx(25.0 + WPU * (-0.4 + 0.05))  # 23.25 s
    assert w.state.c0_step == WPU * 0.05
    new = rec.for_source(f)
    assert new.initial["format"] == 3 and new.initial["c0"] == 26.0 and new.initial["initial"]["c0"] == 26.0
    assert rec.for_source(make("5-cell").source) is rec  # a polytope's frame (0, 1): nothing to convert


def test_a_rendered_picture_names_c0_and_the_slices_in_seconds():
    from rot4d_widget.keep.pictures.state_picture import render_state

    st = RotationState(c0=26.0)
    fig = render_state(st, _field(resolution=16), annotate=True, size=(300, 250), dpi=50)
    text = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "c0 = +26 s" in text
    fig = render_state(st, _field(resolution=16), slices=3, spacing=1.0, annotate=True, size=(300, 250), dpi=50)
    text = " ".join(t.get_text() for t in fig.axes[0].texts)
    assert "3 slices w = +25 \u2026 +27 s, \u0394 = 1 s" in text
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["w = +25 s", "w = +26 s", "w = +27 s"]
