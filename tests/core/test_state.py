"""Keys of the paper's Tables 1 and 2 through RotationState.press."""

import math

import numpy as np
import pytest

from rot4d_widget import DEFAULT_KEYMAP, RotationState, double_rotation, simple_rotation
from rot4d_widget.core.state import ALPHA_STEP_FRACTION, DEFAULT_THETA0, PAPER_ALPHA_RATIO, THETA0_FACTOR

SIMPLE_KEYS = {"2": "xy", "3": "xz", "4": "xw", "6": "yz", "8": "yw", "c": "zw"}
DOUBLE_KEYS = {"y": "xy,zw", "z": "xz,yw", "w": "xw,yz"}


def explicit_simple(plane, a):
    """Eq. (5)-style matrix written out independently of rot4d_widget."""
    i, j = "xyzw".index(plane[0]), "xyzw".index(plane[1])
    m = np.eye(4)
    m[i, i] = m[j, j] = math.cos(a)
    m[i, j], m[j, i] = -math.sin(a), math.sin(a)
    return m


@pytest.mark.parametrize("key, plane", SIMPLE_KEYS.items())
def test_simple_keys_and_their_shift_inverse(key, plane):
    st = RotationState(theta0=0.1)
    assert st.press(key) is True
    np.testing.assert_allclose(st.matrix, explicit_simple(plane, 0.1), atol=1e-15)
    st.reset()
    assert st.press(key, shift=True)
    np.testing.assert_allclose(st.matrix, explicit_simple(plane, -0.1), atol=1e-15)
    if key.isalpha():
        st.reset()
        assert st.press(key.upper(), shift=False)  # "C": upper case counts as shifted
        np.testing.assert_allclose(st.matrix, explicit_simple(plane, -0.1), atol=1e-15)


@pytest.mark.parametrize("key, planes", DOUBLE_KEYS.items())
def test_double_keys_use_alpha_and_beta_and_shift_negates_both(key, planes):
    st = RotationState(theta0=0.3, alpha=0.1)
    assert st.beta == pytest.approx(0.2)
    p1, p2 = planes.split(",")
    st.press(key)
    np.testing.assert_allclose(st.matrix, explicit_simple(p1, 0.1) @ explicit_simple(p2, 0.2), atol=1e-15)
    st.reset()
    st.press(key.upper())
    np.testing.assert_allclose(st.matrix, explicit_simple(p1, -0.1) @ explicit_simple(p2, -0.2), atol=1e-15)
    np.testing.assert_allclose(st.matrix, double_rotation(planes, 0.1, 0.2).T, atol=1e-15)


def test_composition_is_extrinsic():
    st = RotationState(theta0=0.2)
    st.press("2")
    st.press("4")
    expected = explicit_simple("xw", 0.2) @ explicit_simple("xy", 0.2)
    np.testing.assert_allclose(st.matrix, expected, atol=1e-15)
    assert not np.allclose(expected, explicit_simple("xy", 0.2) @ explicit_simple("xw", 0.2))


def test_32_presses_of_4_at_pi_over_16_return_to_identity():
    st = RotationState(theta0=math.pi / 16)
    for k in range(1, 33):
        st.press("4")
        if k < 32:
            assert np.abs(st.matrix - np.eye(4)).max() > 1e-3
    np.testing.assert_allclose(st.matrix, np.eye(4), atol=1e-13)


def test_many_random_presses_stay_orthogonal():
    rng = np.random.default_rng(42)
    st = RotationState(theta0=0.37)
    keys = list(SIMPLE_KEYS) + list(DOUBLE_KEYS)
    choice = rng.integers(0, len(keys), size=200_000)
    shifts = rng.random(200_000) < 0.5
    for k, s in zip(choice, shifts):
        st.press(keys[k], shift=bool(s))
    m = st.matrix
    assert np.linalg.norm(m @ m.T - np.eye(4)) < 1e-13


def test_alpha_keys_keep_sum_and_are_not_clamped():
    st = RotationState(theta0=0.2, alpha=0.01)
    step = 0.2 * ALPHA_STEP_FRACTION
    st.press("k")
    assert st.alpha == pytest.approx(0.01 + step) and st.alpha + st.beta == pytest.approx(0.2)
    for _ in range(10):
        st.press("j")
    assert st.alpha < 0 and st.alpha + st.beta == pytest.approx(0.2)
    np.testing.assert_allclose(st.matrix, np.eye(4))  # parameter keys do not rotate
    before = st.alpha
    st.press("J")  # shift has no effect on parameter keys
    assert st.alpha == pytest.approx(before - step)


def test_c0_keys_step_and_shift_does_nothing_special():
    st = RotationState(c0_step=0.05)
    st.press("l")
    st.press("l")
    st.press("H")
    assert st.c0 == pytest.approx(0.05)
    np.testing.assert_allclose(st.matrix, np.eye(4))


def test_theta0_keys_keep_alpha_ratio():
    st = RotationState(theta0=0.2, alpha=0.05)
    st.press("+")
    assert st.theta0 == pytest.approx(0.2 * THETA0_FACTOR)
    assert st.alpha / st.theta0 == pytest.approx(0.25)
    st.press("-")
    st.press("-")
    assert st.theta0 == pytest.approx(0.2 / THETA0_FACTOR)
    st.theta0 = 1.0
    assert st.alpha == pytest.approx(0.25)


def test_defaults_are_documented_values():
    st = RotationState()
    assert st.theta0 == DEFAULT_THETA0 == math.pi / 64
    assert st.alpha == pytest.approx(math.pi / 64 * math.pi * math.sqrt(2) / (8 * math.sqrt(3)))
    assert 0 < st.alpha < st.theta0 and st.beta == st.theta0 - st.alpha
    assert PAPER_ALPHA_RATIO == pytest.approx(0.3206, abs=1e-4)
    assert st.c0 == 0.0


def test_unbound_and_help_keys_change_nothing():
    st = RotationState()
    st.press("4")
    snapshot = (st.matrix.copy(), st.theta0, st.alpha, st.c0)
    for key in ["q", "5", "@", "Enter", "?"]:
        assert st.press(key) is False
    assert np.array_equal(st.matrix, snapshot[0]) and (st.theta0, st.alpha, st.c0) == snapshot[1:]


def test_reset_restores_the_constructed_state():
    st = RotationState(theta0=0.1, alpha=0.03, c0=0.2)
    for key in "24ykl+":
        st.press(key)
    st.press("r")
    np.testing.assert_array_equal(st.matrix, np.eye(4))
    assert (st.theta0, st.alpha, st.c0) == (0.1, 0.03, 0.2)


def test_custom_keymap():
    km = DEFAULT_KEYMAP.replace(q="xw", **{"4": None})
    st = RotationState(theta0=0.1, keymap=km)
    assert st.press("4") is False
    assert st.press("q")
    np.testing.assert_allclose(st.matrix, simple_rotation("xw", 0.1))


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        ({"theta0": float("nan")}, ValueError, "theta0.*finite"),
        ({"theta0": 0.0}, ValueError, r"\(0, pi\]"),
        ({"theta0": -1.0}, ValueError, r"\(0, pi\]"),
        ({"theta0": "fast"}, TypeError, "real number"),
        ({"alpha": float("inf")}, ValueError, "alpha"),
        ({"c0": float("nan")}, ValueError, "c0"),
        ({"c0_step": -0.1}, ValueError, "c0_step"),
        ({"keymap": {"4": "xw"}}, TypeError, "Keymap"),
        ({"matrix": np.eye(3)}, ValueError, r"\(4, 4\)"),
    ],
)
def test_bad_state_input(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        RotationState(**kwargs)


def test_bad_assignments():
    st = RotationState()
    with pytest.raises(ValueError, match="orthogonal"):
        st.matrix = np.ones((4, 4))
    with pytest.raises(ValueError, match="finite"):
        st.c0 = float("inf")
    with pytest.raises(TypeError, match="string"):
        st.press(4)


# -- state that cannot be corrupted (issue 7) ---------------------------------


def test_setting_matrix_copies_the_callers_array():
    st = RotationState()
    m = np.eye(4)
    st.matrix = m
    m[0, 0] = 7.0
    np.testing.assert_array_equal(st.matrix, np.eye(4))


def test_constructor_matrix_is_copied():
    m = simple_rotation("xy", 0.3)
    st = RotationState(matrix=m)
    m[:] = 0.0
    np.testing.assert_allclose(st.matrix, simple_rotation("xy", 0.3))
    st.press("4")
    st.reset()
    np.testing.assert_allclose(st.matrix, simple_rotation("xy", 0.3))


def test_matrix_is_read_only():
    st = RotationState()
    with pytest.raises(ValueError, match="read-only"):
        st.matrix[0, 0] = 5.0
    st.press("4")
    with pytest.raises(ValueError, match="read-only"):
        st.matrix[0, 0] = 5.0
    st.matrix = simple_rotation("yz", 0.2)
    with pytest.raises(ValueError, match="read-only"):
        st.matrix[0, 0] = 5.0
    st.reset()
    with pytest.raises(ValueError, match="read-only"):
        st.matrix[0, 0] = 5.0
    with pytest.raises(ValueError):
        st.matrix.flags.writeable = True  # cannot be unlocked ...
    with pytest.raises(ValueError):
        st.matrix.resize((2, 2), refcheck=False)  # ... nor resized in place
    np.testing.assert_array_equal(st.matrix, np.eye(4))


def test_reset_cannot_be_corrupted_through_matrix():
    st = RotationState(matrix=simple_rotation("xw", 0.4))
    for write in (lambda m: m.__setitem__((0, 0), 9.0), lambda m: m.fill(0.0)):
        with pytest.raises(ValueError):
            write(st.matrix)
    st.press("r")
    np.testing.assert_allclose(st.matrix, simple_rotation("xw", 0.4))


def test_matrix_is_the_same_object_until_a_step_replaces_it():
    """The widget caches its slice on ``state.matrix is m``: reading is free and stable,
    every step hands out a new object, and no step edits an array handed out before."""
    st = RotationState(theta0=0.1)
    first = st.matrix
    assert st.matrix is first
    seen = [(first, first.copy())]
    for key in ["4", "Z", "c", "k", "y", "l", "+", "r", "8"]:
        st.press(key)
        seen.append((st.matrix, st.matrix.copy()))
    st.matrix = simple_rotation("xz", 0.2)
    seen.append((st.matrix, st.matrix.copy()))
    for old, snapshot in seen:
        np.testing.assert_array_equal(old, snapshot)
    before = st.matrix
    st.press("2")
    assert st.matrix is not before


def test_step_matrix_cache_cannot_be_corrupted():
    st = RotationState(theta0=0.1)
    for _ in range(2):  # the first call (which fills the cache) and a cached one
        step = st.step_matrix(DEFAULT_KEYMAP["4"])
        with pytest.raises(ValueError, match="read-only"):
            step[0, 0] = 0.0
        with pytest.raises(ValueError):
            step.flags.writeable = True
    st.press("4")
    np.testing.assert_allclose(st.matrix, simple_rotation("xw", 0.1), atol=1e-15)


@pytest.mark.parametrize("shift", ["yes", 1, 0, None, 1.0, [True]])
def test_shift_must_be_a_bool(shift):
    st = RotationState()
    with pytest.raises(TypeError, match="`shift` to be a bool.*True or False"):
        st.press("4", shift=shift)
    with pytest.raises(TypeError, match="`shift` to be a bool"):
        DEFAULT_KEYMAP.resolve("4", shift)
    np.testing.assert_array_equal(st.matrix, np.eye(4))


def test_numpy_bool_shift_is_accepted():
    st = RotationState(theta0=0.1)
    assert st.press("4", shift=np.bool_(True))
    np.testing.assert_allclose(st.matrix, simple_rotation("xw", -0.1), atol=1e-15)
    assert DEFAULT_KEYMAP.resolve("4", np.False_) == (DEFAULT_KEYMAP["4"], False)


@pytest.mark.parametrize("key", ["o", "i", "n", "b", "g", "f", "p"])
def test_reserved_keys_change_nothing_in_the_core(key):
    st = RotationState(theta0=0.1)
    st.press("4")
    before = (st.matrix, st.theta0, st.alpha, st.c0)
    assert key in DEFAULT_KEYMAP
    assert st.press(key) is False and st.press(key, shift=True) is False
    assert st.matrix is before[0] and (st.theta0, st.alpha, st.c0) == before[1:]


def test_custom_actions_change_nothing_in_the_core():
    from rot4d_widget import Action

    st = RotationState()
    before = st.matrix
    assert st.apply(Action("custom", name="phase+", sign=1, text="advance the phase")) is False
    assert st.matrix is before


# ----------------------------------------------------------------- to_dict / from_dict (issue 12)
def _walked_state():
    from rot4d_widget import Action
    from rot4d_widget.core.rotation import random_rotation

    st = RotationState(0.13, alpha=0.05, c0=0.1, c0_step=0.03, matrix=random_rotation(7))
    st.keymap = st.keymap.extended({"o": Action("custom", name="level up", sign=1, text="raise the level")})
    for key in "4zZkkl8+wh":
        st.press(key)
    return st


def test_to_dict_round_trips_exactly_through_json():
    import json

    st = _walked_state()
    d = json.loads(json.dumps(st.to_dict()))
    back = RotationState.from_dict(d)
    assert np.array_equal(back.matrix, st.matrix)  # bit for bit
    assert (back.theta0, back.alpha, back.c0, back.c0_step) == (st.theta0, st.alpha, st.c0, st.c0_step)
    assert list(back.keymap.items()) == list(st.keymap.items())  # same bindings, same order
    assert back.keymap["o"].kind == "custom" and back.keymap["o"].text == "raise the level"
    assert d["keymap"]["4"] == "xw" and d["keymap"]["l"] == "c0+" and d["format"] == 3
    # the loaded state steps like the original
    st.press("y"), back.press("y")
    assert np.array_equal(back.matrix, st.matrix)


def test_a_loaded_state_is_where_reset_returns():
    st = _walked_state()
    back = RotationState.from_dict(st.to_dict())
    back.press("4"), back.press("l"), back.press("k")
    back.reset()
    assert np.array_equal(back.matrix, st.matrix)
    assert (back.theta0, back.alpha, back.c0) == (st.theta0, st.alpha, st.c0)
    # restore() does the same in place, keeping the object
    fresh = RotationState()
    fresh.restore(st.to_dict())
    fresh.press("3")
    fresh.reset()
    assert np.array_equal(fresh.matrix, st.matrix) and fresh.c0 == st.c0
    # initial=True keeps the original reset point instead (recordings)
    keep = RotationState.from_dict(st.to_dict(initial=True))
    keep.reset()
    assert not np.allclose(keep.matrix, st.matrix)
    st.reset()
    assert np.array_equal(keep.matrix, st.matrix)


def test_from_dict_reorthonormalises_a_nearly_orthogonal_orientation():
    from rot4d_widget.core.rotation import random_rotation

    m = random_rotation(5)
    d = RotationState(matrix=m).to_dict()
    noisy = m + 4e-7 * np.random.default_rng(0).standard_normal((4, 4)) / 4
    err = np.abs(noisy @ noisy.T - np.eye(4)).max()
    assert 1e-9 < err <= 1e-6
    d["orientation"] = noisy.tolist()
    got = RotationState.from_dict(d).matrix
    assert np.abs(got @ got.T - np.eye(4)).max() < 1e-14
    assert np.abs(got - m).max() < 1e-6


@pytest.mark.parametrize("orientation, match", [
    ((np.eye(4) + 1e-5 * np.arange(16).reshape(4, 4) / 16).tolist(), r"to be orthogonal .*deviation "),
    (np.diag([1.0, 1.0, 1.0, -1.0]).tolist(), "reflection"),
    (np.eye(3).tolist(), r"shape \(4, 4\)"),
    ("identity", r"\(4, 4\) array of real numbers"),
])
def test_from_dict_refuses_what_is_not_a_rotation(orientation, match):
    d = RotationState().to_dict()
    d["orientation"] = orientation
    with pytest.raises(ValueError, match=match):
        RotationState.from_dict(d)


@pytest.mark.parametrize("change, exc, match", [
    ({"colour": "red"}, ValueError, "Unknown state field"),
    ({"format": 99}, ValueError, "Unsupported state format 99"),
    ({"theta0": 7.0}, ValueError, r"theta0"),
    ({"keymap": {"4": "sideways"}}, ValueError, "Unknown action 'sideways'"),
    ({"keymap": {"4": {"kind": "rotate", "planes": "xw", "colour": 1}}}, ValueError, "action dict"),
])
def test_from_dict_names_what_is_wrong(change, exc, match):
    d = {**RotationState().to_dict(), **change}
    with pytest.raises(exc, match=match):
        RotationState.from_dict(d)
    with pytest.raises(TypeError, match="Expected a dict"):
        RotationState.from_dict([1, 2])


def test_copy_is_independent_and_keeps_the_reset_point():
    st = _walked_state()
    c = st.copy()
    c.press("4")
    assert not np.array_equal(c.matrix, st.matrix)
    c.reset(), st.reset()
    assert np.array_equal(c.matrix, st.matrix)


def test_without_source_keys_lets_a_widget_extend_a_stored_keymap_again():
    from rot4d_widget import Action
    from rot4d_widget.core.state import without_source_keys

    custom = {"o": Action("custom", name="level up", sign=1), "x": Action("custom", name="phase", sign=1)}
    stored = RotationState.from_dict(RotationState(keymap=DEFAULT_KEYMAP.extended(custom)).to_dict()).keymap
    with pytest.raises(ValueError, match="already bound"):
        stored.extended(custom)
    base = without_source_keys(stored)
    assert base["o"] == DEFAULT_KEYMAP["o"] and "x" not in base
    assert list(base.items()) == list(DEFAULT_KEYMAP.items())
    assert base.extended(custom)["x"].name == "phase"


def test_a_format_1_state_has_its_c0_converted_to_the_source_s_w_units():
    """Format 1 kept c0 in slice units; read with the source's w frame it becomes the data's w."""
    st = _walked_state()
    d = st.to_dict(initial=True)
    d["format"] = 1
    back = RotationState.from_dict(d, w_frame=(30.0, 4.0))
    assert back.c0 == 30.0 + 4.0 * st.c0 and back.c0_step == 4.0 * st.c0_step
    back.reset()
    assert back.c0 == 30.0 + 4.0 * 0.1  # the reset point converted too
    # format 2 is already in the source's units, and a polytope's frame (0, 1) changes nothing
    d2 = st.to_dict()
    assert RotationState.from_dict(d2, w_frame=(30.0, 4.0)).c0 == st.c0
    assert RotationState.from_dict(d, w_frame=(0.0, 1.0)).c0 == st.c0
    with pytest.raises(ValueError, match="per_unit > 0"):
        RotationState.from_dict(d, w_frame=(0.0, -1.0))


def test_the_l_h_range_is_centred_on_the_source_s_origin():
    st = RotationState(c0=30.0, c0_step=1.0, c0_limit=2.5, c0_origin=30.0)
    assert [st.press("l") for _ in range(4)] == [True, True, False, False]  # 32 then 33 is refused
    assert st.c0 == 32.0
    assert [st.press("h") for _ in range(6)] == [True] * 4 + [False] * 2  # down to 28
    assert st.c0 == 28.0
