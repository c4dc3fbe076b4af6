"""Issue 12: recorded key sequences (rot4d_widget.recording): record, save, replay, animate."""

import json

import numpy as np
import pytest

from rot4d_widget import DEFAULT_KEYMAP, RotationState
from rot4d_widget.recording import (
    Recorder,
    Recording,
    Setting,
    Step,
    animation_states,
    paper_animation,
    paper_recording,
    render_animation,
)
from rot4d_widget.rotation import random_rotation


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def _drive(state, recorder, keys, clock, dt=1 / 30):
    """What the widget does: apply each key's action, then tell the recorder."""
    for key in keys:
        shift = key.isupper()
        found = state.keymap.resolve(key)
        action, inverted = found
        clock.now += dt
        if state.apply(action, inverted):
            recorder.record(key.lower(), shift, action, inverted)


KEYS = "4" * 20 + "zzZ8kkkllh+" + "w" * 15 + "r" + "y" * 9 + "-c3j"


def _live():
    clock = Clock()
    st = RotationState(0.07, c0=0.1, matrix=random_rotation(9))
    for k in "48l":  # before recording: the reset point stays the constructed state
        st.press(k)
    rec = Recorder(st, clock=clock)
    return st, rec, clock


def test_replay_gives_the_recorded_final_state_bit_for_bit(tmp_path):
    st, rec, clock = _live()
    start = st.to_dict()
    _drive(st, rec, KEYS[:30], clock)
    clock.now += 0.5
    st.c0 = 0.33  # a slider, outside the keys
    rec.record_set("c0", 0.33)
    st.matrix = random_rotation(1)
    rec.record_set("matrix", st.matrix)
    _drive(st, rec, KEYS[30:], clock)
    r = rec.recording()
    assert len(r) == len(KEYS) + 2 and r.dropped == 0
    assert r.initial["orientation"] == start["orientation"]
    assert [e.label for e in r.events[:2]] == ["R_xw", "R_xw"] and r.events[22].label == "R_xz,yw\u207b\u00b9"
    assert r.duration == pytest.approx(clock.now - 100.0)
    for again in (r, Recording.from_dict(json.loads(json.dumps(r.to_dict())))):
        got = again.replay()
        assert np.array_equal(got.matrix, st.matrix)  # bit for bit
        assert (got.theta0, got.alpha, got.c0, got.c0_step) == (st.theta0, st.alpha, st.c0, st.c0_step)
    # save / load
    r.save(tmp_path / "keys.json")
    back = Recording.load(tmp_path / "keys.json")
    assert back.to_dict() == r.to_dict()
    # into an existing state (a widget's): restarted at the recording's start, keymap kept
    km = DEFAULT_KEYMAP.replace(**{"4": "yw"})
    other = RotationState(keymap=km)
    back.replay(other)
    assert np.array_equal(other.matrix, st.matrix) and list(other.keymap.items()) == list(km.items())
    # the recorded reset ("r") went to the state as constructed, not to the recording's start
    live_reset = st.copy()
    live_reset.reset()
    other.reset()
    assert np.array_equal(other.matrix, live_reset.matrix)
    assert not np.array_equal(other.matrix, np.asarray(start["orientation"]))


def test_a_bounded_recorder_still_replays_to_the_live_state():
    st, _, clock = _live()
    rec = Recorder(st, max_events=7, clock=clock)
    _drive(st, rec, KEYS, clock)
    r = rec.recording()
    assert len(r) == 7 and r.dropped == len(KEYS) - 7
    assert r.events[0].t == pytest.approx((len(KEYS) - 6) / 30)
    got = r.replay()
    assert np.array_equal(got.matrix, st.matrix) and got.c0 == st.c0 and got.theta0 == st.theta0


def test_source_actions_replay_on_a_source_and_are_skipped_without():
    from rot4d_widget.tomography import StackSource

    src = StackSource("5-cell", slices=3)
    st = RotationState()
    rec = Recorder(st, clock=Clock())
    keymap = st.keymap.extended({"n": __import__("rot4d_widget").Action("custom", name="slice +", sign=1)})
    action, inverted = keymap.resolve("n")
    for _ in range(2):
        src.actions["n"].run(1)
        rec.record("n", False, action, inverted)
    st.press("4"), rec.record("4", False, "xw")
    r = rec.recording()
    mine = StackSource("5-cell", slices=3)
    got = r.replay(source=mine)
    assert mine.slices == 5 == src.slices and np.array_equal(got.matrix, st.matrix)
    assert np.array_equal(r.replay().matrix, st.matrix)  # skipped without a source
    # animations replay on a copy: the source given is left alone
    states = [(t, s.matrix, source.slices) for t, s, source in animation_states(r, None, mine)]
    assert [n for *_, n in states] == [5, 6, 7, 7] and mine.slices == 5


def test_frames_per_time_show_the_state_at_each_tick():
    st = RotationState(0.1)
    rec = Recorder(st, clock=Clock())
    for t, key in ((0.05, "4"), (0.12, "4"), (0.31, "8"), (1.0, "l")):
        rec.record(key, False, st.keymap[key], t=t)
    r = rec.recording()
    frames = [(t, s.matrix.copy(), s.c0) for t, s, _ in animation_states(r, per="time", fps=10)]
    assert [round(t, 6) for t, *_ in frames] == [round(0.1 * k, 6) for k in range(11)]
    counts = [0, 1, 2, 2, 3, 3, 3, 3, 3, 3, 4]  # events at or before each tick
    for (t, m, c0), n in zip(frames, counts):
        s = RotationState(0.1)
        for e in r.events[:n]:
            s.apply(e.action, e.inverted)
        assert np.array_equal(m, s.matrix) and c0 == s.c0
    steps = list(animation_states(r, per="step"))
    assert len(steps) == 5


def _gif_frames(path):
    from PIL import Image

    im = Image.open(path)
    out = []
    for k in range(im.n_frames):
        im.seek(k)
        out.append(np.asarray(im.convert("RGB")))
    return out


@pytest.mark.parametrize("figure", [3, 4])
def test_paper_figures_as_gif_have_16_different_frames(tmp_path, figure):
    path = tmp_path / f"fig{figure}.gif"
    n = paper_animation(figure, path, size=(160, 160), dpi=40, labels=False)
    frames = _gif_frames(path)
    assert n == 16 == len(frames)
    for a, b in zip(frames, frames[1:]):
        assert (a != b).any(axis=2).mean() > 0.002  # each press moves the slice visibly
    # the sequence is the figure's: the recording replays to 15 presses of the key
    r, _ = paper_recording(figure)
    want = RotationState(theta0=np.pi / 16) if figure == 3 else RotationState(theta0=1.0, alpha=np.pi * 2**0.5 / (8 * 3**0.5))
    for _ in range(15):
        want.press("4" if figure == 3 else "z")
    np.testing.assert_allclose(r.replay().matrix, want.matrix, atol=1e-15)
    if figure == 3:  # 32 presses of R_xw(pi/16) return: frame 0 and 15 differ, a frame 32 would not
        assert (frames[0] != frames[15]).any()


def test_mp4_has_one_frame_per_step(tmp_path):
    imageio = pytest.importorskip("imageio.v2")
    r, src = paper_recording(4, frames=6, fps=5)
    path = tmp_path / "fig4.mp4"
    assert render_animation(r, None, src, path, fps=5, size=(161, 121), dpi=40) == 6
    reader = imageio.get_reader(path)
    assert reader.count_frames() == 6
    assert tuple(reader.get_meta_data()["size"]) == (162, 122)  # padded to even sizes
    assert reader.get_meta_data()["fps"] == pytest.approx(5)


def test_bad_input_is_named(tmp_path):
    st = RotationState()
    rec = Recorder(st, clock=Clock())
    with pytest.raises(ValueError, match="Unknown action 'sideways'"):
        rec.record("x", False, "sideways")
    with pytest.raises(ValueError, match="a setting among"):
        rec.record_set("colour", 1)
    with pytest.raises(ValueError, match="orthogonal"):
        rec.record_set("matrix", np.ones((4, 4)))
    with pytest.raises(ValueError, match="max_events"):
        Recorder(st, max_events=0)
    r = rec.recording()
    with pytest.raises(ValueError, match="end in one of .gif, .mp4"):
        render_animation(r, None, "5-cell", tmp_path / "a.avi")
    with pytest.raises(ValueError, match="'step' or 'time'"):
        list(animation_states(r, per="frame"))
    rec.record("4", False, "xw", t=100.0)
    with pytest.raises(ValueError, match="more than max_frames = 50"):
        render_animation(rec.recording(), None, "5-cell", tmp_path / "a.gif", per="time", fps=10, max_frames=50)
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(ValueError, match="not a rot4d_widget recording: not JSON"):
        Recording.load(tmp_path / "bad.json")
    d = rec.recording().to_dict()
    for change, match in (({"format": "x"}, "Not a rot4d_widget recording"), ({"version": 5}, "version 5"),
                          ({"events": [{"t": 1.0}]}, "an 'action' or a 'set'"),
                          ({"events": [{"t": -1, "action": "xw"}]}, "time stamp >= 0"),
                          ({"events": [{"t": 2.0, "action": "xw"}, {"t": 1.0, "action": "xw"}]}, "time order")):
        with pytest.raises(ValueError, match=match):
            Recording.from_dict({**d, **change})


def test_events_are_steps_and_settings():
    rec = Recorder(RotationState(), clock=Clock())
    s = rec.record("C", True, "zw")
    assert isinstance(s, Step) and s.inverted and s.label == "R_zw\u207b\u00b9" and s.t == 0.0
    p = rec.record("l", True, "c0+")
    assert not p.inverted  # Shift inverts rotations only
    assert isinstance(rec.record_set("alpha", 0.01, t=2.0), Setting)
    assert [e["label"] if "label" in e else e["set"] for e in rec.recording().to_dict()["events"]] == \
        ["R_zw\u207b\u00b9", "c0+", "alpha"]
