"""Every uniform polychoron by name in the widget (issue 11): built through `polytope(name)`,
shown (the scene's capacity grows to the biggest slice), turned by keys.

The combinatorics and slices themselves are tests/geometry/test_uniform.py's; here the path a user
takes: ``Rot4DWidget("x5x3x3x")``.
"""

from __future__ import annotations

import numpy as np
import pytest

import rot4d_widget
from rot4d_widget import polytope

pytestmark = pytest.mark.usefixtures("recording_comms")

NON_PRISMATIC = [n for fam, names in rot4d_widget.polytope_names().items()  # the convex uniform ones
                 if not fam.startswith(("prisms", "duoprisms", "antiprismatic", "regular star")) for n in names]
PRISMATIC_SAMPLE = ["tetrahedral prism", "truncated icosahedral prism", "3-3 duoprism", "5-7 duoprism",
                    "32-32 duoprism", "3-antiprismatic prism", "32-antiprismatic prism"]


def test_polytope_knows_the_uniform_names_and_dynkin_symbols():
    assert len(NON_PRISMATIC) == 47
    assert polytope("x3o3o3o") is polytope("5-cell")  # the regular six are the core's own
    assert polytope("o3x3o3o").counts == (10, 30, 30, 10)
    assert polytope("Truncated Tesseract").counts == (64, 128, 88, 24)
    with pytest.raises(ValueError, match="polytope_names"):
        polytope("x3x3x3x3x")


@pytest.mark.parametrize("name", NON_PRISMATIC + PRISMATIC_SAMPLE)
def test_every_uniform_polychoron_shows_and_turns_in_the_widget(make, name):
    w = make(name, c0=0.1)  # off the centre: a generic slice
    p = w.polytope
    assert p is polytope(name) and p.name == polytope(name).name
    n_rows = max(w.scene.counts)
    assert 0 < n_rows <= w.scene.capacity  # the capacity grew to what the slice needs
    before = w.scene.rows[:n_rows].copy()
    w.press("4")
    w.press("8")
    w.refresh()  # past the flow control: the rows of the current state
    s = w.slice
    assert s.volume > 0 and len(s.points) > 0
    assert max(w.scene.counts) <= w.scene.capacity
    assert not np.array_equal(before, w.scene.rows[:n_rows]) or max(w.scene.counts) != n_rows
