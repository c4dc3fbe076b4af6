"""rot4d_widget.sources.datasets: the simulated phase separation (cache, shape, physics) and the moving sphere."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from rot4d_widget.sources import datasets
from rot4d_widget.sources.datasets import default_cache_dir, moving_sphere, phase_separation, phase_separation_key
from rot4d_widget.sources.field.container import Field4D, slice_field
from rot4d_widget.core.rotation import simple_rotation

pytest.importorskip("pde")
pytest.importorskip("xarray")

#: a small run that still separates into domains and coarsens (about 0.3 s)
SMALL = dict(n=16, steps=11, t_end=10.0, interface=1.0, bias=-0.1, seed=3)


@pytest.fixture
def counted(monkeypatch):
    """Counts the calls that reach py-pde."""
    calls = []
    real = datasets._simulate

    def simulate(*args):
        calls.append(args)
        return real(*args)

    monkeypatch.setattr(datasets, "_simulate", simulate)
    return calls


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    return phase_separation(**SMALL, cache_dir=tmp_path_factory.mktemp("cache"))


def free_energy(c, xi):
    """F = sum(xi^2/2 |grad c|^2 + (1 - c^2)^2 / 4) per frame (periodic forward differences)."""
    c = np.asarray(c, dtype=np.float64)
    g2 = sum((np.roll(c, -1, axis=a) - c) ** 2 for a in (1, 2, 3))
    return (xi**2 / 2 * g2 + (1 - c * c) ** 2 / 4).sum(axis=(1, 2, 3))


def interface_area(c):
    """Grid faces across which c changes sign, per frame (periodic): a measure of the interface area."""
    s = np.signbit(np.asarray(c))
    return sum((s != np.roll(s, 1, axis=a)).sum(axis=(1, 2, 3)) for a in (1, 2, 3))


# ----------------------------------------------------------------------------- cache
def test_the_cache_key_follows_every_parameter():
    base = phase_separation_key(**SMALL)
    assert base == phase_separation_key(**SMALL)
    assert phase_separation_key(**{**SMALL, "t_end": 10}) == base  # 10 and 10.0 are one run
    changed = {"n": 17, "steps": 12, "t_end": 11.0, "interface": 1.1, "bias": 0.0, "seed": 4}
    keys = {name: phase_separation_key(**{**SMALL, name: value}) for name, value in changed.items()}
    assert base not in keys.values()
    assert len(set(keys.values())) == len(keys)
    assert all(len(k) == 16 and int(k, 16) >= 0 for k in keys.values())


def test_a_second_call_reads_the_cache(tmp_path, counted):
    first = phase_separation(**SMALL, cache_dir=tmp_path)
    files = list(tmp_path.glob("phase_separation-*.npz"))
    assert [f.name for f in files] == [f"phase_separation-{phase_separation_key(**SMALL)}.npz"]
    assert not list(tmp_path.glob("*.tmp*"))  # written under a temporary name, then renamed
    second = phase_separation(**SMALL, cache_dir=tmp_path)
    assert len(counted) == 1
    np.testing.assert_array_equal(first.values, second.values)
    assert second.attrs == first.attrs
    other = phase_separation(**{**SMALL, "seed": 4}, cache_dir=tmp_path)  # another key: simulated
    assert len(counted) == 2 and len(list(tmp_path.glob("*.npz"))) == 2
    assert not np.array_equal(other.values, first.values)


def test_default_cache_dir_honours_xdg_cache_home(tmp_path, monkeypatch, counted):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_cache_dir() == tmp_path / "xdg" / "rot4d_widget"
    phase_separation(**SMALL)
    assert len(list((tmp_path / "xdg" / "rot4d_widget").glob("phase_separation-*.npz"))) == 1
    phase_separation(**SMALL)
    assert len(counted) == 1
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert default_cache_dir() == datasets.Path.home() / ".cache" / "rot4d_widget"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/dir")  # the XDG spec: relative paths are ignored
    assert default_cache_dir() == datasets.Path.home() / ".cache" / "rot4d_widget"


def test_no_cache_when_asked(tmp_path, monkeypatch, counted):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    phase_separation(**SMALL, cache_dir=False)
    phase_separation(**SMALL, cache_dir=False)
    assert len(counted) == 2
    assert not list(tmp_path.rglob("*.npz"))


def test_an_unreadable_cache_file_is_replaced(tmp_path, counted):
    path = tmp_path / f"phase_separation-{phase_separation_key(**SMALL)}.npz"
    path.write_bytes(b"not a zip file")
    with pytest.warns(RuntimeWarning, match="unreadable cache file"):
        da = phase_separation(**SMALL, cache_dir=tmp_path)
    assert len(counted) == 1
    again = phase_separation(**SMALL, cache_dir=tmp_path)
    assert len(counted) == 1
    np.testing.assert_array_equal(da.values, again.values)


# ----------------------------------------------------------------------------- the data
def test_dims_shape_coordinates_and_attrs(small_run):
    da = small_run
    n, steps = SMALL["n"], SMALL["steps"]
    assert da.dims == ("time", "x", "y", "z")
    assert da.shape == (steps, n, n, n) and da.dtype == np.float32
    np.testing.assert_allclose(da["time"].values, np.linspace(0, SMALL["t_end"], steps))
    for d in "xyz":
        np.testing.assert_allclose(da[d].values, np.arange(n) + 0.5)  # cell centres, spacing 1
        assert da[d].attrs["units"] == "grid spacing"
    assert da.name == "c" and da.attrs["units"] == "1" and "long_name" in da.attrs
    assert da.attrs["cache_key"] == phase_separation_key(**SMALL)
    assert {k: da.attrs[k] for k in SMALL} == SMALL
    assert np.all(np.isfinite(da.values))


def test_it_is_a_field4d_with_time_as_w(small_run):
    f = Field4D.from_xarray(small_run, w="time")
    assert f.axes == "wxyz" and f.shape == (16, 16, 16, 11)
    assert f.extent[3] == (0.0, SMALL["t_end"]) and f.w_per_unit == pytest.approx(1.0)
    s = slice_field(f, np.eye(4), 0.0, 0.0, resolution=24)
    assert not s.empty and s.volume > 0


def test_the_simulation_separates_phases_and_coarsens(small_run):
    c = small_run.values
    xi = SMALL["interface"]
    # Allen-Cahn is the gradient flow of F: F falls at every stored frame
    assert abs(c[0].mean() - SMALL["bias"]) < 1e-6  # the initial state's mean is the bias
    F = free_energy(c, xi)
    assert np.all(np.diff(F) < 0), F
    # two phases, c = +-1, form out of a state with |c| of about 0.4 ...
    assert np.abs(c[0]).mean() < 0.5 and np.abs(c[-1]).mean() > 0.75
    assert c[-1].max() > 0.9 and c[-1].min() < -0.9
    # ... and the interface between them shrinks (coarsening)
    area = interface_area(c)
    assert np.all(np.diff(area) <= 0) and area[-1] < 0.6 * area[0], area


def test_the_interfaces_are_resolved(small_run):
    """Across an interface c goes from -0.8 to 0.8 over ~3.1 xi = 3.1 grid spacings (tanh profile):
    no grid step jumps across it."""
    c = small_run.values[-1].astype(np.float64)
    jumps = max(np.abs(np.roll(c, -1, axis=a) - c).max() for a in range(3))
    assert jumps < 1.0, jumps  # tanh(1/sqrt 2) - tanh(-1/sqrt 2) would be 1.22 for the steepest spacing


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(n=4), r"`n` in \[8, 128\]"),
        (dict(n=500), r"`n` in \[8, 128\]"),
        (dict(steps=1), r"`steps` in \[2, 1000\]"),
        (dict(t_end=0.0), r"`t_end` > 0"),
        (dict(t_end=math.inf), r"`t_end` to be finite"),
        (dict(interface=0.3), r"fewer than 2 grid points"),
        (dict(n=16, interface=3.0), r"n/8 = 2"),
        (dict(seed=-1), r"`seed` in \[0, "),
        (dict(bias=0.8), r"`bias` \(the mean of the initial state\) in \[-0.5, 0.5\]"),
        (dict(backend="gpu"), r"'numpy' or 'numba'"),
    ],
)
def test_bad_parameters_are_named(kw, match, counted):
    with pytest.raises(ValueError, match=match):
        phase_separation(**kw, cache_dir=False)
    assert counted == []


@pytest.mark.parametrize("kw", [dict(n=16.0), dict(steps="10"), dict(seed=True), dict(t_end="1")])
def test_wrong_types_are_named(kw):
    with pytest.raises(TypeError, match="Expected `"):
        phase_separation(**kw, cache_dir=False)


def test_missing_py_pde_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pde", None)  # import pde -> ImportError
    with pytest.raises(ImportError, match=r'pip install "rot4d_widget\[notebooks\]"'):
        phase_separation(**SMALL, cache_dir=False)


# ----------------------------------------------------------------------------- the moving sphere
V, R = 0.75, 0.5


def test_moving_sphere_slices_are_the_moving_ball():
    f = moving_sphere(V, R, resolution=48)
    for t in (-0.5, 0.0, 0.5):
        s = slice_field(f, np.eye(4), t, 0.0, resolution=48)
        centre = (s.vertices.max(axis=0) + s.vertices.min(axis=0)) / 2
        np.testing.assert_allclose(centre, [V * t, 0, 0], atol=0.01)
        assert s.volume == pytest.approx(4 / 3 * math.pi * R**3, rel=0.02)


def test_moving_sphere_turned_by_arctan_v_is_one_ellipsoid():
    f = moving_sphere(V, R, resolution=48)
    m = simple_rotation("xw", math.atan(V))
    a = R / math.sqrt(1 + V * V)  # semi-axis along x: the tube's perpendicular cross-section
    vols = []
    for c0 in (-0.3, 0.0, 0.3):
        s = slice_field(f, m, c0, 0.0, resolution=48)
        x, y, z = s.vertices.T
        assert np.abs(x.mean()) < 0.01  # centred: nothing moves any more
        np.testing.assert_allclose((x / a) ** 2 + (y / R) ** 2 + (z / R) ** 2, 1.0, atol=0.02)
        vols.append(s.volume)
    assert max(vols) / min(vols) < 1.01
    assert np.mean(vols) == pytest.approx(4 / 3 * math.pi * a * R * R, rel=0.02)


@pytest.mark.parametrize("kw, err", [(dict(radius=0.0), ValueError), (dict(v=math.nan), ValueError),
                                     (dict(t_max=-1.0), ValueError), (dict(margin=-0.1), ValueError),
                                     (dict(v="fast"), TypeError)])
def test_moving_sphere_bad_parameters(kw, err):
    with pytest.raises(err, match="Expected `"):
        moving_sphere(**kw)
