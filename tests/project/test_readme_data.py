"""The README's "Which side is inside, caps, and the cut's values" block runs as written (issue 37,
problem 6): a field enclosing T >= 1150 K, a ball given by its signed distance (inside="below"), a
field that fills its box drawn open (caps=False) and the cut's values on a grid (`sample_field`)."""

from __future__ import annotations

import pathlib
import re

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _block() -> str:
    readme = (ROOT / "README.md").read_text()
    section = readme.split("**Which side is inside, caps, and the cut's values.**", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_inside_caps_and_sample_block_runs(capsys):
    ns: dict = {}
    exec(compile(_block(), "README.md", "exec"), ns)
    w = ns["w"]
    try:
        assert ns["dist"].inside == "below" and ns["wave"].caps is False
        ball = ns["dist"].slice(np.eye(4), 0.0)
        assert abs(ball.volume - 4 / 3 * np.pi * 0.7**3) < 0.05  # the ball r <= 0.7, not the box around it
        assert ns["wave"].slice(np.eye(4), 0.0).volume is None  # open at the faces: no volume to give
        g = ns["grid"]
        assert g.values.shape[0] == 34 and np.isnan(g.values).any() and np.nanmax(g.values) > 1900
        assert "(34, 34, 34)" in capsys.readouterr().out
    finally:
        w.close()
