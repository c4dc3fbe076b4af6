"""Files from other tools (issue 22): `Polytope.from_off(path, tolerance=...)` takes coordinates
written with few digits when the caller allows a looser tolerance (the default error says which
would do), and the forms other programs write (comments before the keyword, blank lines, trailing
spaces, no final newline, a wrong or zero edge count) all read."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

from rot4d_widget import polytope
from rot4d_widget.geometry.mesh import MAX_TOLERANCE, MESH_TOLERANCE, Polytope
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope


def rounded_off(p, digits):
    """``p``'s 4OFF text with every vertex coordinate written with ``digits`` significant digits."""
    lines = p.to_off().splitlines()
    nv = len(p.vertices)
    done = 0
    for i, ln in enumerate(lines):
        toks = ln.split("#")[0].split()
        if done < nv and len(toks) == 4 and any("." in t for t in toks):  # a vertex line
            lines[i] = " ".join(f"{float(t):.{digits}g}" for t in toks)
            done += 1
    assert done == nv
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("name, digits", [("120-cell", 3), ("rectified 600-cell", 4)])
def test_few_digits_are_refused_by_default_with_the_tolerance_that_would_do(name, digits):
    exact = polytope(name)
    text = rounded_off(exact, digits)
    with pytest.raises(ValueError, match=r"not planar|does not lie in a hyperplane") as err:
        Polytope.from_off(text)
    hint = re.search(r"tolerance=([0-9.e+-]+) \(Polytope", str(err.value))
    assert hint, str(err.value)
    loose = Polytope.from_off(text, tolerance=float(hint.group(1)))  # the suggested tolerance does
    assert loose.tolerance == float(hint.group(1))
    assert (len(loose.faces), len(loose.cells), len(loose.edges)) == (len(exact.faces), len(exact.cells),
                                                                       len(exact.edges))
    assert loose.convex
    # its slices are the exact polytope's, to the file's precision
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, _ = np.linalg.qr(rng.normal(size=(4, 4)))
        q[:, 0] *= np.sign(np.linalg.det(q))
        a, b = slice_polytope(exact, q, 0.1), slice_polytope(loose, q, 0.1)
        # the same solid to the file's precision (rounding may split a corner into two close ones, and a
        # crossing on an edge almost in the hyperplane moves by far more than the rounding: the bulk)
        near = 10 ** (1 - digits) * exact.circumradius
        for x, y in ((a, b), (b, a)):
            assert np.percentile(cKDTree(x.vertices).query(y.vertices)[0], 90) < near
        assert b.volume == pytest.approx(a.volume, rel=10 ** (1 - digits))


def test_the_default_tolerance_is_the_mesh_tolerance_and_bad_ones_are_refused():
    text = polytope("24-cell").to_off()
    assert Polytope.from_off(text).tolerance == MESH_TOLERANCE
    for bad, exc in [(0.0, ValueError), (-1e-3, ValueError), (2 * MAX_TOLERANCE, ValueError),
                     (float("nan"), ValueError), ("1e-3", TypeError), (True, TypeError)]:
        with pytest.raises(exc, match=r"`tolerance` to be None \(the default .*\) or a number in \(0, 0.01\]"):
            Polytope.from_off(text, tolerance=bad)


def test_what_other_programs_write_reads():
    p = polytope("5-cell")
    lines = p.to_off().splitlines()
    body = [ln for ln in lines if ln and not ln.startswith("#")]
    assert body[0] == "4OFF"
    counts = body[1].split()
    messy = ["# written by another viewer", "# with comments before the keyword", "", "4OFF   ",
             "", f"{counts[0]} {counts[1]} 0 {counts[3]}  "]  # E = 0: not counted
    messy += [ln + "   " for ln in body[2:]]  # trailing spaces
    q = Polytope.from_off("\n".join(messy))  # and no final newline
    assert (len(q.vertices), len(q.faces), len(q.cells)) == (5, 10, 5)
    wrong = messy.copy()
    wrong[5] = f"{counts[0]} {counts[1]} 7 {counts[3]}"  # a wrong edge count: read, with a warning
    with pytest.warns(UserWarning, match=r"E = 7 but the faces have 10 edges"):
        q = Polytope.from_off("\n".join(wrong))
    assert len(q.edges) == 10
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Polytope.from_off("\n".join(messy))  # E = 0 says nothing


def test_a_file_without_the_keyword_says_what_is_missing():
    body = [ln for ln in polytope("5-cell").to_off().splitlines() if ln and not ln.startswith("#")]
    with pytest.raises(ValueError, match=r"line 1: expected the header 4OFF"):
        Polytope.from_off("\n".join(body[1:]))


def test_a_deviation_beyond_rounding_is_not_offered_a_tolerance():
    """A corner 5 % of the extent off its plane is a wrong number, not rounding: the error says so
    and suggests no tolerance (one above MAX_TOLERANCE would itself be refused)."""
    lines = polytope("8-cell").to_off().splitlines()
    i = next(i for i, ln in enumerate(lines) if len(ln.split("#")[0].split()) == 4 and "." in ln)
    x = [float(t) for t in lines[i].split()]
    x[0] += 0.2  # the tesseract's extent is 2: 10 %
    lines[i] = " ".join(repr(v) for v in x)
    with pytest.raises(ValueError, match=r"more than rounding \(the loosest tolerance allowed is 0\.01\)") as err:
        Polytope.from_off("\n".join(lines) + "\n")
    assert "tolerance=" not in str(err.value)
