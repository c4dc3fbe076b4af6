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
