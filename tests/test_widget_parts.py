"""The units Rot4DWidget is composed of (issue 20), each on its own: trait types, the view key,
kinds read through the source protocol, a user's source's own settings recorded and replayed,
screenshots, the key pad, the key path."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import traitlets

from rot4d_widget.core.rotation import simple_rotation
from rot4d_widget.sources.protocol import SliceData
from rot4d_widget.view import traits as t
from rot4d_widget.view.painter import ViewKey
from rot4d_widget.view.screenshots import MAX_PENDING_SCREENSHOTS
from rot4d_widget.view.stacking import is_stack


# -- trait types -----------------------------------------------------------------------------------
class _Holder(traitlets.HasTraits):
    radius = t.Positive(0.5, upper=10.0)
    opacity = t.Fraction(0.4)
    flag = t.Flag(True)
    count = t.Count(None, low=1, high=64, allow_none=True)
    spacing = t.Spacing(None, allow_none=True)
    arrangement = t.Choice(None, ("oval", "grid", "stack"), allow_none=True)
    levels = t.Levels(None, allow_none=True)
    angle = t.Angle(0.1)
    colour = t.Colour("#fff")
    color_by = t.ColorBy("group")


@pytest.mark.parametrize("name, value, exc, match", [
    ("radius", -1.0, ValueError, r"`radius` in \(0, 10.0\]"),
    ("radius", "big", TypeError, "`radius` to be a positive number"),
    ("opacity", 1.5, ValueError, r"`opacity` to be a number in \[0, 1\]"),
    ("flag", "no", TypeError, "`flag` to be True or False"),
    ("count", 0, ValueError, "`count` to be an int in 1 \u2026 64 or None"),
    ("count", True, TypeError, "`count` to be an int in 1 \u2026 64 or None"),
    ("count", 2.0, TypeError, "`count`"),
    ("spacing", True, TypeError, "`spacing` to be a finite number > 0 or None"),
    ("spacing", -1, ValueError, "`spacing` to be a finite number > 0 or None"),
    ("arrangement", "spiral", ValueError, "'oval', 'grid', 'stack' or None"),
    ("arrangement", 3, TypeError, "`arrangement`"),
    ("levels", "high", TypeError, "`levels` to be a number or a sequence of numbers"),
    ("levels", [], TypeError, "`levels`"),
    ("angle", -0.1, ValueError, r"\(0, pi\]"),
    ("colour", "sky", ValueError, "#rrggbb"),
    ("color_by", "purple", ValueError, "color_by.*group"),
])
def test_trait_types_refuse_naming_what_is_allowed(name, value, exc, match):
    h = _Holder()
    before = getattr(h, name)
    with pytest.raises(exc, match=match):
        setattr(h, name, value)
    assert getattr(h, name) == before


def test_trait_types_normalise_what_they_accept():
    h = _Holder()
    h.count, h.spacing, h.flag, h.radius = np.int64(5), 2, np.bool_(False), 1
    assert (type(h.count), type(h.spacing), type(h.flag), type(h.radius)) == (int, float, bool, float)
    h.levels = 0.5
    assert h.levels == (0.5,)
    h.levels = np.array([0.1, 0.2])
    assert h.levels == (0.1, 0.2)
    h.count = None
    assert h.count is None
    h.color_by = [1, 0, 0]
    assert h.color_by == (1.0, 0.0, 0.0)


def test_the_widgets_traits_are_typed_in_the_declaration():
    from rot4d_widget.view.widget import Rot4DWidget

    typed = {n for n, tr in Rot4DWidget.class_traits().items() if isinstance(tr, t.Checked)}
    assert typed >= {"theta0", "alpha", "c0", "ball_radius", "bar_radius", "face_opacity", "background",
                     "show_balls", "show_bars", "show_faces", "color_by", "levels", "inside", "caps", "slices",
                     "spacing", "arrangement"}
    assert Rot4DWidget.class_traits()["slices"].high == 64


# -- the view key --------------------------------------------------------------------------------------
def test_view_key_compares_by_name_not_position():
    m = np.eye(4)
    a = ViewKey(m, 0.0, (0, 0, 5), 1, "group", False)
    assert a.same(ViewKey(m.copy(), 0.0, (0, 0, 5), 1, "group", False))
    assert not a.same(ViewKey(m, 0.0, (0, 0, 5), 1, "group", True))  # coarse differs
    assert a.same_cut(ViewKey(simple_rotation("xy", 0.3), 0.0, (0, 0, 5), 1, "group", True))
    assert not a.same_cut(ViewKey(m, 0.1, (0, 0, 5), 1, "group", False))
    turned = ViewKey(simple_rotation("xy", 0.3), 0.0, (0, 0, 5), 1, "group", False)
    np.testing.assert_allclose(turned.turn_from(a), simple_rotation("xy", 0.3)[:3, :3])
    assert ViewKey(simple_rotation("xw", 0.3), 0.0, (0, 0, 5), 1, "group", False).turn_from(a) is None
    with pytest.raises(AttributeError):
        a.c0 = 1.0  # frozen


# -- kinds through the protocol ------------------------------------------------------------------------
class Slab:
    """A user's source with its own setting (thickness), through the protocol's settings/apply_setting."""

    size = math.sqrt(3.0)
    n_groups = 1

    def __init__(self, thickness=0.5):
        self.thickness = thickness

    @property
    def settings(self):
        return {"thickness": self.thickness}

    def apply_setting(self, name, value):
        if name != "thickness":
            raise ValueError(f"A slab's setting is 'thickness', not {name!r}")
        self.thickness = float(value)

    def slice(self, matrix, c0):
        h = self.thickness
        pts = np.array([[x, y, z] for x in (-h, h) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        return SliceData.build(pts, volume=8 * h)

    def describe(self):
        return {"kind": "slab", "thickness": self.thickness, "rebuild": "a test's own class"}


class Wrapper(Slab):
    """Not a StackSource, but a source made around another: the protocol says so (``wraps``)."""

    def __init__(self):
        super().__init__()
        self.wraps = Slab()


def test_a_stack_is_a_source_that_wraps_another_whatever_its_class():
    assert is_stack(Wrapper()) and not is_stack(Slab())


def test_a_user_sources_settings_are_recorded_on_refresh_and_replayed(make):
    slab = Slab()
    w = make(slab)
    assert w.recording.initial_source == {"thickness": 0.5}
    assert w.source.user_object is slab  # the source shown is the UserSource wrapping it (issue 38)
    w.source.thickness = 0.25
    assert slab.thickness == 0.25
    w.refresh()
    rec = w.recording
    assert [(e.name, e.value) for e in rec.events if hasattr(e, "name") and e.name == "thickness"] == [
        ("thickness", 0.25)]
    w.refresh()  # unchanged: not recorded again
    assert sum(getattr(e, "name", None) == "thickness" for e in w.recording.events) == 1
    other = make(Slab())
    other.replay(rec)
    assert other.source.thickness == 0.25 and other.slice.volume == pytest.approx(2.0)


# -- screenshots, key pad, key path ----------------------------------------------------------------------
def test_screenshots_without_a_view_are_bounded_and_say_so(make):
    w = make("5-cell")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(3 * MAX_PENDING_SCREENSHOTS):
            assert w.screenshot() is None
    assert len(w._shots.pending) == MAX_PENDING_SCREENSHOTS
    assert "no view is displayed" in w._painter.note and "no view is displayed" in w.readout.value


def test_the_key_pad_is_built_once_when_first_shown(make):
    w = make("5-cell")
    assert w._keypad.box is None
    w.keypad = True
    box = w._keypad.box
    w.keypad = False
    w.keypad = True
    assert w._keypad.box is box and box.layout.display is None and len(w._keypad.events) >= 20


def test_the_key_path_steps_records_and_settles(make):
    w = make("5-cell")
    keys = w._keys
    keys.handle_event({"type": "keydown", "key": "4", "code": "Digit4", "timeStamp": 1000.0})
    assert keys.last.label is not None and keys.last.count == 1 and w.held_keys == ("Digit4",)
    keys.handle_event({"type": "keyup", "key": "4", "code": "Digit4", "timeStamp": 1010.0})
    assert w.held_keys == () and w._painter.settled
    assert len(w.recording.events) == 1
    keys.handle_event("not an event")  # ignored, never raised
    assert w.errors.outputs == ()
