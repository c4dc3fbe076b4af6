"""Rotations against the explicit entries of the paper's eqs. (3)-(6)."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, strategies as st

from rot4d_widget import double_rotation, simple_rotation
from rot4d_widget.core.rotation import PLANES, as_rotation_matrix, reorthonormalize

angles = st.floats(-10.0, 10.0, allow_nan=False)


def test_xy_is_eq5_written_out():
    a = 0.3
    c, s = math.cos(a), math.sin(a)
    expected = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(simple_rotation("xy", a), expected, atol=1e-15)


def test_zw_is_eq6_written_out():
    b = -1.1
    c, s = math.cos(b), math.sin(b)
    expected = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, c, -s], [0, 0, s, c]])
    np.testing.assert_allclose(simple_rotation("zw", b), expected, atol=1e-15)


@pytest.mark.parametrize("plane", PLANES)
def test_every_plane_has_its_block_in_rows_i_j(plane):
    i, j = "xyzw".index(plane[0]), "xyzw".index(plane[1])
    a = 0.7
    m = simple_rotation(plane, a)
    assert m[i, i] == pytest.approx(math.cos(a)) and m[j, j] == pytest.approx(math.cos(a))
    assert m[i, j] == pytest.approx(-math.sin(a)) and m[j, i] == pytest.approx(math.sin(a))
    others = [k for k in range(4) if k not in (i, j)]
    for k in others:
        assert m[k, k] == 1.0
        assert np.count_nonzero(m[k]) == 1 and np.count_nonzero(m[:, k]) == 1


def test_double_xy_zw_is_eq4_written_out():
    a, b = 0.4, 1.3
    ca, sa, cb, sb = math.cos(a), math.sin(a), math.cos(b), math.sin(b)
    expected = np.array([[ca, -sa, 0, 0], [sa, ca, 0, 0], [0, 0, cb, -sb], [0, 0, sb, cb]])
    np.testing.assert_allclose(double_rotation("xy,zw", a, b), expected, atol=1e-15)


def test_double_xz_yw_and_xw_yz_written_out():
    a, b = 0.25, -0.9
    ca, sa, cb, sb = math.cos(a), math.sin(a), math.cos(b), math.sin(b)
    xz_yw = np.array([[ca, 0, -sa, 0], [0, cb, 0, -sb], [sa, 0, ca, 0], [0, sb, 0, cb]])
    xw_yz = np.array([[ca, 0, 0, -sa], [0, cb, -sb, 0], [0, sb, cb, 0], [sa, 0, 0, ca]])
    np.testing.assert_allclose(double_rotation("xz,yw", a, b), xz_yw, atol=1e-15)
    np.testing.assert_allclose(double_rotation("xw,yz", a, b), xw_yz, atol=1e-15)


@given(plane=st.sampled_from(PLANES), a=angles)
def test_simple_rotations_are_proper_orthogonal(plane, a):
    m = simple_rotation(plane, a)
    np.testing.assert_allclose(m @ m.T, np.eye(4), atol=1e-14)
    assert np.linalg.det(m) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(np.linalg.inv(m), m.T, atol=1e-14)
    np.testing.assert_allclose(simple_rotation(plane, -a), m.T, atol=1e-15)


@given(planes=st.sampled_from(["xy,zw", "xz,yw", "xw,yz"]), a=angles, b=angles)
def test_double_rotation_factors_commute(planes, a, b):
    p1, p2 = planes.split(",")
    r1, r2 = simple_rotation(p1, a), simple_rotation(p2, b)
    np.testing.assert_allclose(r1 @ r2, r2 @ r1, atol=1e-14)
    np.testing.assert_allclose(double_rotation(planes, a, b), r1 @ r2, atol=1e-14)
    m = double_rotation(planes, a, b)
    np.testing.assert_allclose(m @ m.T, np.eye(4), atol=1e-14)
    assert np.linalg.det(m) == pytest.approx(1.0)


def test_planes_of_each_double_rotation_are_absolutely_perpendicular():
    for planes in ["xy,zw", "xz,yw", "xw,yz"]:
        p1, p2 = planes.split(",")
        assert set(p1).isdisjoint(p2) and set(p1 + p2) == set("xyzw")


def test_reorthonormalize_squares_the_error():
    rng = np.random.default_rng(0)
    q, _ = np.linalg.qr(rng.normal(size=(4, 4)))
    noisy = q + 1e-7 * rng.normal(size=(4, 4))
    before = np.abs(noisy @ noisy.T - np.eye(4)).max()
    after_m = reorthonormalize(noisy)
    after = np.abs(after_m @ after_m.T - np.eye(4)).max()
    assert before > 1e-8 and after < 1e-13


@pytest.mark.parametrize(
    "call, exc, match",
    [
        (lambda: simple_rotation("xx", 1.0), ValueError, "'xy', 'xz', 'xw', 'yz', 'yw', 'zw'"),
        (lambda: simple_rotation("wx", 1.0), ValueError, "expected one of"),
        (lambda: simple_rotation(3, 1.0), ValueError, "Unknown rotation plane"),
        (lambda: simple_rotation("xy", float("nan")), ValueError, "finite"),
        (lambda: simple_rotation("xy", "1"), TypeError, "real number"),
        (lambda: double_rotation("xy,zx", 1.0, 2.0), ValueError, "'xy,zw', 'xz,yw', 'xw,yz'"),
        (lambda: double_rotation("xy,zw", 1.0, float("inf")), ValueError, "beta"),
        (lambda: as_rotation_matrix(np.eye(3)), ValueError, r"shape \(4, 4\), got \(3, 3\)"),
        (lambda: as_rotation_matrix(2 * np.eye(4)), ValueError, "orthogonal"),
        (lambda: as_rotation_matrix(np.diag([1.0, 1, 1, -1])), ValueError, "det"),
        (lambda: as_rotation_matrix(np.full((4, 4), np.nan)), ValueError, "finite"),
        (lambda: as_rotation_matrix([["a"] * 4] * 4), TypeError, "real numbers"),
    ],
)
def test_bad_input_names_what_is_allowed(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def test_all_pairs_of_planes_do_not_commute_when_they_share_an_axis():
    # sanity check that the commuting test above is not vacuous
    for p, q in itertools.combinations(PLANES, 2):
        r1, r2 = simple_rotation(p, 0.5), simple_rotation(q, 0.7)
        commute = np.allclose(r1 @ r2, r2 @ r1)
        assert commute == set(p).isdisjoint(q)


@pytest.mark.parametrize(
    "given",
    [
        np.eye(4),
        np.asfortranarray(np.eye(4)),
        simple_rotation("xw", 0.3),
        np.eye(4, dtype=np.float32),
        [[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
    ],
)
def test_as_rotation_matrix_never_hands_back_the_callers_array(given):
    out = as_rotation_matrix(given)
    assert out is not given and out.dtype == np.float64 and out.flags.c_contiguous
    if isinstance(given, np.ndarray):
        assert not np.shares_memory(out, given)
    before = np.array(given, dtype=np.float64)
    out[0, 0] = 7.0  # the result is the caller's to edit ...
    np.testing.assert_array_equal(np.asarray(given, dtype=np.float64), before)  # ... and the input is untouched


def test_as_rotation_matrix_of_a_read_only_input_is_a_writable_copy():
    m = np.eye(4)
    m.flags.writeable = False
    out = as_rotation_matrix(m)
    assert out.flags.writeable and not np.shares_memory(out, m)
