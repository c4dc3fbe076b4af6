"""A non-convex 4-D mesh in the widget: its slices are drawn as non-convex (faces sorted back to
front by depth, not back faces first), alone and as parallel slices."""

from __future__ import annotations

import pytest

from mesh_shapes import tesseract_union
from rot4d_widget import polytope
from rot4d_widget.sources.tomography import StackSource

pytestmark = pytest.mark.usefixtures("recording_comms")


def test_a_non_convex_polytope_s_slices_are_not_drawn_as_convex(make):
    L, pieces = tesseract_union("L")
    assert not L.convex and polytope("24-cell").convex
    w = make(L, c0=0.3)
    w.press("4")
    w.press("8")
    s = w.slice
    assert s.convex is False and s.volume > 0
    assert make("24-cell").slice.convex is True
    stack = StackSource(L, slices=3, spacing=0.2)
    data = stack.slice(w.state.matrix, 0.3)
    assert data.convex is False
    one = StackSource(L, slices=1)
    assert one.slice(w.state.matrix, 0.3).convex is False
    # the L's slice volume is its pieces' sum (their slices are convex)
    from rot4d_widget import Polytope, slice_polytope

    total = sum(slice_polytope(Polytope(p), w.state.matrix, 0.3).volume for p in pieces)  # convex pieces
    assert s.volume == pytest.approx(total, rel=1e-9)
