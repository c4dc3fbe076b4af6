"""The page steps its own copy of the state exactly as the kernel does (issue 34).

The page's modules (``page/state.js``, ``page/keymap.js``, ``page/rotation.js``) get the key table
and bounds from `rot4d_widget.view.pagestate.page_config` and a state from `state_message`; here
10,000 random presses of every state key (both Shifts), with refusals at every bound, are applied
by `RotationState` in Python and by the page under Node: every step's "changed" agrees, and the
state agrees within 1e-12 at checkpoints (matrix products round alike up to the last bits: numpy's
4 x 4 product may use fused multiply-adds); a state adopted from the kernel is its exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from page_node import run_page
from rot4d_widget.core.keymap import DEFAULT_KEYMAP
from rot4d_widget.core.state import RotationState
from rot4d_widget.view.pagestate import page_config, state_message

STATE_KEYS = ["2", "3", "4", "6", "8", "c", "y", "z", "w", "k", "j", "l", "h", "+", "-", "r", "?"]

SCRIPT = """
import { PageState } from "page:state.js";
import { PageKeymap } from "page:keymap.js";
const cfg = INPUT.config;
const km = new PageKeymap(cfg.keymap, cfg.shift_kinds);
const s = new PageState(INPUT.state, cfg.bounds);
const read = () => ({ matrix: Array.from(s.matrix), theta0: s.theta0, alpha: s.alpha, c0: s.c0 });
const adopted = read();
const changed = [], checkpoints = [];
INPUT.keys.forEach(([key, shift], i) => {
  const f = km.resolve(key, shift);
  changed.push(f ? s.apply(f.action, f.inverted) : false);
  if ((i + 1) % INPUT.every === 0) checkpoints.push(read());
});
console.log(JSON.stringify({ adopted, changed, checkpoints }));
"""


def _config():
    return page_config(DEFAULT_KEYMAP, hold_delay=0.25, tick_rate=30.0, max_lag=0.25)


def _presses(n, seed):
    rng = np.random.default_rng(seed)
    keys = rng.choice(STATE_KEYS, size=n, p=None)
    keys = [k if k != "r" or rng.random() < 0.02 else "4" for k in keys]  # resets rare: long runs
    # long runs of one key reach the bounds (alpha, c0, theta0) and stay there a while
    out = []
    for k in keys:
        run = int(rng.integers(1, 40)) if k in ("k", "j", "l", "h", "+", "-") else 1
        out += [[str(k), bool(rng.random() < 0.5)]] * run
    return out[:n]


@pytest.mark.parametrize("seed", [0, 1])
def test_ten_thousand_random_steps_agree_with_python(seed):
    state = RotationState(c0_step=1 / 64, c0_limit=2.0, c0_origin=0.0)
    msg = state_message(state)
    keys = _presses(10_000, seed)
    every = 250
    changed, points = [], []
    for i, (key, shift) in enumerate(keys):
        changed.append(state.press(key, shift))
        if (i + 1) % every == 0:
            points.append((state.matrix.copy(), state.theta0, state.alpha, state.c0))
    page = run_page(SCRIPT, {"config": _config(), "state": msg, "keys": keys, "every": every})
    assert page["changed"] == changed
    assert sum(changed) < len(changed)  # some refused at a bound
    assert page["adopted"] == {k: msg[k] for k in ("matrix", "theta0", "alpha", "c0")}  # exactly
    worst = 0.0
    for (m, t, a, c), p in zip(points, page["checkpoints"]):
        worst = max(worst, float(np.abs(np.asarray(p["matrix"]).reshape(4, 4) - m).max()))
        assert p["theta0"] == pytest.approx(t, rel=1e-12) and p["c0"] == pytest.approx(c, abs=1e-12)
        assert p["alpha"] == pytest.approx(a, rel=1e-12, abs=1e-15)
    assert worst <= 1e-12, worst


def test_a_mismatched_rule_is_caught():
    """The comparison can fail: a page whose bounds are not the kernel's disagrees on a refusal."""
    state = RotationState()
    cfg = _config()
    cfg["bounds"]["theta0_max"] = math.pi / 2  # not the kernel's
    keys = [["+", False]] * 12  # pi/64 * sqrt(2)**12 = pi: past the page's pi/2
    changed = [state.press(*k) for k in keys]
    page = run_page(SCRIPT, {"config": cfg, "state": state_message(RotationState()), "keys": keys, "every": 12})
    assert page["changed"] != changed
