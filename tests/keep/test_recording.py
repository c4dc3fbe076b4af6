"""Issue 12: recorded key sequences (rot4d_widget.keep.recorder, .animation): record, save, replay, animate."""

import json

import numpy as np
import pytest

from rot4d_widget import DEFAULT_KEYMAP, RotationState
from rot4d_widget.keep.recorder import Recorder, Recording, Setting, SourceSetting, Step
from rot4d_widget.keep.animation import animation_states, paper_animation, paper_recording, render_animation
from rot4d_widget.core.rotation import random_rotation


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
    from rot4d_widget.sources.tomography import StackSource

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
                          ({"events": [{"t": 1.0}]}, "an 'action', a 'set', a 'source' or a 'view'"),
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


# -------------------------------------------------------------------- dropped, validated
@pytest.mark.parametrize("dropped", [-5, "x", 1.5, True, None, "3"])
def test_dropped_must_be_an_int_at_least_zero(dropped):
    initial = RotationState().to_dict(initial=True)
    with pytest.raises(ValueError, match=r"`dropped` .* to be an int >= 0, got"):
        Recording(initial, (), dropped=dropped)
    d = Recording(initial).to_dict()
    with pytest.raises(ValueError, match=r"`dropped` .* to be an int >= 0"):
        Recording.from_dict({**d, "dropped": dropped})
    assert Recording(initial, (), dropped=np.int64(3)).dropped == 3 and Recording(initial).dropped == 0


# -------------------------------------------------------------------- source settings
def ball(x, y, z, w):
    return 4.0 - (x * x + y * y + z * z) - 0.5 * w


def _ball_field():
    from rot4d_widget import Field4D

    return Field4D.from_function(ball, [(-2, 2)] * 4, resolution=10, coarse_resolution=8)


def _source_recording():
    """The issue's steps: levels, then parallel slices, their spacing and arrangement, keys between."""
    clock = Clock()
    st = RotationState()
    rec = Recorder(st, clock=clock)
    for key, (name, value) in zip("4z8", [("levels", (2.0, 3.0)), ("slices", 3), ("spacing", 0.3)]):
        clock.now += 0.1
        rec.record_source(name, value)
        clock.now += 0.1
        st.press(key)
        rec.record(key, False, *st.keymap.resolve(key))
    clock.now += 0.1
    rec.record_source("arrangement", "grid")
    rec.record_source("levels", 2.5)
    return rec.recording(), st


def test_source_settings_are_recorded_saved_and_loaded(tmp_path):
    r, st = _source_recording()
    kinds = [type(e).__name__ for e in r.events]
    assert kinds == ["SourceSetting", "Step"] * 3 + ["SourceSetting"] * 2
    assert [(e.name, e.value) for e in r.events if isinstance(e, SourceSetting)] == [
        ("levels", [2.0, 3.0]), ("slices", 3), ("spacing", 0.3), ("arrangement", "grid"), ("levels", [2.5])]
    assert r.events[0].label == "levels set" and r.events[0].t == pytest.approx(0.1)
    d = r.to_dict()
    assert d["version"] == 2 and d["events"][0] == {"t": r.events[0].t, "source": "levels", "value": [2.0, 3.0]}
    r.save(tmp_path / "keys.json")
    back = Recording.load(tmp_path / "keys.json")
    assert back.to_dict() == d and back.events == r.events
    # a recording without source settings is still written as version 1 (older readers read it)
    plain = Recorder(RotationState(), clock=Clock())
    plain.record("4", False, "xw")
    assert plain.recording().to_dict()["version"] == 1
    old = {**plain.recording().to_dict(), "version": 1}
    assert len(Recording.from_dict(old)) == 1


def test_replay_sets_the_source_settings_on_a_stack_and_its_inner_field():
    from rot4d_widget.sources.protocol import inner_source
    from rot4d_widget.sources.tomography import StackSource

    r, st = _source_recording()
    field = _ball_field()
    stack = StackSource(field, slices=2)
    assert field.levels != (2.5,)
    got = r.replay(None, stack)
    assert field.levels == (2.5,)  # `levels` on the stack's inner source
    assert (stack.slices, stack.spacing, stack.arrangement) == (3, 0.3, "grid")
    assert np.array_equal(got.matrix, st.matrix)
    # the case: `w.levels = (2.0, 3.0)` replayed ends at (2.0, 3.0), not the field's default
    rec = Recorder(RotationState(), clock=Clock())
    rec.record_source("levels", (2.0, 3.0))
    fresh = _ball_field()
    rec.recording().replay(None, fresh)
    assert fresh.levels == (2.0, 3.0)
    rec.record_source("spacing", 0.3)
    one = StackSource(_ball_field(), slices=4)
    rec.recording().replay(None, one)
    assert one.spacing == 0.3 and one.source.levels == (2.0, 3.0)


def test_replay_calls_set_source_in_order_with_the_steps():
    r, st = _source_recording()
    calls = []
    state = RotationState()
    got = r.replay(state, "anything: set_source applies the settings",
                   set_source=lambda name, value: calls.append((name, value, state.matrix.copy())))
    assert [(n, v) for n, v, _ in calls] == [("levels", [2.0, 3.0]), ("slices", 3), ("spacing", 0.3),
                                              ("arrangement", "grid"), ("levels", [2.5])]
    # each call came between the steps it was recorded between
    assert np.array_equal(calls[0][2], np.eye(4)) and not np.array_equal(calls[1][2], np.eye(4))
    assert np.array_equal(calls[-1][2], st.matrix) and got is state
    with pytest.raises(TypeError, match="`set_source` to be a callable"):
        r.replay(None, None, set_source="levels")


def test_a_single_view_given_stack_settings_is_refused_before_any_change():
    r, _ = _source_recording()
    field = _ball_field()
    before = field.levels
    state = RotationState()
    with pytest.raises(ValueError, match=r"sets 'arrangement', 'slices', 'spacing'.*single view.*set_source="):
        r.replay(state, field)
    assert field.levels == before and np.array_equal(state.matrix, np.eye(4))
    with pytest.raises(ValueError, match="sets 'levels'.*iso levels"):
        r.replay(None, __import__("rot4d_widget").StackSource("5-cell", slices=2))
    assert np.array_equal(r.replay().matrix, r.replay(None, None).matrix)  # skipped without a source


def test_animations_follow_the_source_settings_on_their_copy():
    from rot4d_widget.sources.protocol import inner_source
    from rot4d_widget.sources.tomography import StackSource

    r, st = _source_recording()
    field = _ball_field()
    before = field.levels
    # every source has `slices` (1: the protocol's default, `SourceBase`); a field has no arrangement
    seen = [(type(src).__name__, tuple(inner_source(src).levels), src.slices,
             src.spacing if isinstance(src, StackSource) and not src.spacing_is_default else None,
             getattr(src, "arrangement", None)) for _, _, src in animation_states(r, None, field)]
    assert seen[0] == ("Field4D", before, 1, None, None)
    assert seen[1] == ("Field4D", (2.0, 3.0), 1, None, None)  # after levels set
    assert seen[3][:3] == ("StackSource", (2.0, 3.0), 3)  # slices made a stack of the copy, as the widget
    assert seen[5][3] == 0.3 and seen[-2][4] == "grid" and seen[-1][1] == (2.5,)
    assert field.levels == before  # the source given is left alone


def test_render_frames_follow_the_source_settings(monkeypatch):
    """Each frame is drawn with the settings recorded up to it; the keywords given are the start."""
    from rot4d_widget.keep.pictures import state_picture
    from rot4d_widget.keep.animation import render_frames

    drawn = []

    def fake_render_state(state, source, **kwargs):
        stack = state_picture.state_source(source, **{k: kwargs.get(k) for k in
                                                ("levels", "slices", "spacing", "arrangement")})
        drawn.append((stack.source.levels, stack.slices, stack.spacing, stack.arrangement))
        import matplotlib.figure

        return matplotlib.figure.Figure(figsize=(0.2, 0.2), dpi=10)

    monkeypatch.setattr(state_picture, "render_state", fake_render_state)
    r, _ = _source_recording()
    field = _ball_field()
    frames = list(render_frames(r, None, field, levels=(1.0,), slices=None, spacing=None, arrangement="oval"))
    assert len(frames) == len(r) + 1
    assert drawn[0][0] == (1.0,) and drawn[0][1] == 1  # the start: the keywords given
    assert drawn[1][0] == (2.0, 3.0)  # the recorded levels, not the keyword's
    assert drawn[3][1] == 3 and drawn[5][2] == 0.3 and drawn[-2][3] == "grid" and drawn[-1][0] == (2.5,)
    assert field.levels != (1.0,)


def test_a_bounded_recorder_folds_source_settings_into_the_starting_ones():
    from rot4d_widget.sources.tomography import StackSource

    clock = Clock()
    st = RotationState()
    rec = Recorder(st, max_events=3, clock=clock, source_settings={"arrangement": "stack"})
    for v in (1.0, 2.0, 3.0):
        clock.now += 0.1
        rec.record_source("levels", v)
    rec.record_source("spacing", 0.4)
    for _ in range(5):
        clock.now += 0.1
        st.press("4")
        rec.record("4", False, "xw")
    r = rec.recording()
    assert r.dropped == 6 and [type(e).__name__ for e in r.events] == ["Step"] * 3
    assert r.initial_source == {"levels": [3.0], "spacing": 0.4, "arrangement": "stack"}
    stack = StackSource(_ball_field(), slices=2)
    got = r.replay(None, stack)
    assert stack.source.levels == (3.0,) and stack.spacing == 0.4 and stack.arrangement == "stack"
    assert np.array_equal(got.matrix, st.matrix)


def test_the_source_settings_at_the_start_are_kept_and_replayed_first(tmp_path):
    from rot4d_widget.sources.tomography import StackSource

    st = RotationState()
    rec = Recorder(st, clock=Clock(), source_settings={"slices": 4, "levels": (1.5,)})
    st.press("4")
    rec.record("4", False, "xw")
    rec.record_source("levels", (2.0,), t=1.0)
    r = rec.recording()
    assert r.initial_source == {"levels": [1.5], "slices": 4}
    d = r.to_dict()
    assert d["version"] == 2 and d["initial_source"] == {"levels": [1.5], "slices": 4}
    r.save(tmp_path / "keys.json")
    assert Recording.load(tmp_path / "keys.json").initial_source == r.initial_source
    calls = []
    r.replay(None, None, set_source=lambda name, value: calls.append((name, value)))
    assert calls == [("levels", [1.5]), ("slices", 4), ("levels", [2.0])]
    calls.clear()
    r.replay(None, None, restart=False, set_source=lambda name, value: calls.append((name, value)))
    assert calls == [("levels", [2.0])]  # not restarted: the start settings are not applied
    stack = StackSource(_ball_field(), slices=2)
    r.replay(None, stack)
    assert stack.slices == 4 and stack.source.levels == (2.0,)
    frames = [(type(src).__name__, getattr(src, "slices", None), getattr(src, "source", src).levels)
              for _, _, src in animation_states(r, None, _ball_field())]
    assert frames == [("StackSource", 4, (1.5,)), ("StackSource", 4, (1.5,)), ("StackSource", 4, (2.0,))]
    rec.restart(st, {"spacing": None})
    assert rec.recording().initial_source == {"spacing": None} and len(rec.recording()) == 0
    with pytest.raises(ValueError, match="a source setting among"):
        Recorder(st, source_settings={"no name": 1})
    # a source's own setting (a name its protocol `settings` may have) is kept as given, after the built-in ones
    assert Recorder(st, source_settings={"colour": 1, "levels": 2.0}).recording().initial_source == {
        "levels": [2.0], "colour": 1}
    with pytest.raises(ValueError, match="as a dict"):
        Recording(st.to_dict(initial=True), initial_source=[("levels", 1.0)])


@pytest.mark.parametrize("name, value, match", [
    ("no name", 1, "a source setting among 'levels', 'inside', 'caps', 'slices', 'spacing', 'arrangement'"),
    (3, 1, "a source setting among .* or a source's own setting"),
    ("colour", object(), "to be JSON"),
    ("colour", float("nan"), "to be JSON"),
    ("levels", (), "non-empty sequence"),
    ("levels", ("a",), "finite number or a non-empty sequence"),
    ("levels", float("nan"), "finite number"),
    ("slices", 0, "'slices' to be set to an int >= 1"),
    ("slices", 2.0, "an int >= 1"),
    ("spacing", -1.0, "finite number > 0 or None"),
    ("arrangement", "circle", "one of 'oval', 'grid', 'stack'"),
    ("inside", "out", "'above' or 'below'"),
    ("caps", 1, "True or False"),
])
def test_record_source_names_what_is_allowed(name, value, match):
    rec = Recorder(RotationState(), clock=Clock())
    with pytest.raises(ValueError, match=match):
        rec.record_source(name, value)
    d = Recording(RotationState().to_dict(initial=True)).to_dict()
    with pytest.raises(ValueError, match=match):
        Recording.from_dict({**d, "version": 2, "events": [{"t": 0.0, "source": name, "value": value}]})
    assert rec.record_source("spacing", None).value is None
