"""Parallel slices in the widget (issue 10): traits, keys, no whole-view turn, colours by w."""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.sources.tomography import StackSource
from test_widget import down, up
from test_widget_scene import drawn, run_ticker

pytestmark = pytest.mark.usefixtures("recording_comms")


def test_slices_spacing_arrangement_are_traits_and_keys_follow(make):
    w = make("24-cell", slices=5, arrangement="grid")
    assert isinstance(w.source, StackSource)
    assert (w.slices, w.arrangement) == (5, "grid") and w.spacing == pytest.approx(2 * 2.0 / 5)
    w.press("n")
    assert w.slices == w.source.slices == 6
    w.press("b")
    w.press("b")
    assert w.slices == 4
    d = w.spacing
    w.press("g")
    assert w.spacing == pytest.approx(d * 2 ** 0.25) == w.source.spacing
    w.slices = 9
    assert w.source.slices == 9
    w.arrangement = "stack"
    assert w.source.arrangement == "stack"
    with pytest.raises(ValueError):
        w.arrangement = "spiral"
    assert w.arrangement == w.source.arrangement == "stack"
    with pytest.raises(ValueError):
        w.slices = 0
    assert w.slices == 9


def _same_picture(a, b):
    """The same rows drawn (the capacities may differ: a wrapped view keeps its first one)."""
    assert a.scene.counts == b.scene.counts
    n = max(a.scene.counts)  # the layers share rows: each draws the first counts[i]
    np.testing.assert_array_equal(a.scene.rows[:n], b.scene.rows[:n])


def test_a_single_view_becomes_parallel_slices_when_asked(make):
    """slices is None on a single view; setting it (or pressing n) wraps the source at run time."""
    w = make("24-cell")
    assert w.slices is None and w.spacing is None
    with pytest.raises(TypeError, match="slices"):
        w.spacing = 0.5  # no stack yet: nothing to space
    with pytest.raises(ValueError, match="slices"):
        w.slices = 0
    assert w.slices is None and not isinstance(w.source, StackSource)
    w.slices = 5
    assert isinstance(w.source, StackSource) and w.source.slices == 5
    assert (w.slices, w.arrangement) == (5, "oval") and w.spacing == pytest.approx(2 * 2.0 / 5)
    _same_picture(w, make("24-cell", slices=5))
    w.press("n")  # the stack's keys are bound now
    assert w.slices == 6 and "add a parallel slice" in w.help_panel.value
    with pytest.raises(TypeError, match="slices"):
        make("24-cell", spacing=0.5)

    pressed = make("5-cell")
    assert not pressed.press("b")  # one slice: nothing to remove
    assert pressed.slices is None
    assert pressed.press("n")
    assert isinstance(pressed.source, StackSource) and pressed.slices == 2
    _same_picture(pressed, make("5-cell", slices=2))
    # the wrap is recorded as the source setting it is (issue 18 item 9: replay ends where you ended)
    [wrap] = pressed.recording.events
    assert (wrap.name, wrap.value) == ("slices", 2)
    pressed.press("n")  # the stack's own key from here on: recorded as a step
    assert pressed.recording.events[-1].action.name == "slice +"
    again = make("5-cell")
    again.replay(pressed.recording)
    assert isinstance(again.source, StackSource) and again.slices == 3


def test_one_slice_is_today_s_view(make):
    one = make("24-cell", slices=1)
    plain = make("24-cell")
    np.testing.assert_array_equal(one.scene.rows, plain.scene.rows)


def test_a_held_3d_turn_reslices_each_slice_instead_of_turning_the_whole_layout(make, clock):
    w = make("8-cell", slices=3, arrangement="stack")
    turns = []
    w.scene.turn = lambda r: turns.append(r) or True
    centres_before = np.asarray(w.source.layout()[0])
    down(w, "2")
    t = clock.t + 0.8
    while clock.t < t:
        drawn(w)
        run_ticker(w, clock, clock.t + 0.05)
    up(w, "2")
    assert turns == []  # never the whole view: the slices stay where the layout puts them
    assert w.stats.updates > 3
    np.testing.assert_allclose(w.source.layout()[0], centres_before)


def test_colours_by_w_reach_the_rows_and_the_legend(make):
    w = make("24-cell", slices=3, spacing=0.5, arrangement="stack")
    colors = w.source.group_colors()
    from rot4d_widget.view import buffers as bf

    packed = set(bf.pack_rgb(colors).tolist())
    used = w.scene.rows[: w.scene.counts[2], 19]
    assert set(np.unique(used).tolist()) <= packed and len(np.unique(used)) == 3
    for k in range(3):
        assert "#" + "".join(f"{round(255 * c):02x}" for c in colors[k]) in w.readout.value
