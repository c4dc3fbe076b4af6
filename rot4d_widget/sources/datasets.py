"""Example 4-D fields: a simulated phase separation f[t, x, y, z], and a moving sphere.

* `phase_separation` runs a real 3-D simulation with py-pde (Allen--Cahn coarsening
  from a random initial state on a periodic grid) and returns its history as an
  ``xarray.DataArray`` with dims ``("time", "x", "y", "z")``: one 4-D field whose w
  is time (``Field4D.from_xarray(da, w="time")``).  The result is cached on disk,
  keyed by the parameters, so only the first call simulates.
* `moving_sphere` is the analytic companion: a ball of radius r moving at speed v
  along x, f = r^2 - ((x - v w)^2 + y^2 + z^2), whose space-time tube is slanted
  by arctan v in the x--w plane.

py-pde and xarray are imported only inside `phase_separation` (the ``notebooks``
extra: ``pip install "rot4d_widget[notebooks]"``).  The cache is a plain ``.npz``
file (numpy only) under `default_cache_dir`.
"""

from __future__ import annotations

import hashlib
import json
import math
import numbers
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

from .field.checks import real_number
from .field.container import Field4D

__all__ = ["phase_separation", "moving_sphere", "default_cache_dir", "phase_separation_key", "INSTALL_HINT"]

#: What to install when py-pde or xarray is missing.
INSTALL_HINT = 'pip install "rot4d_widget[notebooks]"'

#: Bump when the simulation changes in a way that changes its numbers: old cache files are
#: then no longer found (their key differs) and are simply left behind.
_SIMULATION_VERSION = 1
#: Standard deviation of the initial random state and its correlation length (in units of
#: the interface length xi): a quench from a disordered state with short-range correlations.
_INITIAL_STD = 0.5
_INITIAL_CORRELATION = 1.5
#: Largest explicit-Euler time step, and its diffusive bound's safety factor (dt <= 1/(12 xi^2)
#: for grid spacing 1: half the 3-D stability limit 1/(6 gamma)).
_DT_MAX = 0.05


def default_cache_dir() -> Path:
    """Where results are cached: ``$XDG_CACHE_HOME/rot4d_widget`` or ``~/.cache/rot4d_widget``."""
    base = os.environ.get("XDG_CACHE_HOME")
    root = Path(base) if base and os.path.isabs(base) else Path.home() / ".cache"
    return root / "rot4d_widget"


# ----------------------------------------------------------------------------- validation
def _int(value, name: str, lo: int, hi: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"Expected `{name}` to be an int in [{lo}, {hi}], got {type(value).__name__}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"Expected `{name}` in [{lo}, {hi}], got {v}")
    return v


_float = real_number  # a finite real number, or a TypeError/ValueError naming it


def _params(n, steps, t_end, interface, bias, seed) -> dict:
    n = _int(n, "n", 8, 128)
    steps = _int(steps, "steps", 2, 1000)
    t_end = _float(t_end, "t_end")
    if t_end <= 0:
        raise ValueError(f"Expected `t_end` > 0 (time of the last stored frame), got {t_end}")
    xi = _float(interface, "interface")
    # tanh(x / (sqrt(2) xi)) goes from -0.8 to 0.8 over 3.1 xi: below 0.65 that is < 2 grid
    # spacings, and rotated slices of such a field converge slowly (docs/performance.md, "Accuracy")
    if not 0.65 <= xi <= n / 8:
        raise ValueError(
            f"Expected `interface` (the interface length xi, in grid spacings) in [0.65, n/8 = {n / 8:g}], got {xi}: "
            "below 0.65 an interface spans fewer than 2 grid points; above n/8 no domains fit in the box"
        )
    bias = _float(bias, "bias")
    if not -0.5 <= bias <= 0.5:
        raise ValueError(f"Expected `bias` (the mean of the initial state) in [-0.5, 0.5], got {bias}")
    seed = _int(seed, "seed", 0, 2**63 - 1)
    return {"n": n, "steps": steps, "t_end": t_end, "interface": xi, "bias": bias, "seed": seed}


def phase_separation_key(n: int = 32, steps: int = 36, t_end: float = 35.0, interface: float = 1.0,
                         bias: float = -0.06, seed: int = 0) -> str:
    """The cache key of `phase_separation` for these parameters (validated): 16 hex digits."""
    p = _params(n, steps, t_end, interface, bias, seed)
    p["model"] = "allen-cahn"
    p["version"] = _SIMULATION_VERSION
    text = json.dumps(p, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ----------------------------------------------------------------------------- simulation
def _simulate(n: int, steps: int, t_end: float, interface: float, bias: float, seed: int, backend: str):
    """(times (steps,), coordinates (n,), values (steps, n, n, n) float32) from py-pde."""
    try:
        # py-pde (optional, the notebooks extra): imported when a simulation runs
        import pde
    except ImportError as exc:  # pragma: no cover - py-pde is in the notebooks/test extras
        raise ImportError(f"phase_separation needs py-pde: {INSTALL_HINT}") from exc

    grid = pde.CartesianGrid([[0.0, float(n)]] * 3, n, periodic=True)  # grid spacing 1
    rng = np.random.default_rng(seed)
    a = gaussian_filter(rng.standard_normal((n, n, n)), _INITIAL_CORRELATION * interface, mode="wrap")
    a *= _INITIAL_STD / a.std()
    a += bias - a.mean()
    state = pde.ScalarField(grid, a)
    eq = pde.AllenCahnPDE(interface_width=interface**2)  # py-pde's "interface_width" is gamma = xi^2
    interval = t_end / (steps - 1)
    # a whole number of Euler steps per stored frame, so frames land exactly on their times
    dt_max = min(_DT_MAX, 1.0 / (12.0 * interface**2))
    dt = interval / math.ceil(interval / dt_max - 1e-9)
    storage = pde.MemoryStorage()
    eq.solve(state, t_range=t_end + 0.5 * dt, dt=dt, tracker=[storage.tracker(interval)],
             backend=backend, solver="euler")
    times = np.asarray(storage.times, dtype=np.float64)[:steps]
    values = np.asarray(storage.data, dtype=np.float32)[:steps]
    if len(times) != steps or not np.allclose(times, interval * np.arange(steps), atol=1e-6 * max(t_end, 1.0)):
        raise RuntimeError(f"py-pde stored {len(times)} frames at {times[:4]}..., expected {steps} every {interval}")
    coords = np.asarray(grid.axes_coords[0], dtype=np.float64)
    return interval * np.arange(steps), coords, values


def _read_cache(path: Path, steps: int, n: int):
    try:
        with np.load(path, allow_pickle=False) as z:
            out = z["time"], z["coord"], z["values"]
    except Exception as exc:  # unreadable (truncated, foreign): simulate again and overwrite
        warnings.warn(f"ignoring the unreadable cache file {path}: {exc}", RuntimeWarning, stacklevel=3)
        return None
    if out[2].shape != (steps, n, n, n) or out[0].shape != (steps,) or out[1].shape != (n,):
        warnings.warn(f"ignoring the cache file {path}: it holds shape {out[2].shape}", RuntimeWarning, stacklevel=3)
        return None
    return out


def _write_cache(path: Path, times, coords, values) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    # written next to its final name, then renamed: a reader never sees half a file
    fd, tmp = tempfile.mkstemp(prefix=path.stem + ".", suffix=".tmp.npz", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez_compressed(fh, time=times, coord=coords, values=values)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes it private; a cache may be shared
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def phase_separation(n: int = 32, steps: int = 36, t_end: float = 35.0, interface: float = 1.0,
                     bias: float = -0.06, seed: int = 0, cache_dir=None, *, backend: str = "numpy"):
    """Allen--Cahn phase separation in 3-D: the order parameter c[t, x, y, z] of a coarsening mixture.

    Solves ``dc/dt = xi^2 lap(c) + c - c^3`` (py-pde's `AllenCahnPDE` with gamma = xi^2) on a
    periodic ``n^3`` grid of spacing 1, explicit Euler, from a random initial state (Gaussian
    noise smoothed over 1.5 xi, standard deviation 0.5, mean ``bias``, from ``seed``).  Domains
    of c = +1 and c = -1 form within a few time units, separated by interfaces
    c ~ tanh(s / (sqrt 2 xi)) about 3 xi wide; then the interfaces shrink (mean-curvature flow)
    and the free energy ``F = sum(xi^2/2 |grad c|^2 + (1 - c^2)^2 / 4)`` never increases.
    With the default ``bias = -0.06`` the phase c = +1 starts as the minority (46 % of the box
    for the defaults) and breaks up into droplets that shrink and vanish (5 % left at t = 35),
    so the surface c = 0 encloses droplets; with ``bias = 0`` the two phases stay interwoven
    for longer, with ``bias = -0.1`` the droplets are gone by t = 30.

    Parameters
    ----------
    n : int in [8, 128] -- grid points per side (the box is n x n x n grid spacings)
    steps : int in [2, 1000] -- stored frames, at t = 0, t_end/(steps-1), ..., t_end
    t_end : float > 0 -- time of the last frame (time unit: 1 / the linear growth rate)
    interface : float in [0.65, n/8] -- the interface length xi, in grid spacings
        (0.65 puts 2 grid points across the interface; the default 1.0 about 3)
    bias : float in [-0.5, 0.5] -- the mean of the initial state (an off-critical quench)
    seed : int >= 0 -- the random initial state
    cache_dir : path, None or False -- where the result is kept between calls
        (None: `default_cache_dir`; False: neither read nor written).  The file is
        ``phase_separation-<key>.npz`` with ``key = phase_separation_key(...)``.
    backend : "numpy" (default: no compilation) or "numba" (py-pde compiles its
        operators first, ~40 s on a 2-core machine, then steps faster: for big grids).
        Not part of the cache key: both give the same numbers up to rounding.

    Returns
    -------
    xarray.DataArray, float32, dims ("time", "x", "y", "z"), shape (steps, n, n, n),
    coordinates time (0 ... t_end) and x, y, z (cell centres 0.5 ... n - 0.5), name "c",
    attrs units, long_name, description, the parameters and ``cache_key``.

    Measured on a 2-core machine (shared): defaults 32^3 x 36 frames, ~3 s with the numpy
    backend (~50 s with numba, mostly compilation); a cached call ~0.02 s.
    """
    p = _params(n, steps, t_end, interface, bias, seed)
    if backend not in ("numpy", "numba"):
        raise ValueError(f"Expected `backend` to be 'numpy' or 'numba', got {backend!r}")
    try:
        # xarray (optional, the data extra): imported when a data set is made
        import xarray as xr
    except ImportError as exc:  # pragma: no cover - in the data/notebooks extras
        raise ImportError(f"phase_separation returns an xarray.DataArray: {INSTALL_HINT}") from exc
    key = phase_separation_key(**p)
    path = None
    if cache_dir is not False:
        root = default_cache_dir() if cache_dir is None else Path(os.fspath(cache_dir)).expanduser()
        path = root / f"phase_separation-{key}.npz"
    got = _read_cache(path, p["steps"], p["n"]) if path is not None and path.is_file() else None
    if got is None:
        got = _simulate(p["n"], p["steps"], p["t_end"], p["interface"], p["bias"], p["seed"], backend)
        if path is not None:
            _write_cache(path, *got)
    times, coords, values = got
    spatial = {"units": "grid spacing"}
    da = xr.DataArray(
        values,
        dims=("time", "x", "y", "z"),
        coords={
            "time": ("time", times, {"units": "t.u.", "long_name": "time, in units of 1 / (linear growth rate)"}),
            "x": ("x", coords, spatial), "y": ("y", coords, spatial), "z": ("z", coords, spatial),
        },
        name="c",
        attrs={
            "units": "1",
            "long_name": "order parameter c (+1 and -1: the two phases)",
            "description": "Allen-Cahn phase separation from a random initial state (py-pde), periodic box",
            "model": "dc/dt = xi^2 lap(c) + c - c^3",
            **{k: v for k, v in p.items()},
            "cache_key": key,
        },
    )
    return da


# ----------------------------------------------------------------------------- analytic
def moving_sphere(v: float = 0.75, radius: float = 0.5, *, t_max: float = 1.0, margin: float = 0.3, **kwargs):
    """A ball of ``radius`` moving at speed ``v`` along x, as a 4-D field (w is time).

    ``f(x, y, z, w) = radius^2 - ((x - v w)^2 + y^2 + z^2)``: the slice w = t is the ball
    centred at (v t, 0, 0); {f >= 0} in 4-D is a round tube slanted by arctan v in the
    x--w plane.  Turned by theta = arctan v in that plane (``simple_rotation("xw", theta)``)
    the tube stands upright and every slice w = c0 is the same ellipsoid, semi-axes
    ``radius / sqrt(1 + v^2)`` along x and ``radius`` along y and z (the tube's perpendicular
    cross-section).

    The box: w in [-t_max, t_max], x in +-(|v| t_max + radius + margin), y and z in
    +-(radius + margin).  Further keyword arguments go to `Field4D.from_function`
    (``resolution``, ``levels`` ...); ``levels`` defaults to ``[0.0]``.
    Returns a `rot4d_widget.sources.field.container.Field4D`.
    """
    v = _float(v, "v")
    r = _float(radius, "radius")
    if r <= 0:
        raise ValueError(f"Expected `radius` > 0, got {r}")
    t_max = _float(t_max, "t_max")
    if t_max <= 0:
        raise ValueError(f"Expected `t_max` > 0, got {t_max}")
    margin = _float(margin, "margin")
    if margin < 0:
        raise ValueError(f"Expected `margin` >= 0, got {margin}")
    hx = abs(v) * t_max + r + margin
    hy = r + margin

    def moving_ball(x, y, z, w):
        return r * r - ((x - v * w) ** 2 + y * y + z * z)

    kwargs.setdefault("levels", [0.0])
    kwargs.setdefault("name", f"ball r={r:g} moving at v={v:g}")
    return Field4D.from_function(moving_ball, ((-hx, hx), (-hy, hy), (-hy, hy), (-t_max, t_max)), **kwargs)
