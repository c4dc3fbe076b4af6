"""A real 4-D dataset: the fMRI run nibabel ships as test data (notebooks/08_real_fmri.ipynb).

Read with nibabel's own reader, built as a `Field4D` in the header's units (voxel sizes in mm,
the repetition time in s).  What the notebook states is checked here too, each against numbers
computed independently: nibabel's array and header, numpy, and scipy's linear interpolation
(``map_coordinates``) for the cut's values, unturned (volume k exactly, voxel by voxel) and turned.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

nibabel = pytest.importorskip("nibabel")

from nibabel.testing import data_path  # noqa: E402
from scipy.ndimage import map_coordinates  # noqa: E402

from rot4d_widget.core.rotation import random_rotation  # noqa: E402
from rot4d_widget.sources.field.container import Field4D  # noqa: E402

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the test extra brings tomli
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
PATH = os.path.join(data_path, "functional.nii")


@pytest.fixture(scope="module")
def run():
    img = nibabel.load(PATH)
    return img, img.get_fdata()


@pytest.fixture(scope="module")
def field(run):
    img, data = run
    zooms = [float(v) for v in img.header.get_zooms()]
    extent = [(0.0, (n - 1) * h) for n, h in zip(data.shape, zooms)]
    return Field4D(data, axes="xyzw", extent=extent, name="BOLD signal", units="a.u.", space_units="mm",
                   w_units="s")


def _fractional_indices(field, points, matrix, c0, zooms):
    return field.to_data(points, matrix, c0) / np.asarray(zooms)


def test_the_file_is_what_the_notebook_says(run):
    img, data = run
    hdr = img.header
    assert data.shape == img.shape == (17, 21, 3, 20) and hdr.get_data_dtype() == np.int16
    assert tuple(float(v) for v in hdr.get_zooms()) == (4.0, 4.0, 8.0, 2.0)
    assert hdr.get_xyzt_units() == ("mm", "sec")
    assert np.isclose(data.min(), hdr["cal_min"], rtol=1e-6) and np.isclose(data.max(), hdr["cal_max"], rtol=1e-6)


def test_the_field_has_the_files_extent_and_range(run, field):
    _, data = run
    assert field.shape == (17, 21, 3, 20)
    assert field.extent == ((0.0, 64.0), (0.0, 80.0), (0.0, 16.0), (0.0, 38.0))
    assert field.w_range(np.eye(4)) == (0.0, 38.0) and field.w_per_unit == 1.0
    assert field.data_range == (data.min(), data.max()) and field.data_range_source == "data"


@pytest.mark.parametrize("voxel, k", [((8, 10, 1), 5), ((0, 0, 0), 0), ((16, 20, 2), 19), ((3, 17, 0), 11)])
def test_unturned_the_cut_at_c0_2k_is_volume_k_voxel_by_voxel(run, field, voxel, k):
    _, data = run
    grid = field.sample(np.eye(4), 2.0 * k, 21)  # spacing 4 mm, one spacing of padding
    assert grid.spacing == 4.0
    i, j, l = voxel
    # node (i + 1, j + 1, 2 l + 1) is voxel (i, j, l): x, y every node, z (8 mm) every other
    assert grid.values[i + 1, j + 1, 2 * l + 1] == np.float32(data[i, j, l, k])
    # and the whole volume: every voxel's node holds its value
    np.testing.assert_array_equal(grid.values[1:-1, 1:-1, 1:-1:2], data[..., k].astype(np.float32))


@pytest.mark.parametrize("seed", [0, 1])
def test_a_turned_cut_is_scipys_linear_interpolation_of_the_array(run, field, seed):
    img, data = run
    zooms = [float(v) for v in img.header.get_zooms()]
    m = random_rotation(np.random.default_rng(seed))
    lo, hi = field.w_range(m)
    c0 = lo + 0.4 * (hi - lo)
    grid = field.sample(m, c0, 32)
    nodes = np.stack(np.meshgrid(*grid.axes, indexing="ij"), axis=-1).reshape(-1, 3)
    frac = _fractional_indices(field, nodes, m, c0, zooms)
    eps = 1e-6
    inside = np.all((frac > eps) & (frac < np.array(data.shape) - 1 - eps), axis=1)
    outside = np.any((frac < -eps) | (frac > np.array(data.shape) - 1 + eps), axis=1)
    got = grid.values.reshape(-1)
    assert inside.sum() > 100
    np.testing.assert_allclose(got[inside], map_coordinates(data, frac[inside].T, order=1), rtol=1e-6, atol=0)
    assert np.isnan(got[outside]).all()


def test_nibabel_comes_with_the_test_extra_and_binder():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert any(re.match(r"nibabel\b", r) for r in extras["test"])
    lines = [ln.split("#", 1)[0].strip() for ln in (ROOT / "binder" / "requirements.txt").read_text().splitlines()]
    assert any(re.match(r"nibabel\b", ln) for ln in lines), "Binder runs notebook 08: it needs nibabel"
    nb = (ROOT / "notebooks" / "08_real_fmri.ipynb").read_text()
    assert 'pip install -e \\".[test]\\"' in nb  # the notebook says where nibabel comes from
