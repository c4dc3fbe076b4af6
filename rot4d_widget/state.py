"""`RotationState`: the orientation of the 4-D object and the paper's parameters.

Defaults (documented in the README):

* ``theta0 = pi/64`` rad (2.8125 deg): the step of every rotation key.  Small
  enough to look continuous at the widget's 30 Hz tick (84 deg/s), and simple
  rotations return to the identity after exactly 128 steps.
* ``alpha = theta0 * PAPER_ALPHA_RATIO`` with ``PAPER_ALPHA_RATIO =
  pi*sqrt(2)/(8*sqrt(3))``: the ratio of the paper's Fig. 4 (alpha/theta0
  irrational, so a held double rotation never returns).  ``beta = theta0 - alpha``.
* "k"/"j" change alpha by ``theta0 * ALPHA_STEP_FRACTION`` (1/32) keeping
  alpha + beta = theta0; nothing clamps alpha or beta (both may go negative).
* "l"/"h" change c0 by ``c0_step`` (default 0.02; the widget uses 1/64 of the
  polytope's circumradius).
* "+"/"-" multiply/divide theta0 by ``THETA0_FACTOR`` (sqrt 2), keeping alpha/theta0;
  theta0 stays within (0, pi].
"""

from __future__ import annotations

import math

import numpy as np

from .keymap import DEFAULT_KEYMAP, Action, Keymap
from .rotation import as_rotation_matrix, double_rotation, reorthonormalize, simple_rotation

__all__ = [
    "RotationState",
    "DEFAULT_THETA0",
    "PAPER_ALPHA_RATIO",
    "ALPHA_STEP_FRACTION",
    "DEFAULT_C0_STEP",
    "THETA0_FACTOR",
]

DEFAULT_THETA0 = math.pi / 64
PAPER_ALPHA_RATIO = math.pi * math.sqrt(2.0) / (8.0 * math.sqrt(3.0))
ALPHA_STEP_FRACTION = 1.0 / 32.0
DEFAULT_C0_STEP = 0.02
THETA0_FACTOR = math.sqrt(2.0)
THETA0_MAX = math.pi


def _finite(name: str, value) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a real number, got {type(value).__name__}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"Expected `{name}` to be finite, got {value}")
    return value


def _read_only(m: np.ndarray) -> np.ndarray:
    """A freshly made array, read-only behind a read-only view (no copy): what is
    handed out can be neither written, nor resized, nor made writable again."""
    if m.base is not None:  # a view (not made here): its base could be unlocked
        m = m.copy()
    m.flags.writeable = False
    v = m.view()
    v.flags.writeable = False
    return v


def _theta0(value) -> float:
    value = _finite("theta0", value)
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
    ):
        if not isinstance(keymap, Keymap):
            raise TypeError(f"Expected `keymap` to be a rot4d_widget.Keymap, got {type(keymap).__name__}")
        self.keymap = keymap
        self._theta0 = _theta0(theta0)
        self._alpha = self._theta0 * PAPER_ALPHA_RATIO if alpha is None else _finite("alpha", alpha)
        self._c0 = _finite("c0", c0)
        self.c0_step = c0_step
        self._matrix = _read_only(np.eye(4) if matrix is None else as_rotation_matrix(matrix))
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
        self._matrix = _read_only(as_rotation_matrix(value))  # validated copy

    @property
    def theta0(self) -> float:
        return self._theta0

    @theta0.setter
    def theta0(self, value) -> None:
        value = _theta0(value)
        self._alpha *= value / self._theta0  # keep alpha/theta0
        self._theta0 = value
        self._steps.clear()

    @property
    def alpha(self) -> float:
        return self._alpha

    @alpha.setter
    def alpha(self, value) -> None:
        self._alpha = _finite("alpha", value)
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
        self._c0 = _finite("c0", value)

    @property
    def c0_step(self) -> float:
        return self._c0_step

    @c0_step.setter
    def c0_step(self, value) -> None:
        value = _finite("c0_step", value)
        if value <= 0:
            raise ValueError(f"Expected `c0_step` > 0, got {value}")
        self._c0_step = value

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
            m = self._steps[cache_key] = _read_only(m)
        return m

    def apply(self, action: Action, inverted: bool = False) -> bool:
        """Apply one step of ``action``; True if the state changed."""
        kind = action.kind
        if kind == "rotate":
            # a new array each step: arrays handed out before are never edited
            self._matrix = _read_only(reorthonormalize(self.step_matrix(action, inverted) @ self._matrix))
        elif kind == "alpha":
            self.alpha = self._alpha + action.sign * self.alpha_step
        elif kind == "c0":
            self.c0 = self._c0 + action.sign * self._c0_step
        elif kind == "theta0":
            new = self._theta0 * THETA0_FACTOR if action.sign > 0 else self._theta0 / THETA0_FACTOR
            new = min(new, THETA0_MAX)
            if new == self._theta0:
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
        """
        found = self.keymap.resolve(key, shift)
        if found is None:
            return False
        return self.apply(*found)

    def reset(self) -> None:
        """Back to the state as constructed (orientation, theta0, alpha, c0)."""
        self._theta0, self._alpha, self._c0, m = self._initial
        self._matrix = _read_only(m.copy())  # a new object, like every step
        self._steps.clear()

    def __repr__(self) -> str:
        return (
            f"RotationState(theta0={self._theta0:.6g}, alpha={self._alpha:.6g}, "
            f"beta={self.beta:.6g}, c0={self._c0:.6g})"
        )
