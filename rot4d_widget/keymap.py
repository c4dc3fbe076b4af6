"""The paper's key tables as data, and browser-event lookup.

A :class:`Keymap` maps *key names* to :class:`Action` s.  A key name is

* a digit ``"0"``-``"9"``: bound to the **physical** key (``code`` ``"Digit2"``
  and ``"Numpad2"``), so it works on every layout whatever the key types
  (AZERTY's unshifted Digit2 types "é", US Shift+Digit2 types "@");
* any other single character (letters in lower case): bound to the **character
  typed** (``key``), so "z" is the key labelled z on QWERTY, QWERTZ and AZERTY;
* a longer name is a ``KeyboardEvent.code`` (``"NumpadAdd"``, ``"F1"``).

Shift inverts rotations (the paper's Table 1) and does nothing to other
actions.  From a browser event Shift means the ``shiftKey`` flag only, so Caps
Lock does not invert.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Mapping

from .rotation import DOUBLE_PLANES, PLANES

__all__ = ["Action", "Keymap", "DEFAULT_KEYMAP", "ACTION_NAMES"]

#: Parameter and control actions by name; rotations are named by their plane(s).
ACTION_NAMES = (
    "alpha+", "alpha-", "c0+", "c0-", "theta0+", "theta0-", "reset", "help",
)
_ACTION_KINDS = {
    "alpha+": ("alpha", +1), "alpha-": ("alpha", -1),
    "c0+": ("c0", +1), "c0-": ("c0", -1),
    "theta0+": ("theta0", +1), "theta0-": ("theta0", -1),
    "reset": ("reset", 0), "help": ("help", 0),
}
_CODE_RE = re.compile(r"^[A-Z][A-Za-z0-9]+$")
_DIGIT_CODE_RE = re.compile(r"^(?:Digit|Numpad)([0-9])$")

_SUPERSCRIPT_MINUS_ONE = "\u207b\u00b9"


@dataclass(frozen=True)
class Action:
    """What a key does.

    ``kind`` is ``"rotate"`` (``planes`` is one of ``"xy" ... "zw"`` or
    ``"xy,zw" "xz,yw" "xw,yz"``), ``"alpha"``, ``"c0"``, ``"theta0"`` (``sign``
    +1 or -1), ``"reset"`` or ``"help"``.
    """

    kind: str
    planes: str = ""
    sign: int = 0

    @classmethod
    def parse(cls, spec) -> "Action":
        """``"xw"``, ``"xz,yw"``, ``"alpha+"``, ``"c0-"``, ``"reset"`` ... or an Action."""
        if isinstance(spec, Action):
            return spec
        if isinstance(spec, str):
            if spec in PLANES or spec in DOUBLE_PLANES:
                return cls("rotate", planes=spec)
            if spec in _ACTION_KINDS:
                kind, sign = _ACTION_KINDS[spec]
                return cls(kind, sign=sign)
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
        sign = "+" if self.sign > 0 else "\u2212"
        return {"alpha": f"\u03b1{sign}", "c0": f"c0{sign}", "theta0": f"\u03b80{sign}"}.get(
            self.kind, self.kind
        )

    def describe(self) -> str:
        """A sentence for help tables."""
        if self.kind == "rotate":
            if self.is_double:
                p1, p2 = self.planes.split(",")
                return f"double rotation R_{self.planes}: {p1} by \u03b1 and {p2} by \u03b2"
            return f"simple rotation R_{self.planes} by \u03b80"
        return {
            "alpha": "raise \u03b1 (\u03b2 = \u03b80 \u2212 \u03b1 falls)" if self.sign > 0
            else "lower \u03b1 (\u03b2 = \u03b80 \u2212 \u03b1 rises)",
            "c0": "raise the slicing hyperplane w = c0" if self.sign > 0
            else "lower the slicing hyperplane w = c0",
            "theta0": "larger step angle \u03b80" if self.sign > 0 else "smaller step angle \u03b80",
            "reset": "reset orientation and parameters",
            "help": "show / hide this help",
        }[self.kind]


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
    """

    def __init__(self, bindings: Mapping):
        if not isinstance(bindings, Mapping):
            raise TypeError(f"Keymap expects a mapping of key -> action, got {type(bindings).__name__}")
        self._bindings = {_check_key_name(k): Action.parse(v) for k, v in bindings.items()}

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

    def resolve(self, key: str, shift: bool = False):
        """Scripting lookup: ``("C")`` or ``("c", shift=True)`` -> ``(action, inverted)`` or None.

        An upper-case letter counts as shifted.  A ``code`` name such as
        ``"Digit2"`` or ``"NumpadAdd"`` is accepted too.
        """
        if not isinstance(key, str):
            raise TypeError(f"Expected `key` to be a string such as '4' or 'z', got {type(key).__name__}")
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
        return action, bool(shift) and action.is_rotation

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
        return action, shift and action.is_rotation

    def help_rows(self):
        """``[(key, label, description), ...]`` in binding order, for help panels."""
        return [(k, a.label(), a.describe()) for k, a in self._bindings.items()]


#: The paper's Tables 1 and 2, plus reset "r", step angle "+"/"-" and help "?".
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
    }
)
