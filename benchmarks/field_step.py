"""One step of a 4-D field source, timed in parts: resampling, marching cubes, and scipy as yardstick.

Two fields (float32, in memory):

* ``sphere 64^4``: f = R^2 - |q|^2 on a 64^4 grid over [-1, 1]^4, R = 0.8, level 0;
* ``Allen-Cahn 32^3x36``: notebook 04's simulation (`rot4d_widget.sources.datasets.phase_separation`),
  c[t, x, y, z] from py-pde, level 0;
* ``blob 128^3x32``: a Gaussian blob travelling along x as t grows plus a smooth
  random field, f[x, y, z, t] with the default extent (w = sample index, cubic voxels).

For each field, ``--orientations`` fixed random orientations (seed 0), c0 = 0.1
(slice units), one step at the coarse resolution on the coarse copy and one at the
full resolution; each part's time is the best of ``--repeats`` runs, the table shows
the median over orientations:

* resample: the whole resampling of a step (box cut, grid, numba kernel);
* kernel: the numba quadrilinear kernel alone, as the step runs it (parallel from
  `PARALLEL_MIN_POINTS` grid points on), and in brackets its serial build;
* map_coordinates: ``scipy.ndimage.map_coordinates(order=1, prefilter=False)`` on the
  same grid points (all of them, as a resampler without the box test would do; and
  only those inside the box, which is all the kernel interpolates);
* marching cubes: `level_surface` for the one level (min with the box distance, skimage
  Lewiner, winding, normals, volume);
* whole step: `Field4D.slice` (the above plus the box's cut as bars, readout, `SliceData`);
* bytes: what the slice would send as float32 positions + normals and uint32 indices.

    python benchmarks/field_step.py [--orientations 5] [--repeats 3] [--resolution 64]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates

from rot4d_widget.sources.field.kernels import PARALLEL_MIN_POINTS, _get_kernels, resample_affine
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.field.slicing import slice_samples
from rot4d_widget.sources.field.surface import level_surface
from rot4d_widget.core.rotation import random_rotation


def sphere_field(n: int = 64, R: float = 0.8) -> Field4D:
    x = np.linspace(-1, 1, n, dtype=np.float32)
    r2 = x[:, None, None] ** 2 + x[None, :, None] ** 2 + x[None, None, :] ** 2  # (n, n, n)
    a = np.empty((n, n, n, n), dtype=np.float32)
    for i, w in enumerate(x):
        a[..., i] = R * R - r2 - w * w
    f = Field4D(a, axes="xyzw", extent=((-1, 1),) * 4, name="sphere")
    f.levels = 0.0
    return f


def blob_field(n: int = 128, nt: int = 32, seed: int = 0) -> Field4D:
    rng = np.random.default_rng(seed)
    x = np.linspace(-1, 1, n, dtype=np.float32)
    noise = gaussian_filter(rng.standard_normal((n // 4,) * 3).astype(np.float32), 2, mode="wrap")
    noise = np.kron(noise / noise.std(), np.ones((4, 4, 4), dtype=np.float32))  # (n, n, n), smooth enough
    yz = x[None, :, None] ** 2 + x[None, None, :] ** 2
    a = np.empty((n, n, n, nt), dtype=np.float32)
    for t in range(nt):
        cx = -0.6 + 1.2 * t / (nt - 1)
        a[..., t] = np.exp(-((x[:, None, None] - cx) ** 2 + yz) / 0.15) + 0.15 * noise
    f = Field4D(a, axes="xyzw", name="blob")
    f.levels = 0.5
    return f


def simulation_field() -> Field4D:
    """Notebook 04's data: py-pde's Allen-Cahn coarsening, c[t, x, y, z] (cached after the first run)."""
    from rot4d_widget.sources.datasets import phase_separation

    return Field4D.from_xarray(phase_separation(), w="time", levels=[0.0])


def best(fn, repeats: int):
    out, ts = None, []
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return out, min(ts)


def kernel_inputs(field, m, c0, s):
    """The affine-grid arguments `slice_samples` gives the kernel (numpy arrays: no block offset)."""
    hw = field._hw
    sc = np.array([(field.shape[j] - 1) / (2 * hw[j]) for j in range(4)])
    base_d = (m.T @ np.array([*s.origin, c0]) + hw) * sc
    step_d = s.spacing * m[:3, :] * sc
    base, step, centre, inv_s = np.empty(4), np.empty((3, 4)), np.empty(4), np.empty(4)
    for j in range(4):
        a = field._axis_of[j]
        base[a], step[:, a] = base_d[j], step_d[:, j]
        centre[a], inv_s[a] = (field.shape[j] - 1) / 2, 1 / sc[j]
    return base, step, centre, inv_s


def slice_step(field, m, c0, res):
    """The whole source step the widget calls (`Field4D.slice`) at resolution ``res``."""
    keep = field.resolution
    field.resolution = res
    try:
        return field.slice(m, c0)
    finally:
        field.resolution = keep


def measure(field: Field4D, res: int, orientations: int, repeats: int, c0: float = 0.1) -> dict:
    rng = np.random.default_rng(0)
    rows = []
    arr = field.values
    for _ in range(orientations):
        m = random_rotation(rng)
        s, t_res = best(lambda: slice_samples(field, m, c0, res), repeats)
        base, step, centre, inv_s = kernel_inputs(field, m, c0, s)
        (f, g), t_k = best(lambda: resample_affine(arr, base, step, s.f.shape, centre, centre, inv_s), repeats)
        assert np.array_equal(f, s.f)
        serial = _get_kernels(False)[0]
        fo, go, nn = np.empty(s.f.shape), np.empty(s.f.shape), np.array(s.f.shape, dtype=np.int64)
        _, t_ser = best(lambda: serial(arr, base, step, nn, centre, centre, inv_s, fo, go), repeats)
        idx = base[:, None] + step.T @ np.indices(s.f.shape, dtype=np.float64).reshape(3, -1)
        inside = g.ravel() >= 0
        ref, t_all = best(lambda: map_coordinates(arr, idx, order=1, prefilter=False, mode="nearest"), repeats)
        idx_in = np.ascontiguousarray(idx[:, inside])
        _, t_in = best(lambda: map_coordinates(arr, idx_in, order=1, prefilter=False, mode="nearest"), repeats)
        err = float(np.abs(ref[inside] - f.ravel()[inside]).max())
        surf, t_mc = best(lambda: level_surface(s, field.levels[0]), repeats)
        _, t_step = best(lambda: slice_step(field, m, c0, res), repeats)
        nv, nt = len(surf.vertices), len(surf.triangles)
        rows.append(dict(step=t_step, res=t_res, kernel=t_k, serial=t_ser, all=t_all, inside_t=t_in, mc=t_mc, grid=s.f.size,
                         inside=float(inside.mean()), tri=nt, bytes=nv * 24 + nt * 12, err=err))
    return {k: statistics.median(r[k] for r in rows) for k in rows[0]} | {"max_err": max(r["err"] for r in rows)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--orientations", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--resolution", type=int, default=64)
    args = ap.parse_args()
    fields = [("sphere 64^4", sphere_field()), ("blob 128^3x32", blob_field()),
              ("Allen-Cahn 32^3x36 (notebook 04)", simulation_field())]
    # compile (or load) the kernels outside the timing
    fields[0][1].slice(np.eye(4), 0.0)
    print(f"numba threads: {numba.get_num_threads()}, parallel kernel from {PARALLEL_MIN_POINTS} points\n")
    print("| field | step | grid points (inside) | resample ms | kernel ms (serial) | map_coordinates ms all / inside "
          "| speed-up all / inside | marching cubes ms | whole step ms | triangles | bytes | max abs diff |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, field in fields:
        field.resolution = args.resolution
        field.coarse_resolution = max(24, args.resolution // 2)
        for label, src, res in (("coarse", field.coarse(), field.coarse_resolution), ("full", field, field.resolution)):
            src.levels = field.levels
            r = measure(src, res, args.orientations, args.repeats)
            shape = "x".join(str(n) for n in src.values.shape)
            print(f"| {name} | {label} {res} on {shape} | {r['grid']:.0f} ({r['inside']:.0%}) | {r['res'] * 1e3:.1f} | "
                  f"{r['kernel'] * 1e3:.1f} ({r['serial'] * 1e3:.1f}) | {r['all'] * 1e3:.1f} / {r['inside_t'] * 1e3:.1f} | "
                  f"{r['all'] / r['kernel']:.1f}x / {r['inside_t'] / r['kernel']:.1f}x | {r['mc'] * 1e3:.1f} | "
                  f"{r['step'] * 1e3:.1f} | {r['tri']:.0f} | {r['bytes'] / 1024:.0f} KiB | {r['max_err']:.1e} |", flush=True)


if __name__ == "__main__":
    main()
