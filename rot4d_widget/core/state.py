"""`RotationState`: the orientation of the 4-D object and the paper's parameters.

Defaults (documented in the README):

* ``theta0 = pi/64`` rad (2.8125 deg): the step of every rotation key.  Small
  enough to look continuous at the widget's 30 Hz tick (84 deg/s), and simple
  rotations return to the identity after exactly 128 steps.
* ``alpha = theta0 * PAPER_ALPHA_RATIO`` with ``PAPER_ALPHA_RATIO =
  pi*sqrt(2)/(8*sqrt(3))``: the ratio of the paper's Fig. 4 (alpha/theta0
  irrational, so a held double rotation never returns).  ``beta = theta0 - alpha``.
* "k"/"j" change alpha by ``theta0 * ALPHA_STEP_FRACTION`` (1/32) keeping
  alpha + beta = theta0; both may go negative.
* "l"/"h" change c0 by ``c0_step`` (default 0.02; the widget uses 1/64 of the
  polytope's circumradius).
* "+"/"-" multiply/divide theta0 by ``THETA0_FACTOR`` (sqrt 2), keeping alpha/theta0.

**Bounds of the repeating keys.**  A key step that would leave its range is refused
(``apply`` returns False, nothing changes), never clamped, so the opposite key always
undoes a step that was made: theta0 stays in [`THETA0_MIN`, `THETA0_MAX`] = [pi/2^20, pi];
alpha and beta in [-pi, pi] (`ALPHA_MAX`); c0 within ``c0_limit`` of ``c0_origin`` (default
infinite about 0; the widget sets the source's w frame: twice its size, in its w units, about
its centre), where a c0 set outside by hand may still step back towards the range.

**Units of c0.**  c0 and ``c0_step`` are in the source's w units -- a polytope's own w, a
field's data w (seconds for a time axis in seconds: at rest c0 = 30 cuts at t = 30 s); the
state itself is unit-free and only keeps the numbers.

``to_dict()`` / ``from_dict(d)`` turn a state into JSON-able data and back, exactly (floats
are written with Python's shortest round-tripping repr): the orientation, theta0, alpha, c0,
the c0 step and the key bindings.  A state read with ``from_dict`` is also where ``reset()``
goes back to.
"""

from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from . import tolerances as tol_
from ._arrays import sealed
from .keymap import ACTION_NAMES, DEFAULT_KEYMAP, Action, Keymap
from .rotation import (
    as_rotation_matrix,
    double_rotation,
    reorthonormalize,
    simple_rotation,
)
from .validate import positive, real

__all__ = [
    "RotationState",
    "check_theta0",
    "DEFAULT_THETA0",
    "PAPER_ALPHA_RATIO",
    "ALPHA_STEP_FRACTION",
    "DEFAULT_C0_STEP",
    "THETA0_FACTOR",
    "THETA0_MIN",
    "THETA0_MAX",
    "ALPHA_MAX",
    "STATE_FORMAT",
    "spacing_factor",
    "action_to_data",
    "action_from_data",
    "keymap_to_dict",
    "keymap_from_dict",
    "without_source_keys",
]

#: The version of `RotationState.to_dict`'s layout (``d["format"]``).  2: c0 and its step are in
#: the source's w units (a field's data w, `rot4d_widget.sources.protocol.w_frame`); 1 had them in the drawn
#: (slice) units -- `RotationState.from_dict` converts them given the source's ``w_frame``.  3: the same
#: state, and the spacing of parallel slices saved beside it (a state file's settings, a recording's
#: source settings) is in those w units too; up to 2 it was in the drawn units (`spacing_factor`).
STATE_FORMAT = 3
#: A loaded orientation this close to orthogonal (max |M M^T - I|) is taken as it is;
#: further off, up to `rotation.ORTHOGONALITY_TOLERANCE`, it is re-orthonormalised.
_EXACT_ENOUGH = tol_.ORTHOGONAL_TO_ROUNDING

DEFAULT_THETA0 = math.pi / 64
PAPER_ALPHA_RATIO = math.pi * math.sqrt(2.0) / (8.0 * math.sqrt(3.0))
ALPHA_STEP_FRACTION = 1.0 / 32.0
DEFAULT_C0_STEP = 0.02
THETA0_FACTOR = math.sqrt(2.0)
THETA0_MAX = math.pi
#: The smallest theta0 the "-" key reaches (pi / 2**20 rad): far below what a person sees.
THETA0_MIN = math.pi / 2**20
#: k / j keep |alpha| and |beta| within this (radians).
ALPHA_MAX = math.pi


def check_alpha_beta(alpha: float, theta0: float, what: str) -> None:
    """ValueError unless |alpha| and |beta| = |theta0 - alpha| are within `ALPHA_MAX`."""
    if not (abs(alpha) <= ALPHA_MAX and abs(theta0 - alpha) <= ALPHA_MAX):
        raise ValueError(f"{what} gives alpha = {alpha:.6g}, beta = {theta0 - alpha:.6g}: expected both "
                         f"in [-pi, pi] radians")


def _check_c0_steps(c0: float, step: float) -> None:
    """ValueError when a step of ``step`` cannot move ``c0`` (c0 + step == c0 or c0 - step == c0): a
    c0 of 1e308 from a state file could then never be stepped back by h / l.  c0 may lie outside
    the keys' range (set by hand, stepped back), but only where the keys move it."""
    if c0 + step == c0 or c0 - step == c0:
        raise ValueError(f"Expected `c0` where its step {step:.6g} moves it (|c0| below about "
                         f"{step * 2.0 ** 52:.3g}), got {c0!r}: the l / h keys could never bring it back")


def check_theta0(value) -> float:
    """A step angle theta0 as a float in (0, `THETA0_MAX`] radians; else TypeError/ValueError naming
    what is allowed.  The check of `RotationState.theta0` and the view's `Angle` trait.

    >>> check_theta0(0.5)
    0.5
    >>> check_theta0(4.0)
    Traceback (most recent call last):
    ...
    ValueError: Expected `theta0` in (0, pi] radians, got 4.0
    """
    value = real(value, "theta0")
    if not 0.0 < value <= THETA0_MAX:
        raise ValueError(f"Expected `theta0` in (0, pi] radians, got {value}")
    return value


class RotationState:
    """Orientation (4x4 rotation), step angle theta0, alpha/beta, slice level c0.

    ``press(key, shift=False)`` applies one step of the key's action;
    rotations compose extrinsically (``matrix = step @ matrix``) and the
    matrix is re-orthonormalised after every step.

    ``matrix`` is a read-only array that every step *replaces* (never edits),
    so an array read earlier keeps its values, reading it twice without a
    step in between gives the same object (callers may cache on ``is``), and
    assigning ``state.matrix = m`` copies ``m`` after validating it.
    """

    def __init__(
        self,
        theta0: float = DEFAULT_THETA0,
        alpha: float | None = None,
        c0: float = 0.0,
        *,
        keymap: Keymap = DEFAULT_KEYMAP,
        c0_step: float = DEFAULT_C0_STEP,
        matrix=None,
        c0_limit: float = math.inf,
        c0_origin: float = 0.0,
    ):
        if not isinstance(keymap, Keymap):
            raise TypeError(f"Expected `keymap` to be a rot4d_widget.Keymap, got {type(keymap).__name__}")
        self.keymap = keymap
        self._theta0 = check_theta0(theta0)
        self._alpha = self._theta0 * PAPER_ALPHA_RATIO if alpha is None else real(alpha, "alpha")
        check_alpha_beta(self._alpha, self._theta0, f"alpha = {self._alpha:.6g}")
        self._c0 = real(c0, "c0")
        self.c0_step = c0_step  # checks that the step can move c0 (`_check_c0_steps`)
        self.c0_limit = c0_limit
        self.c0_origin = c0_origin
        self._matrix = sealed(np.eye(4) if matrix is None else as_rotation_matrix(matrix))
        self._initial = (self._theta0, self._alpha, self._c0, self._matrix)
        self._steps: dict = {}

    # -- parameters ---------------------------------------------------------
    @property
    def matrix(self) -> np.ndarray:
        """(4, 4) float64 orientation, read-only; points rotate as ``vertices @ matrix.T``.

        The same object until the next step or assignment replaces it.
        """
        return self._matrix

    @matrix.setter
    def matrix(self, value) -> None:
        self._matrix = sealed(as_rotation_matrix(value))  # validated copy

    @property
    def theta0(self) -> float:
        return self._theta0

    @theta0.setter
    def theta0(self, value) -> None:
        value = check_theta0(value)
        alpha = self._alpha * (value / self._theta0)  # keep alpha/theta0
        check_alpha_beta(alpha, value, f"theta0 = {value:.6g} (alpha keeps its ratio to theta0)")
        self._alpha = alpha
        self._theta0 = value
        self._steps.clear()

    @property
    def alpha(self) -> float:
        return self._alpha

    @alpha.setter
    def alpha(self, value) -> None:
        value = real(value, "alpha")
        check_alpha_beta(value, self._theta0, f"alpha = {value:.6g}")
        self._alpha = value
        self._steps.clear()

    @property
    def beta(self) -> float:
        """Always ``theta0 - alpha``."""
        return self._theta0 - self._alpha

    @property
    def c0(self) -> float:
        return self._c0

    @c0.setter
    def c0(self, value) -> None:
        value = real(value, "c0")
        _check_c0_steps(value, self._c0_step)
        self._c0 = value

    @property
    def c0_step(self) -> float:
        return self._c0_step

    @c0_step.setter
    def c0_step(self, value) -> None:
        value = positive(value, "c0_step")
        _check_c0_steps(self._c0, value)
        self._c0_step = value

    @property
    def c0_limit(self) -> float:
        """The l / h keys keep |c0 - c0_origin| within this (inf: no limit); setting c0 directly is
        not limited."""
        return self._c0_limit

    @property
    def c0_origin(self) -> float:
        """The centre of the l / h keys' range (`c0_limit`): the source's w at its centre."""
        return self._c0_origin

    @c0_origin.setter
    def c0_origin(self, value) -> None:
        self._c0_origin = real(value, "c0_origin")

    @c0_limit.setter
    def c0_limit(self, value) -> None:
        self._c0_limit = positive(value, "c0_limit", what="a number > 0 (or inf)", finite=False,
                                  must="> 0 (or inf)")

    def snapshot(self) -> tuple:
        """``(matrix, theta0, alpha, c0)`` now: what `restore_snapshot` sets back exactly."""
        return (self._matrix, self._theta0, self._alpha, self._c0)

    def restore_snapshot(self, snap: tuple) -> None:
        """Set the orientation, theta0, alpha and c0 to a `snapshot` of this state, exactly (the
        matrix object is shared: matrices are never edited)."""
        self._matrix, self._theta0, self._alpha, self._c0 = snap
        self._steps.clear()

    @property
    def reset_point(self) -> tuple:
        """``(theta0, alpha, c0, matrix)``: the state `reset` returns to (as made, or as restored)."""
        return self._initial

    @property
    def alpha_step(self) -> float:
        """How much "k"/"j" change alpha: ``theta0 * ALPHA_STEP_FRACTION``."""
        return self._theta0 * ALPHA_STEP_FRACTION

    # -- actions ------------------------------------------------------------
    def step_matrix(self, action: Action, inverted: bool = False) -> np.ndarray:
        """The (4, 4) matrix (read-only, cached) one press of a rotation ``action`` applies."""
        cache_key = (action.planes, inverted)
        m = self._steps.get(cache_key)
        if m is None:
            sign = -1.0 if inverted else 1.0
            if action.is_double:
                m = double_rotation(action.planes, sign * self._alpha, sign * self.beta)
            else:
                m = simple_rotation(action.planes, sign * self._theta0)
            m = self._steps[cache_key] = sealed(m)
        return m

    def apply(self, action: Action, inverted: bool = False) -> bool:
        """Apply one step of ``action``; True if the state changed."""
        kind = action.kind
        if kind == "rotate":
            # a new array each step: arrays handed out before are never edited
            self._matrix = sealed(reorthonormalize(self.step_matrix(action, inverted) @ self._matrix))
        elif kind == "alpha":
            new = self._alpha + action.sign * self.alpha_step
            if not (abs(new) <= ALPHA_MAX and abs(self._theta0 - new) <= ALPHA_MAX):
                return False  # refused, not clamped: the opposite key undoes every step made
            self.alpha = new
        elif kind == "c0":
            step = self._c0_step
            new = self._c0 + action.sign * step
            o = self._c0_origin
            if abs(new - o) > self._c0_limit and abs(new - o) >= abs(self._c0 - o):
                return False
            if new + step == new or new - step == new:
                return False  # where the step would no longer move c0: refused (`_check_c0_steps`)
            self.c0 = new
        elif kind == "theta0":
            new = self._theta0 * THETA0_FACTOR if action.sign > 0 else self._theta0 / THETA0_FACTOR
            ratio = self._alpha / self._theta0
            if not (THETA0_MIN <= new <= THETA0_MAX and abs(ratio * new) <= ALPHA_MAX
                    and abs((1.0 - ratio) * new) <= ALPHA_MAX):
                return False
            self.theta0 = new
        elif kind == "reset":
            self.reset()
        else:  # "help", the reserved "level" "slices" "spacing" "screenshot", "custom":
            return False  # the widget or a data source acts on them, the core has no meaning for them
        return True

    def press(self, key: str, shift: bool = False) -> bool:
        """One step of the action bound to ``key``; False (and no change) if unbound.

        An upper-case letter counts as shifted (``press("C")`` is R_zw
        inverted).  Shift inverts rotations and is ignored by parameter keys.
        ``shift`` must be a bool (``True``/``False`` or a numpy bool): a
        ``TypeError`` otherwise.

        >>> st = RotationState(theta0=0.1)
        >>> st.press("4"), np.allclose(st.matrix, simple_rotation("xw", 0.1))
        (True, True)
        >>> st.press("4", shift=True), np.allclose(st.matrix, np.eye(4))  # Shift inverts
        (True, True)
        >>> st.press("l"), st.c0, st.press("Q")  # "l" raises c0 by c0_step; "q" is unbound
        (True, 0.02, False)
        """
        found = self.keymap.resolve(key, shift)
        if found is None:
            return False
        return self.apply(*found)

    def reset(self) -> None:
        """Back to the initial state (orientation, theta0, alpha, c0): the state as constructed,
        or as read by `from_dict` / `restore`."""
        self._theta0, self._alpha, self._c0, m = self._initial
        self._matrix = sealed(m.copy())  # a new object, like every step
        self._steps.clear()

    # -- to and from JSON-able data -------------------------------------------
    def to_dict(self, *, initial: bool = False) -> dict:
        """The state as JSON-able data (lists, floats, strings); `from_dict` reads it back exactly.

        ``{"format": 3, "orientation": 4 x 4 list (rows), "theta0", "alpha", "c0", "c0_step",
        "keymap": {key: action}}``; an action is its name as `Action.parse` reads it
        (``"xw"``, ``"xz,yw"``, ``"c0+"`` ...) or, for a source's own action, a dict of the
        `Action` fields.  ``initial=True`` adds ``"initial"``: the state `reset` returns to
        (orientation, theta0, alpha, c0) -- recordings keep it so that a recorded reset replays
        the same; state files leave it out, so the state they hold becomes the reset point.

        >>> d = RotationState(theta0=0.1, c0=0.5).to_dict()
        >>> d["format"], d["theta0"], d["c0"], d["keymap"]["4"], d["orientation"][0]
        (3, 0.1, 0.5, 'xw', [1.0, 0.0, 0.0, 0.0])
        >>> RotationState.from_dict(d).c0
        0.5
        """
        d = {
            "format": STATE_FORMAT,
            "orientation": np.asarray(self._matrix).tolist(),
            "theta0": self._theta0,
            "alpha": self._alpha,
            "c0": self._c0,
            "c0_step": self._c0_step,
            "keymap": keymap_to_dict(self.keymap),
        }
        if initial:
            t, a, c, m = self._initial
            d["initial"] = {"orientation": np.asarray(m).tolist(), "theta0": t, "alpha": a, "c0": c}
        return d

    @classmethod
    def from_dict(cls, d, *, keymap: Keymap | None = None, w_frame=None) -> "RotationState":
        """A state from `to_dict`'s data (a dict, e.g. read from JSON).

        The orientation is validated: within 1e-6 of orthogonal (max |M M^T - I|) it is
        re-orthonormalised (`rotation.reorthonormalize`, repeated until orthogonal to
        rounding), further off -- or a reflection, or not 4 x 4 -- ``ValueError`` says how far
        it is.  Missing fields take their defaults (the default keymap, ``c0_step`` 0.02);
        unknown fields, or a newer ``format``, are refused.  ``keymap`` replaces the stored
        bindings.  The state read is what `reset` returns to (unless ``d`` has ``"initial"``).

        ``w_frame``: the source's ``(origin, per_unit)`` (`rot4d_widget.sources.protocol.w_frame`); a
        format-1 state (c0 in slice units) has its c0 (and initial c0) converted to ``origin +
        per_unit * c0`` and its c0 step multiplied by ``per_unit``.  Without it a format-1 state is
        read as it is (right for a polytope, whose frame is (0, 1)).
        """
        if not isinstance(d, Mapping):
            raise TypeError(f"Expected a dict from RotationState.to_dict, got {type(d).__name__}")
        unknown = sorted(set(d) - _DICT_KEYS)
        if unknown:
            raise ValueError(f"Unknown state field(s) {', '.join(map(repr, unknown))}; expected some of "
                             f"{', '.join(sorted(_DICT_KEYS))}")
        fmt = d.get("format", STATE_FORMAT)
        if isinstance(fmt, bool) or not isinstance(fmt, int) or not 1 <= fmt <= STATE_FORMAT:
            raise ValueError(f"Unsupported state format {fmt!r}; this version reads format 1 ... {STATE_FORMAT}")
        if "orientation" not in d:
            raise ValueError("A state needs its 'orientation' (a 4 x 4 list of rows)")
        if keymap is None:
            keymap = keymap_from_dict(d["keymap"]) if "keymap" in d else DEFAULT_KEYMAP
        kwargs = {k: d[k] for k in ("theta0", "alpha", "c0", "c0_step") if k in d}
        origin, per = _old_units(fmt, w_frame)
        if "c0" in kwargs:
            kwargs["c0"] = origin + per * real(kwargs["c0"], "c0")
        if "c0_step" in kwargs:
            kwargs["c0_step"] = per * real(kwargs["c0_step"], "c0_step")
        state = cls(keymap=keymap, matrix=_loaded_rotation(d["orientation"], "orientation"), **kwargs)
        if "initial" in d:
            init = d["initial"]
            if not isinstance(init, Mapping) or set(init) != {"orientation", "theta0", "alpha", "c0"}:
                raise ValueError("Expected 'initial' to hold 'orientation', 'theta0', 'alpha' and 'c0'")
            state._initial = (check_theta0(init["theta0"]), real(init["alpha"], "initial alpha"),
                              origin + per * real(init["c0"], "initial c0"),
                              sealed(_loaded_rotation(init["orientation"], "initial orientation")))
        return state

    def restore(self, d, *, w_frame=None) -> None:
        """Set this state (in place) from `to_dict`'s data, as `from_dict` reads it (``w_frame``
        converts a format-1 c0); it becomes what `reset` returns to.  The keymap is kept unless
        ``d`` has one; the c0 range (`c0_limit`, `c0_origin`) is kept."""
        other = type(self).from_dict(d, keymap=None if "keymap" in d else self.keymap, w_frame=w_frame)
        self.keymap = other.keymap
        self._theta0, self._alpha, self._c0, self._c0_step = other._theta0, other._alpha, other._c0, other._c0_step
        self._matrix = other._matrix
        self._initial = other._initial
        self._steps.clear()

    def copy(self) -> "RotationState":
        """An independent state with the same values, keymap, reset point and c0 range."""
        new = type(self).from_dict(self.to_dict(initial=True), keymap=self.keymap)
        new.c0_limit = self._c0_limit
        new.c0_origin = self._c0_origin
        return new

    def __repr__(self) -> str:
        return (
            f"RotationState(theta0={self._theta0:.6g}, alpha={self._alpha:.6g}, "
            f"beta={self.beta:.6g}, c0={self._c0:.6g})"
        )


# ----------------------------------------------------------------------------- data helpers
def spacing_factor(fmt, w_frame) -> float:
    """What a parallel-slice spacing saved beside a state of format ``fmt`` is multiplied by to be
    in today's units, the source's w units (format 3): its ``per_unit`` (`w_frame`) for format 1
    or 2 (spacing in the drawn units then), else 1.

    >>> spacing_factor(2, (30.0, 12.5)), spacing_factor(3, (30.0, 12.5)), spacing_factor(2, None)
    (12.5, 1.0, 1.0)
    """
    if isinstance(fmt, bool) or not isinstance(fmt, int) or fmt >= 3 or w_frame is None:
        return 1.0
    return _old_units(1, w_frame)[1]


def _old_units(fmt: int, w_frame) -> tuple:
    """(origin, per_unit) that turn a format-``fmt`` c0 into today's: identity for format 2."""
    if fmt >= 2 or w_frame is None:
        return 0.0, 1.0
    try:
        origin, per = (float(v) for v in w_frame)
    except (TypeError, ValueError):
        raise TypeError(f"Expected `w_frame` to be (origin, per_unit), two numbers, got {w_frame!r}") from None
    if not (math.isfinite(origin) and math.isfinite(per) and per > 0):
        raise ValueError(f"Expected `w_frame` (origin, per_unit) finite with per_unit > 0, got {w_frame!r}")
    return origin, per


_DICT_KEYS = frozenset({"format", "orientation", "theta0", "alpha", "c0", "c0_step", "keymap", "initial"})
_ACTION_FIELDS = ("kind", "planes", "sign", "name", "text")


def _loaded_rotation(value, name: str) -> np.ndarray:
    """A stored orientation: exact if orthogonal to rounding, re-orthonormalised within 1e-6, else refused."""
    try:
        m = as_rotation_matrix(value, name)  # (4, 4), finite, within 1e-6 of orthogonal, det +1, a fresh copy
    except TypeError as exc:
        raise ValueError(str(exc)) from None  # from_dict refuses bad data with ValueError
    for _ in range(4):  # Newton-Schulz squares the error: 1e-6 -> 1e-12 -> rounding
        if float(np.abs(m @ m.T - np.eye(4)).max()) <= _EXACT_ENOUGH:
            break
        m = reorthonormalize(m)
    return m


def action_to_data(action: Action):
    """An `Action` as JSON-able data: its `Action.parse` name when that gives it back, else a dict."""
    if not isinstance(action, Action):
        raise TypeError(f"Expected a rot4d_widget.Action, got {type(action).__name__}")
    if action.kind == "rotate":
        spec = action.planes
    elif action.kind == "custom":
        spec = None
    else:
        spec = _spec_name(action)
    if spec is not None:
        try:
            if Action.parse(spec) == action:
                return spec
        except ValueError:
            pass
    return {f: getattr(action, f) for f in _ACTION_FIELDS}


def _spec_name(action: Action):
    for name in ACTION_NAMES:
        if Action.parse(name) == action:
            return name
    return None


def action_from_data(data) -> Action:
    """`action_to_data`'s output back to the `Action`; ValueError names what is wrong."""
    if isinstance(data, str):
        return Action.parse(data)
    if isinstance(data, Mapping):
        unknown = sorted(set(data) - set(_ACTION_FIELDS))
        if unknown or "kind" not in data:
            raise ValueError(f"Expected an action dict with 'kind' and some of {', '.join(_ACTION_FIELDS)}, "
                             f"got {dict(data)!r}")
        sign = data.get("sign", 0)
        if isinstance(sign, bool) or not isinstance(sign, int):
            raise ValueError(f"Expected an action's 'sign' to be an int, got {sign!r}")
        for f in ("kind", "planes", "name", "text"):
            if not isinstance(data.get(f, ""), str):
                raise ValueError(f"Expected an action's {f!r} to be a string, got {data[f]!r}")
        return Action(data["kind"], planes=data.get("planes", ""), sign=sign, name=data.get("name", ""),
                      text=data.get("text", ""))
    raise ValueError(f"Expected an action name such as 'xw' or an action dict, got {data!r}")


def keymap_to_dict(keymap: Keymap) -> dict:
    """``{key: action data}`` in binding order (`action_to_data`)."""
    return {k: action_to_data(a) for k, a in keymap.items()}


def keymap_from_dict(d) -> Keymap:
    """`keymap_to_dict`'s output back to a `Keymap` (same bindings, same order)."""
    if not isinstance(d, Mapping):
        raise ValueError(f"Expected 'keymap' to be a dict of key -> action, got {type(d).__name__}")
    return Keymap({k: action_from_data(v) for k, v in d.items()})


def without_source_keys(keymap: Keymap) -> Keymap:
    """``keymap`` without a source's own actions (``Action("custom", ...)``): each such key gets back
    its `DEFAULT_KEYMAP` binding (a reserved one: o/i, n/b, g/f) or is unbound.  A stored keymap
    passes through this before a widget extends it with its source's actions again
    (`Keymap.extended` refuses to rebind a key a custom action holds)."""
    changes = {k: DEFAULT_KEYMAP.get(k) for k, a in keymap.items() if a.kind == "custom"}
    return keymap.replace(**changes) if changes else keymap
