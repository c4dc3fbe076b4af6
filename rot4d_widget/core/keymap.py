"""The paper's key tables as data, and browser-event lookup.

A :class:`Keymap` maps *key names* to :class:`Action` s.  A key name is

* a digit ``"0"``-``"9"``: bound to the **physical** key (``code`` ``"Digit2"``
  and ``"Numpad2"``), so it works on every layout whatever the key types
  (AZERTY's unshifted Digit2 types "é", US Shift+Digit2 types "@");
* any other single character (letters in lower case): bound to the **character
  typed** (``key``), so "z" is the key labelled z on QWERTY, QWERTZ and AZERTY;
* a longer name is a ``KeyboardEvent.code`` (``"NumpadAdd"``, ``"F1"``).

Shift inverts rotations (the paper's Table 1), cycles a field's rendering
backwards and moves a section plane back (`SHIFT_KINDS`); it does nothing to other
actions.  From a browser event Shift means the ``shiftKey`` flag only, so Caps
Lock does not invert.

Besides the paper's keys the default table reserves keys for the next
features (iso level ``o``/``i``, parallel slices ``n``/``b``, slice spacing
``g``/``f``, screenshot ``p``) and binds the view's field keys (rendering ``v``, section
planes ``a``/``s``/``d``); the core gives them no meaning.  A data source
brings its own keys as ``Action("custom", ...)`` through `Keymap.extended`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .rotation import DOUBLE_PLANES, PLANES

__all__ = ["Action", "Keymap", "DEFAULT_KEYMAP", "ACTION_NAMES", "RESERVED_KINDS", "REPEATING_KINDS", "SHIFT_KINDS"]

#: Parameter and control actions by name; rotations are named by their plane(s).
ACTION_NAMES = (
    "alpha+", "alpha-", "c0+", "c0-", "theta0+", "theta0-", "reset", "help",
    "level+", "level-", "slices+", "slices-", "spacing+", "spacing-", "screenshot",
    "rendering+", "section-x", "section-y", "section-z",
)
_ACTION_KINDS = {
    "alpha+": ("alpha", +1), "alpha-": ("alpha", -1),
    "c0+": ("c0", +1), "c0-": ("c0", -1),
    "theta0+": ("theta0", +1), "theta0-": ("theta0", -1),
    "reset": ("reset", 0), "help": ("help", 0),
    "level+": ("level", +1), "level-": ("level", -1),
    "slices+": ("slices", +1), "slices-": ("slices", -1),
    "spacing+": ("spacing", +1), "spacing-": ("spacing", -1),
    "screenshot": ("screenshot", 0),
    "rendering+": ("rendering", +1),
    "section-x": ("section", +1, "x"), "section-y": ("section", +1, "y"), "section-z": ("section", +1, "z"),
}

#: Kinds bound in `DEFAULT_KEYMAP` for features still to come; `RotationState`
#: ignores them, and `Keymap.extended` may rebind their keys.
RESERVED_KINDS = frozenset({"level", "slices", "spacing", "screenshot"})

#: Kinds that repeat while their key is held (at the widget's tick rate):
#: rotations, alpha (k/j), c0 (l/h), the iso level (o/i) and the slice
#: spacing (g/f) -- continuous changes.  The others act once per press:
#: theta0 (+/-) would run away, reset/help/screenshot are one-shot, and
#: adding or removing a parallel slice (n/b) is counted by the user.
REPEATING_KINDS = frozenset({"rotate", "alpha", "c0", "level", "spacing", "section"})

#: Kinds whose Shift goes the other way: rotations (the paper's Table 1), the field rendering
#: cycle (v: surface, volume, mip, sections; Shift+v backwards) and the section planes (a, s, d
#: move the x, y, z plane up; with Shift, down).  The view acts on the last two, the core ignores them.
SHIFT_KINDS = frozenset({"rotate", "rendering", "section"})

_SIGNED_LABELS = {
    "alpha": "\u03b1", "c0": "c0", "theta0": "\u03b80", "level": "level", "slices": "slices", "spacing": "spacing",
}
_DESCRIPTIONS = {
    ("alpha", +1): "raise \u03b1 (\u03b2 = \u03b80 \u2212 \u03b1 falls)",
    ("alpha", -1): "lower \u03b1 (\u03b2 = \u03b80 \u2212 \u03b1 rises)",
    ("c0", +1): "raise the slicing hyperplane w = c0",
    ("c0", -1): "lower the slicing hyperplane w = c0",
    ("theta0", +1): "larger step angle \u03b80",
    ("theta0", -1): "smaller step angle \u03b80",
    ("reset", 0): "reset orientation and parameters",
    ("help", 0): "show / hide this help",
    ("level", +1): "raise the iso level (fields)",
    ("level", -1): "lower the iso level (fields)",
    ("slices", +1): "add a parallel slice (multi-slice view)",
    ("slices", -1): "remove a parallel slice (multi-slice view)",
    ("spacing", +1): "widen the slice spacing (multi-slice view)",
    ("spacing", -1): "narrow the slice spacing (multi-slice view)",
    ("screenshot", 0): "save a picture of the view (PNG)",
    ("rendering", 1): "next rendering of a field: surface, volume, mip, sections (Shift: the previous one)",
}
#: In help, a character typed on the same physical key as another one bound
#: to the same action is not shown ("=" next to "+", "_" next to "-").
_HELP_TWINS = {"=": "+", "_": "-"}
_CODE_RE = re.compile(r"^[A-Z][A-Za-z0-9]+$")
_LETTER_CODE_RE = re.compile(r"^Key([A-Z])$")
_DIGIT_CODE_RE = re.compile(r"^(?:Digit|Numpad)([0-9])$")

_SUPERSCRIPT_MINUS_ONE = "\u207b\u00b9"


@dataclass(frozen=True)
class Action:
    """What a key does.

    ``kind`` is ``"rotate"`` (``planes`` is one of ``"xy" ... "zw"`` or
    ``"xy,zw" "xz,yw" "xw,yz"``), ``"alpha"``, ``"c0"``, ``"theta0"`` (``sign``
    +1 or -1), ``"reset"`` or ``"help"``; the reserved ``"level"``,
    ``"slices"``, ``"spacing"`` (``sign`` +1 or -1) and ``"screenshot"``; the view's
    ``"rendering"`` and ``"section"`` (``name`` the plane's axis, "x", "y" or "z"), which Shift
    turns backwards like a rotation; or
    ``"custom"``, an action a data source brings, shown as ``name`` and
    described by ``text`` (``Action("custom", name="phase+", sign=1,
    text="advance the phase")``).
    """

    kind: str
    planes: str = ""
    sign: int = 0
    name: str = ""
    text: str = ""

    def __post_init__(self):
        if self.kind == "custom":
            if not (isinstance(self.name, str) and self.name):
                raise ValueError(
                    f"A custom action needs a `name` (a non-empty string shown in help), got {self.name!r}"
                )
            if not isinstance(self.text, str):
                raise TypeError(f"A custom action's `text` must be a string, got {type(self.text).__name__}")

    @classmethod
    def parse(cls, spec) -> "Action":
        """``"xw"``, ``"xz,yw"``, ``"alpha+"``, ``"c0-"``, ``"reset"`` ... or an Action.

        >>> Action.parse("xw")
        Action(kind='rotate', planes='xw', sign=0, name='', text='')
        >>> Action.parse("c0-").label(), Action.parse("xz,yw").describe()
        ('c0−', 'double rotation R_xz,yw: xz by α and yw by β')
        >>> Action.parse("sideways")  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Unknown action 'sideways'; expected one of 'xy', 'xz', 'xw', ...
        """
        if isinstance(spec, Action):
            return spec
        if isinstance(spec, str):
            if spec in PLANES or spec in DOUBLE_PLANES:
                return cls("rotate", planes=spec)
            if spec in _ACTION_KINDS:
                kind, sign, *name = _ACTION_KINDS[spec]
                return cls(kind, sign=sign, name=name[0] if name else "")
        allowed = ", ".join(repr(s) for s in (*PLANES, *DOUBLE_PLANES, *ACTION_NAMES))
        raise ValueError(f"Unknown action {spec!r}; expected one of {allowed}")

    @property
    def is_rotation(self) -> bool:
        return self.kind == "rotate"

    @property
    def is_double(self) -> bool:
        return self.kind == "rotate" and "," in self.planes

    def label(self, inverted: bool = False) -> str:
        """Short human name: ``"R_xw"``, ``"R_xz,yw⁻¹"``, ``"α+"``, ``"c0−"``..."""
        if self.kind == "rotate":
            return f"R_{self.planes}" + (_SUPERSCRIPT_MINUS_ONE if inverted else "")
        if self.kind == "custom":
            return self.name
        if self.kind == "rendering":
            return "rendering" + ("\u2212" if inverted else "+")
        if self.kind == "section":
            return f"section {self.name}" + ("\u2212" if inverted else "+")
        if self.kind in _SIGNED_LABELS:
            return _SIGNED_LABELS[self.kind] + ("+" if self.sign > 0 else "\u2212")
        return self.kind

    def describe(self) -> str:
        """A sentence for help tables."""
        if self.kind == "rotate":
            if self.is_double:
                p1, p2 = self.planes.split(",")
                return f"double rotation R_{self.planes}: {p1} by \u03b1 and {p2} by \u03b2"
            return f"simple rotation R_{self.planes} by \u03b80"
        if self.kind == "custom":
            return self.text or self.name
        if self.kind == "section":
            return f"move the {self.name} section plane (sections rendering of a field; Shift: back)"
        sign = 0 if self.kind in ("reset", "help", "screenshot") else (1 if self.sign > 0 else -1)
        return _DESCRIPTIONS.get((self.kind, sign), self.kind)


def _check_key_name(name) -> str:
    if not isinstance(name, str):
        raise TypeError(f"Keymap keys must be strings, got {type(name).__name__}")
    if len(name) == 1:
        if not name.isprintable() or name.isspace():
            raise ValueError(f"Keymap key {name!r} is not a printable character")
        if name != name.lower():
            raise ValueError(
                f"Keymap key {name!r}: bind the lower-case letter {name.lower()!r}; "
                "Shift gives the inverse"
            )
        return name
    if _DIGIT_CODE_RE.match(name):
        raise ValueError(f"Keymap key {name!r}: bind the digit {name[-1]!r}, which covers Digit and Numpad")
    if not _CODE_RE.match(name):
        raise ValueError(
            f"Keymap key {name!r} is neither a single character (e.g. 'c', '4', '?') "
            "nor a KeyboardEvent.code (e.g. 'NumpadAdd', 'F1')"
        )
    return name


class Keymap(Mapping):
    """Key name -> :class:`Action`; an immutable mapping.

    ``Keymap({"4": "xw", "z": "xz,yw", "l": "c0+"})``.  See the module docstring
    for what a key name binds.

    >>> km = Keymap({"4": "xw", "z": "xz,yw", "l": "c0+"})
    >>> km["4"].label(), km.resolve("Z")[0].planes, km.resolve("Z")[1]  # upper case: shifted, inverted
    ('R_xw', 'xz,yw', True)
    >>> km.lookup({"key": "$", "code": "Digit4", "shiftKey": True})[0].label()  # digits by their physical key
    'R_xw'
    >>> Keymap({"T": "xw"})
    Traceback (most recent call last):
    ...
    ValueError: Keymap key 'T': bind the lower-case letter 't'; Shift gives the inverse
    """

    def __init__(self, bindings: Mapping):
        if not isinstance(bindings, Mapping):
            raise TypeError(f"Keymap expects a mapping of key -> action, got {type(bindings).__name__}")
        self._bindings = {_check_key_name(k): Action.parse(v) for k, v in bindings.items()}
        for k, a in self._bindings.items():  # one physical key, two names: which would win is not ours to guess
            m = _LETTER_CODE_RE.match(k) or _DIGIT_CODE_RE.match(k)
            twin = m.group(1).lower() if m else None
            if twin is not None and twin in self._bindings and self._bindings[twin] != a:
                raise ValueError(f"Keymap binds both {twin!r} and {k!r} (the same key) to different actions: "
                                 f"bind one of them")

    def __getitem__(self, key: str) -> Action:
        return self._bindings[key]

    def __iter__(self):
        return iter(self._bindings)

    def __len__(self) -> int:
        return len(self._bindings)

    def __repr__(self) -> str:
        body = ", ".join(
            f"{k!r}: {a.planes if a.is_rotation else a.label()!r}" for k, a in self._bindings.items()
        )
        return f"Keymap({{{body}}})"

    def replace(self, **changes) -> "Keymap":
        """A copy with some bindings changed; a value of None removes a key."""
        new = dict(self._bindings)
        for k, v in changes.items():
            if v is None:
                new.pop(k, None)
            else:
                new[k] = v
        return Keymap(new)

    def extended(self, bindings: Mapping) -> "Keymap":
        """A copy with extra bindings, e.g. a data source's ``Action("custom", ...)`` s.

        ``bindings`` maps key names (as in the constructor) to actions.  A key
        may be new, or one bound to a reserved kind (``"level"``, ``"slices"``,
        ``"spacing"``, ``"screenshot"``: features still to come).  Any other
        bound key -- the paper's keys, reset, help, theta0 -- raises
        ``ValueError`` naming the key and its action, and so does a code
        ``"KeyX"`` while the letter ``x`` is bound to such an action (the code
        would take precedence over the letter on most layouts).
        """
        extra = Keymap(bindings)._bindings  # checks names and actions like the constructor
        for key in extra:
            current = self._bindings.get(key)
            if current is not None and current.kind not in RESERVED_KINDS:
                raise ValueError(
                    f"Key {key!r} is already bound to {current.label()} ({current.describe()}); "
                    f"only keys of the reserved kinds {', '.join(sorted(RESERVED_KINDS))} or unbound keys "
                    "can be extended -- use Keymap.replace to rebind it on purpose"
                )
            if len(key) == 4 and key.startswith("Key"):
                shadowed = self._bindings.get(key[3].lower())
                if shadowed is not None and shadowed.kind not in RESERVED_KINDS:
                    raise ValueError(
                        f"Key {key!r} would shadow {key[3].lower()!r}, bound to {shadowed.label()} "
                        f"({shadowed.describe()}); bind the character instead"
                    )
        return Keymap({**self._bindings, **extra})

    def resolve(self, key: str, shift: bool = False):
        """Scripting lookup: ``("C")`` or ``("c", shift=True)`` -> ``(action, inverted)`` or None.

        An upper-case letter counts as shifted.  A ``code`` name such as
        ``"Digit2"`` or ``"NumpadAdd"`` is accepted too.  ``shift`` must be a
        bool (or numpy bool): ``TypeError`` otherwise.
        """
        if not isinstance(key, str):
            raise TypeError(f"Expected `key` to be a string such as '4' or 'z', got {type(key).__name__}")
        if not isinstance(shift, (bool, np.bool_)):
            raise TypeError(f"Expected `shift` to be a bool (True or False), got {type(shift).__name__} {shift!r}")
        if len(key) == 1:
            lower = key.lower()
            if lower != key:
                shift = True
            action = self._bindings.get(lower)
        else:
            m = _DIGIT_CODE_RE.match(key)
            action = self._bindings.get(m.group(1) if m else key)
        if action is None:
            return None
        return action, bool(shift) and action.kind in SHIFT_KINDS

    def lookup(self, event: Mapping):
        """Browser key event -> ``(action, inverted)`` or None.

        ``event`` is the dict ipyevents sends (``key``, ``code``, ``shiftKey``,
        ...).  Digits are found by ``code``, other keys by the character
        typed; Ctrl/Alt/Meta chords are not ours (None).  Malformed events
        (not a mapping, non-string fields) give None, never an exception.
        """
        if not isinstance(event, Mapping):
            return None
        if event.get("ctrlKey") or event.get("altKey") or event.get("metaKey"):
            return None
        code = event.get("code") or ""
        key = event.get("key") or ""
        if not isinstance(code, str) or not isinstance(key, str):
            return None
        shift = event.get("shiftKey") is True
        action = None
        m = _DIGIT_CODE_RE.match(code)
        if m:
            action = self._bindings.get(m.group(1))
        if action is None and code and len(code) > 1:
            action = self._bindings.get(code) if not m else None
        if action is None and len(key) == 1:
            action = self._bindings.get(key.lower())
        if action is None:
            return None
        return action, shift and action.kind in SHIFT_KINDS

    def help_rows(self):
        """``[(key, label, description), ...]`` in binding order, one row per binding."""
        return [(k, a.label(), a.describe()) for k, a in self._bindings.items()]

    def help_groups(self):
        """``[(keys_text, label, description), ...]``: one row per distinct action, in table order.

        The keys of one action are collapsed to what a reader types: a digit
        once (it covers Digit and Numpad), ``"+"`` without its twin ``"="``
        and ``"-"`` without ``"_"``, and codes such as ``"NumpadAdd"`` only
        when no single character is bound to the action (``"F1"`` alone is
        kept).  Several distinct characters are joined by spaces (``"a q"``).
        """
        keys_of: dict = {}
        for key, action in self._bindings.items():
            keys_of.setdefault(action, []).append(key)
        rows = []
        for action, keys in keys_of.items():
            chars = [k for k in keys if len(k) == 1]
            shown = [k for k in chars if _HELP_TWINS.get(k) not in chars] if chars else keys
            rows.append((" ".join(shown), action.label(), action.describe()))
        return rows


#: The paper's Tables 1 and 2, plus reset "r", step angle "+"/"-", help "?", and
#: the keys reserved for the next features (letters by the character typed).
DEFAULT_KEYMAP = Keymap(
    {
        # Table 1: simple rotations, key = product of the axis numbers (hex)
        "2": "xy", "3": "xz", "4": "xw", "6": "yz", "8": "yw", "c": "zw",
        # Table 1: double rotations, key = x's counterpart
        "y": "xy,zw", "z": "xz,yw", "w": "xw,yz",
        # Table 2: parameters (vi convention)
        "k": "alpha+", "j": "alpha-", "l": "c0+", "h": "c0-",
        # additions, none colliding with the paper's keys
        "r": "reset",
        "+": "theta0+", "=": "theta0+", "NumpadAdd": "theta0+",
        "-": "theta0-", "_": "theta0-", "NumpadSubtract": "theta0-",
        "?": "help",
        # reserved for the next features; the core ignores them
        "o": "level+", "i": "level-",  # a field's iso level
        "n": "slices+", "b": "slices-",  # parallel slices
        "g": "spacing+", "f": "spacing-",  # their spacing
        "p": "screenshot",  # a PNG of the view
        "v": "rendering+",  # a field's rendering: surface, volume, mip, sections
        "a": "section-x", "s": "section-y", "d": "section-z",  # the sections' planes
    }
)
