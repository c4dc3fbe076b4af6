"""What a `Field4D` checks: its numbers, levels, resolutions and extent, the axes' names, and a
field function's output; the warnings a field gives.  Every message names what is allowed."""

from __future__ import annotations

import math
import numbers

import numpy as np

from ...geometry.mesh import COORDINATE_RANGE, check_scale

__all__ = ["AxesWarning", "NonFiniteWarning", "MAX_SAMPLE_BYTES", "BYTES_PER_SAMPLE"]

#: A step may hold at most this many bytes of samples (about `BYTES_PER_SAMPLE` per grid point).
MAX_SAMPLE_BYTES = 2 * 1024**3
#: Working bytes per grid point: f and g (float64), v (float32), marching cubes' own.
BYTES_PER_SAMPLE = 24
AXES = "xyzw"


class AxesWarning(UserWarning):
    """Kept for code that filters it; `Field4D(array)` without ``axes=`` is now a TypeError."""


class NonFiniteWarning(RuntimeWarning):
    """The data hold NaN or +-inf samples: how many, and where in w (reported once per field)."""


class UnitsWarning(UserWarning):
    """Data read from xarray name no units for their values or coordinates: which, and the attribute
    to set (once per field)."""


def axes_text(axes: str) -> str:
    """'wzyx' -> 'f[w, z, y, x]': which of x, y, z, w each array axis is."""
    return "f[" + ", ".join(axes) + "]"


def real_number(value, name: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a real number, got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"Expected `{name}` to be finite, got {v}")
    return v


def as_levels(level) -> tuple:
    """A number or a non-empty sequence of numbers -> tuple of finite floats."""
    if isinstance(level, (numbers.Real, np.integer, np.floating)) and not isinstance(level, (bool, np.bool_)):
        return (real_number(level, "level"),)
    try:
        items = list(np.asarray(level, dtype=object).ravel()) if not isinstance(level, (str, bytes)) else None
    except Exception:
        items = None
    if not items:
        raise TypeError(f"Expected `level` to be a real number or a non-empty sequence of them, got {level!r}")
    return tuple(real_number(v, f"level[{i}]") for i, v in enumerate(items))


def check_resolution(resolution, name: str = "resolution") -> int:
    if isinstance(resolution, (bool, np.bool_)) or not isinstance(resolution, (numbers.Integral, np.integer)):
        raise TypeError(f"Expected `{name}` to be an int >= 2, got {type(resolution).__name__}")
    r = int(resolution)
    if r < 2:
        raise ValueError(f"Expected `{name}` >= 2 (samples along the longest side), got {r}")
    need = r**3 * BYTES_PER_SAMPLE
    if need > MAX_SAMPLE_BYTES:
        r_max = int((MAX_SAMPLE_BYTES / BYTES_PER_SAMPLE) ** (1 / 3))
        raise ValueError(
            f"`{name}`={r} would need up to {_bytes_text(need)} of samples ({r}^3 points x "
            f"{BYTES_PER_SAMPLE} bytes); the limit is {_bytes_text(MAX_SAMPLE_BYTES)} "
            f"(rot4d_widget.sources.field.checks.MAX_SAMPLE_BYTES), i.e. resolution <= {r_max}"
        )
    return r


def _bytes_text(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} TiB"  # pragma: no cover


def check_extent(extent) -> tuple:
    try:
        e = np.array(extent, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError("Expected `extent` to be ((xmin, xmax), (ymin, ymax), (zmin, zmax), (wmin, wmax)) of "
                        "real numbers") from None
    if e.shape != (4, 2):
        raise ValueError(f"Expected `extent` to have shape (4, 2): ((xmin, xmax), ..., (wmin, wmax)), got {e.shape}")
    if not np.all(np.isfinite(e)):
        raise ValueError(f"Expected `extent` to be finite, got {e.tolist()}")
    bad = [AXES[d] for d in range(4) if not e[d, 0] < e[d, 1]]
    if bad:
        raise ValueError(f"Expected min < max in `extent` for every axis; not so for {', '.join(bad)}: {e.tolist()}")
    lo, hi = COORDINATE_RANGE
    for d in range(4):
        end = float(np.abs(e[d]).max())
        if end > hi:
            raise ValueError(f"`extent` of {AXES[d]} reaches {end:.3g}; expected |ends| <= {hi:g} and half widths "
                             f"{lo:g} to {hi:g} (rot4d_widget.geometry.mesh.COORDINATE_RANGE; "
                             f"rescale the coordinates, "
                             f"e.g. to other units)")
        check_scale(float(e[d, 1] - e[d, 0]) / 2, f"The half width of `extent` along {AXES[d]}")
    return tuple((float(a), float(b)) for a, b in e)


def check_positive(value, name: str) -> float:
    v = real_number(value, name)
    if v <= 0:
        raise ValueError(f"Expected `{name}` > 0, got {v}")
    return v


def checked_call(f, *arrays) -> np.ndarray:
    """``f(*arrays)`` validated: same shape as the inputs, real numbers -> float64."""
    out = f(*arrays)
    try:
        out = np.asarray(out)
    except Exception:
        raise TypeError(f"Expected the field function to return an array, got {type(out).__name__}") from None
    if out.dtype.kind not in "fiub":
        raise TypeError(f"Expected the field function to return real numbers (float, int or bool), "
                        f"got dtype {out.dtype}")
    if out.shape != arrays[0].shape:
        raise ValueError(
            f"Expected the field function to return one value per point, shape {arrays[0].shape}, got {out.shape} "
            "(write it with numpy operations on its arguments; for a constant use c + 0 * x)"
        )
    return out.astype(np.float64, copy=False)
