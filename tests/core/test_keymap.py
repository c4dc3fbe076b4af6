"""Keymap: data a user can replace, browser-event lookup on several layouts."""

import pytest

from rot4d_widget import DEFAULT_KEYMAP, Action, Keymap


def ev(key, code, shift=False, **extra):
    return {"type": "keydown", "key": key, "code": code, "shiftKey": shift, "repeat": False, **extra}


def planes(found):
    action, inverted = found
    return action.planes if action.is_rotation else action.kind, inverted


PAPER_TABLES = {
    "2": "xy", "3": "xz", "4": "xw", "6": "yz", "8": "yw", "c": "zw",
    "y": "xy,zw", "z": "xz,yw", "w": "xw,yz",
}


def test_default_keymap_holds_the_papers_tables():
    for key, p in PAPER_TABLES.items():
        assert DEFAULT_KEYMAP[key] == Action("rotate", planes=p)
    assert DEFAULT_KEYMAP["k"].kind == "alpha" and DEFAULT_KEYMAP["k"].sign == 1
    assert DEFAULT_KEYMAP["j"].kind == "alpha" and DEFAULT_KEYMAP["j"].sign == -1
    assert DEFAULT_KEYMAP["l"].kind == "c0" and DEFAULT_KEYMAP["l"].sign == 1
    assert DEFAULT_KEYMAP["h"].kind == "c0" and DEFAULT_KEYMAP["h"].sign == -1


def test_simple_rotation_keys_are_the_product_of_axis_numbers_in_hex():
    for key, action in DEFAULT_KEYMAP.items():
        if action.is_rotation and not action.is_double:
            i, j = ("xyzw".index(a) + 1 for a in action.planes)
            assert key == format(i * j, "x")


def test_extra_keys_do_not_collide_with_the_paper():
    extras = {k for k, a in DEFAULT_KEYMAP.items() if a.kind in ("reset", "theta0", "help")}
    assert extras and extras.isdisjoint(set(PAPER_TABLES) | set("kjlh"))
    kinds = {a.kind for a in DEFAULT_KEYMAP.values()}
    assert {"reset", "theta0", "help"} <= kinds


US = [
    (ev("4", "Digit4"), ("xw", False)),
    (ev("$", "Digit4", True), ("xw", True)),
    (ev("2", "Digit2", True), ("xy", True)),  # Playwright's "Shift+2"
    (ev("@", "Digit2", True), ("xy", True)),  # a real US keyboard / "Shift+Digit2"
    (ev("2", "Numpad2"), ("xy", False)),
    (ev("c", "KeyC"), ("zw", False)),
    (ev("C", "KeyC", True), ("zw", True)),
    (ev("C", "KeyC", False), ("zw", False)),  # Caps Lock does not invert
    (ev("z", "KeyZ"), ("xz,yw", False)),
    (ev("W", "KeyW", True), ("xw,yz", True)),
    (ev("k", "KeyK"), ("alpha", False)),
    (ev("K", "KeyK", True), ("alpha", False)),  # shift does nothing to parameter keys
]
GERMAN = [
    (ev("z", "KeyY"), ("xz,yw", False)),  # QWERTZ: the key typing z has code KeyY
    (ev("y", "KeyZ"), ("xy,zw", False)),
    (ev('"', "Digit2", True), ("xy", True)),
    (ev("$", "Digit4", True), ("xw", True)),
    (ev("(", "Digit8", True), ("yw", True)),
]
FRENCH = [
    (ev("w", "KeyZ"), ("xw,yz", False)),  # AZERTY: the key typing w has code KeyZ
    (ev("z", "KeyW"), ("xz,yw", False)),
    (ev("é", "Digit2"), ("xy", False)),  # unshifted Digit2 types é: still R_xy
    (ev("2", "Digit2", True), ("xy", True)),  # Shift+Digit2 types 2: the inverse
    (ev("'", "Digit4"), ("xw", False)),
    (ev("-", "Digit6"), ("yz", False)),  # Digit6 types "-" on AZERTY, not theta0-
    (ev("_", "Digit8"), ("yw", False)),
]


@pytest.mark.parametrize("event, expected", US + GERMAN + FRENCH)
def test_lookup_on_layouts(event, expected):
    assert planes(DEFAULT_KEYMAP.lookup(event)) == expected


@pytest.mark.parametrize(
    "event",
    [
        ev("5", "Digit5"),
        ev("q", "KeyQ"),
        ev("Enter", "Enter"),
        ev("Shift", "ShiftLeft", True),
        ev("c", "KeyC", ctrlKey=True),
        ev("4", "Digit4", metaKey=True),
        {"type": "keydown"},
        {"key": 4, "code": None},
        "4",
        None,
    ],
)
def test_lookup_of_unbound_or_malformed_events_is_none(event):
    assert DEFAULT_KEYMAP.lookup(event) is None


def test_symbol_keys_by_character_and_code():
    assert DEFAULT_KEYMAP.lookup(ev("?", "Slash", True))[0].kind == "help"
    assert DEFAULT_KEYMAP.lookup(ev("+", "NumpadAdd"))[0].kind == "theta0"
    assert DEFAULT_KEYMAP.lookup(ev("+", "Equal", True))[0].sign == 1
    assert DEFAULT_KEYMAP.lookup(ev("r", "KeyR"))[0].kind == "reset"


def test_user_keymap_replaces_bindings():
    km = Keymap({"a": "xw", "1": "zw", "F2": "reset"})
    assert planes(km.lookup(ev("a", "KeyA"))) == ("xw", False)
    assert planes(km.lookup(ev("!", "Digit1", True))) == ("zw", True)
    assert planes(km.lookup(ev("F2", "F2"))) == ("reset", False)
    assert km.lookup(ev("4", "Digit4")) is None
    assert len(km) == 3 and "a" in km


@pytest.mark.parametrize(
    "bindings, exc, match",
    [
        ({"4": "xq"}, ValueError, "Unknown action 'xq'; expected one of 'xy'"),
        ({"4": "spin"}, ValueError, "'alpha\\+', 'alpha-', 'c0\\+'"),
        ({"C": "zw"}, ValueError, "lower-case letter 'c'"),
        ({"Digit4": "xw"}, ValueError, "bind the digit '4'"),
        ({"two words": "xw"}, ValueError, "single character"),
        ({" ": "xw"}, ValueError, "printable"),
        ({4: "xw"}, TypeError, "strings"),
        ([("4", "xw")], TypeError, "mapping"),
    ],
)
def test_bad_keymaps_name_what_is_allowed(bindings, exc, match):
    with pytest.raises(exc, match=match):
        Keymap(bindings)


def test_labels():
    assert DEFAULT_KEYMAP["4"].label() == "R_xw"
    assert DEFAULT_KEYMAP["z"].label(True) == "R_xz,yw\u207b\u00b9"
    assert DEFAULT_KEYMAP["k"].label() == "\u03b1+"
    rows = DEFAULT_KEYMAP.help_rows()
    assert ("4", "R_xw", "simple rotation R_xw by \u03b80") in rows


# -- keys the next issues add (issue 7) ------------------------------------------

from rot4d_widget.core import keymap as keymap_module  # noqa: E402

RESERVED = {
    "o": ("level", 1, "raise the iso level (fields)"),
    "i": ("level", -1, "lower the iso level (fields)"),
    "n": ("slices", 1, "add a parallel slice (multi-slice view)"),
    "b": ("slices", -1, "remove a parallel slice (multi-slice view)"),
    "g": ("spacing", 1, "widen the slice spacing (multi-slice view)"),
    "f": ("spacing", -1, "narrow the slice spacing (multi-slice view)"),
    "p": ("screenshot", 0, "save a picture of the view (PNG)"),
}
EXISTING_EXTRAS = {"r", "+", "-", "=", "_", "?", "NumpadAdd", "NumpadSubtract"}


@pytest.mark.parametrize("key, expected", RESERVED.items())
def test_reserved_keys_of_the_next_issues(key, expected):
    kind, sign, description = expected
    action = DEFAULT_KEYMAP[key]
    assert (action.kind, action.sign) == (kind, sign)
    assert action.describe() == description
    assert action == Action.parse(action.label().replace("\u2212", "-"))  # the label is its name
    found = DEFAULT_KEYMAP.lookup(ev(key.upper(), f"Key{key.upper()}", True))
    assert found == (action, False)  # by the character typed; Shift inverts nothing


def test_reserved_keys_collide_with_nothing():
    reserved = set(RESERVED)
    assert reserved.isdisjoint(set(PAPER_TABLES) | set("kjlh"))
    assert reserved.isdisjoint(EXISTING_EXTRAS)
    assert EXISTING_EXTRAS <= set(DEFAULT_KEYMAP)
    assert {a.kind for k, a in DEFAULT_KEYMAP.items() if k in reserved} == {"level", "slices", "spacing", "screenshot"}


def test_reserved_labels_are_short_and_distinct():
    labels = {key: DEFAULT_KEYMAP[key].label() for key in RESERVED}
    assert labels == {
        "o": "level+", "i": "level\u2212", "n": "slices+", "b": "slices\u2212",
        "g": "spacing+", "f": "spacing\u2212", "p": "screenshot",
    }


def test_repeating_kinds():
    REPEATING_KINDS = keymap_module.REPEATING_KINDS
    assert REPEATING_KINDS == frozenset({"rotate", "alpha", "c0", "level", "spacing", "section"})
    kinds = {a.kind for a in DEFAULT_KEYMAP.values()}
    assert REPEATING_KINDS <= kinds
    assert kinds - REPEATING_KINDS == {"theta0", "reset", "help", "slices", "screenshot", "rendering"}


# -- custom actions a data source brings -----------------------------------------


def test_custom_action_label_and_description():
    a = Action("custom", name="phase+", sign=1, text="advance the phase by one step")
    assert a.label() == "phase+" and a.label(True) == "phase+"
    assert a.describe() == "advance the phase by one step"
    assert not a.is_rotation and not a.is_double
    assert a == Action("custom", name="phase+", sign=1, text="advance the phase by one step")
    assert a != Action("custom", name="phase-", sign=-1, text="advance the phase by one step")
    # the old positional and keyword forms still work
    assert Action("rotate", "xw") == Action("rotate", planes="xw") == DEFAULT_KEYMAP["4"]
    assert Action("alpha", "", 1) == DEFAULT_KEYMAP["k"]


@pytest.mark.parametrize(
    "kwargs, match",
    [({}, "custom.*`name`"), ({"name": ""}, "custom.*`name`"), ({"name": 3}, "custom.*`name`")],
)
def test_custom_action_needs_a_name(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        Action("custom", **kwargs)


def test_extended_adds_keys_and_replaces_only_reserved_ones():
    phase = Action("custom", name="phase+", sign=1, text="advance the phase")
    iso = Action("custom", name="iso+", sign=1, text="raise the density contour")
    km = DEFAULT_KEYMAP.extended({"t": phase, "o": iso, "F2": "reset"})
    assert isinstance(km, Keymap) and km is not DEFAULT_KEYMAP
    assert km["t"] == phase and km["o"] == iso and km["F2"].kind == "reset"
    assert km.lookup(ev("t", "KeyT")) == (phase, False)
    assert "t" not in DEFAULT_KEYMAP and DEFAULT_KEYMAP["o"].kind == "level"  # the original is untouched
    assert {k: a for k, a in km.items() if k not in ("t", "o", "F2")} == {
        k: a for k, a in DEFAULT_KEYMAP.items() if k != "o"
    }


@pytest.mark.parametrize(
    "key, match",
    [
        ("4", "'4' is already bound to R_xw"),
        ("c", "'c' is already bound to R_zw"),
        ("k", "'k' is already bound to \u03b1\\+"),
        ("r", "'r' is already bound to reset"),
        ("NumpadAdd", "'NumpadAdd' is already bound to \u03b80\\+"),
        ("KeyC", "'KeyC' would shadow 'c'.*R_zw"),
    ],
)
def test_extended_refuses_to_replace_a_bound_key(key, match):
    phase = Action("custom", name="phase+", sign=1, text="advance the phase")
    with pytest.raises(ValueError, match=match):
        DEFAULT_KEYMAP.extended({key: phase})


def test_extended_checks_its_input_like_the_constructor():
    with pytest.raises(ValueError, match="lower-case letter 't'"):
        DEFAULT_KEYMAP.extended({"T": "reset"})
    with pytest.raises(TypeError, match="mapping"):
        DEFAULT_KEYMAP.extended([("t", "reset")])


# -- help with aliases collapsed ---------------------------------------------------


def test_help_groups_collapse_aliases():
    groups = DEFAULT_KEYMAP.help_groups()
    actions = list(dict.fromkeys(DEFAULT_KEYMAP.values()))
    assert len(groups) == len(actions)  # every action once, in table order
    assert [(label, d) for _, label, d in groups] == [(a.label(), a.describe()) for a in actions]
    texts = {label: keys for keys, label, _ in groups}
    assert not any("Numpad" in keys for keys, _, _ in groups)
    assert texts["R_xw"] == "4" and texts["R_zw"] == "c" and texts["R_xz,yw"] == "z"
    assert texts["\u03b80+"] == "+" and texts["\u03b80\u2212"] == "-"
    assert texts["help"] == "?" and texts["level+"] == "o"


def test_help_groups_keep_a_code_only_key_and_distinct_letters():
    km = Keymap({"F1": "help", "a": "xw", "q": "xw", "NumpadAdd": "theta0+", "=": "theta0+", "+": "theta0+"})
    assert km.help_groups() == [
        ("F1", "help", "show / hide this help"),
        ("a q", "R_xw", "simple rotation R_xw by \u03b80"),
        ("+", "\u03b80+", "larger step angle \u03b80"),
    ]
    assert Keymap({"=": "theta0+", "NumpadAdd": "theta0+"}).help_groups()[0][0] == "="
    assert len(km.help_rows()) == 6  # one row per binding, as before
