"""The source protocol: what `Rot4DWidget` shows, whatever it is.

A *source* is anything that can be cut by the hyperplane w = c0 after a 4-D
rotation.  The widget, the scene and the readout only ever see what a source
returns, so a polytope, a 4-D scalar field or a user's own object are shown
through the same keys.  A point q of the object is drawn at ``matrix @ q``
(the rotation centre is the origin of the source's own coordinates).

A source has

``slice(matrix, c0)``
    -> a slice object (see `SliceData`) for the (4, 4) rotation ``matrix`` and
    the level ``c0``, in the source's own w units (a field's: its time, in seconds
    if its w is in seconds; see ``w_frame``).
``size``
    Circumradius about the rotation centre, in the source's units: the view
    scales every source to the same displayed size, the default l/h step is
    ``size / 64`` and the c0 gauge spans ``[-size, size]``.
``n_groups``
    How many colour groups triangles can have (cells, iso levels, ...).
``describe()``
    A JSON-able dict that rebuilds the source where that is possible
    (``{"kind": "polytope", "name": "24-cell"}``), used by exports.
``actions`` (optional)
    A mapping ``key -> SourceAction``: extra keys the source brings (for
    instance a level up/down).  The widget binds them and lists them in its help.
``w_range(matrix)`` (optional)
    ``(lowest, highest)`` c0 at which w = c0 still touches the rotated object, in
    the same units as c0, for the c0 gauge (default ``(-size, size)``).
``w_frame`` (optional)
    ``(origin, per_unit)``: c0 = origin + per_unit * d, where d is the offset of
    the hyperplane from the rotation centre along the turned w axis, in the units
    the slice is drawn in.  A polytope's c0 is its own w (the default ``(0, 1)``);
    a field's is its data's w, ``(w at the box's centre, w_per_unit)``, so that
    at rest c0 = 30 cuts the data at t = 30.  The widget's l/h step, c0 bounds
    and gauge follow it; `w_frame` reads it, validated.

What the widget, exports, figures and recordings need to know of a source beyond
that comes from these optional members, never from its class (`inner_source`,
`settings_of`, `apply_setting`, `takes_coarse` read them; each has its default in `SourceBase`):

``wraps`` (optional)
    The source this one cuts in its own way, for a source made around another
    (parallel slices: `rot4d_widget.sources.tomography.StackSource`); absent or
    None for every other.  Levels, units and frames are then the inner source's.
``settings`` (optional)
    A dict ``{name: JSON-able value}`` of the settings a recording keeps and a
    state file restores (a field's ``levels``, ``inside``, ``caps``; a stack's
    ``slices``, ``spacing``, ``arrangement`` and its inner source's); with
    ``apply_setting(name, value)`` to set one (ValueError naming the allowed
    names and values).  A user's source declares its own (a thickness ...): the
    widget records them when they change (`Rot4DWidget.refresh`) and a replay
    sets them again.
``coarse_steps`` (optional)
    True when ``slice(matrix, c0, coarse=True)`` gives a cheaper slice for held
    keys (a field's coarse copy); by default read from ``slice``'s signature.
``outline(matrix, c0)`` (optional)
    A slice with the balls and bars ``slice`` gives and no surface, made without reading
    the source's data (a field's: the cut of its data box): what the widget sizes its buffers
    and its default ball radius from (`outline_of`; default: ``slice`` itself).
``prepare(progress=True)`` (optional)
    Start the background work that makes later slices fast (a field's read into memory and
    its coarse copy) and return at once: a `rot4d_widget.core.progress.Progress` counting it
    (the widget shows it in its own bar), or None when there is nothing to do
    (`prepare_in_background`; default: nothing).
``sample(matrix, c0, resolution=None, *, coarse=False)`` (optional)
    The cut's values on a regular 3-D grid (a field's `FieldGrid`: values, origin,
    spacing, units, data range): what the volume and maximum-intensity renderings
    draw (`rot4d_widget.keep.pictures.ray_caster`); a source without it has only surfaces.
Descriptions (optional) a view, a picture, a readout or an export shows when a source has them,
each None by default: ``name`` (a title; else its class's name, `source_title`), ``edge_length``
(the default ball radius), ``polytope``, a field's ``levels``, ``level_step``, ``inside``,
``caps``, ``units``, ``long_name``, ``data_range``, ``known_range``, ``extent``, ``half_widths``,
``dims``, ``axes``, ``space_units``, ``w_units``, ``w_epoch``, ``w_per_unit``, ``to_data(points,
matrix, c0)``, ``coarse_resolution`` and ``coarse_ready`` (True); a stack's ``slices`` (1),
``spacing``, ``spacing_is_default`` (False), ``cuts_at(c0)`` and ``color_by`` ("w").

**Defaults live in one place**, `SourceBase`: every optional member above (`OPTIONAL_MEMBERS`)
with its default -- a class attribute, or a method doing what a source without it gets
(``outline`` is ``slice``, ``w_range`` is ``(-size, size)``, ``prepare`` returns None,
``note_matrix`` does nothing).  The package's sources (`PolytopeSource`, `StackSource`,
`rot4d_widget.Field4D`) inherit it, and a user's may (then it is used as it is); `as_source` wraps
any other object with the four required members, once, in a `UserSource`, which reads each member
from the object every time (a change before `Rot4DWidget.refresh` is seen), the default where the
object has none, and sets every attribute on the object.  So the package reads
``source.levels``, never ``getattr(source, "levels", None)``; the helpers below (`w_frame`,
`settings_of`, `apply_setting`, `takes_coarse` ...) stay where they validate, and take a user's
object too.

``describe()`` returns everything a state file needs to rebuild the source: its
``"kind"`` and, when it cannot be rebuilt from the description, ``"rebuild"``:
the reason (a string; True or absent when it can).  A copy of a source
(``copy.copy``) is one that replaying its own actions may change without
changing the original (a stack copies its inner source too; a `UserSource` copies its object).

Rotations in the planes xy, xz and yz never change which part of a source
the hyperplane cuts, only how the cut is turned in 3-D: the slice at
``matrix`` equals the slice at ``R3 @ matrix`` turned by the 3-D rotation R3.
That is geometry, not a promise a source has to make.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import sys
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Callable, Mapping, Protocol, runtime_checkable

import numpy as np

from ..core.text import number_text
from ..geometry.catalogue import polytope as get_polytope
from ..geometry.mesh import Polytope
from ..geometry.regular import POLYTOPE_NAMES
from ..geometry.slicing.polytope_slice import slice_polytope
from ..geometry.slicing.tables import Slice
from .field_labels import axis_names, coordinate_text

__all__ = [
    "Source",
    "SourceBase",
    "UserSource",
    "OPTIONAL_MEMBERS",
    "user_object",
    "class_name",
    "source_title",
    "SliceData",
    "SourceAction",
    "PolytopeSource",
    "as_source",
    "check_slice",
    "as_slice",
    "PolytopeSlice",
    "BadSlice",
    "data_w_text",
    "note_matrix",
    "known_range",
    "w_value_text",
    "c0_text",
    "w_span_text",
    "w_frame",
    "inner_source",
    "settings_of",
    "apply_setting",
    "takes_coarse",
    "outline_of",
    "prepare_in_background",
]


@runtime_checkable
class Source(Protocol):
    """What `Rot4DWidget` shows.  See the module docstring for each member."""

    @property
    def size(self) -> float: ...

    @property
    def n_groups(self) -> int: ...

    def slice(self, matrix: np.ndarray, c0: float) -> Any: ...

    def describe(self) -> dict: ...


_NO_MAPPING: Mapping = MappingProxyType({})

#: The optional members a source may have, each with the default `SourceBase` gives it (a method's
#: default is `SourceBase`'s method of that name).  What the package reads of a source beyond
#: `Source`'s four required members is one of these, read as a plain attribute.
OPTIONAL_MEMBERS = (
    # the protocol's own (module docstring)
    "actions", "w_range", "w_frame", "wraps", "settings", "apply_setting", "coarse_steps", "outline",
    "prepare", "sample", "note_matrix",
    # descriptions a view, a picture or a readout shows when a source has them (a field's, a polytope's)
    "name", "edge_length", "polytope", "levels", "level_step", "inside", "caps", "units", "long_name",
    "data_range", "known_range", "extent", "half_widths", "dims", "axes", "space_units", "w_units",
    "w_epoch", "w_per_unit", "to_data", "coarse_ready", "coarse_resolution",
    # parallel slices' (a stack's)
    "slices", "spacing", "spacing_is_default", "cuts_at", "color_by",
)
_METHODS = ("w_range", "apply_setting", "outline", "prepare", "note_matrix")


class SourceBase:
    """Every optional member of the source protocol with its default, in one place.

    The package's sources (`PolytopeSource`, `rot4d_widget.sources.tomography.StackSource`,
    `rot4d_widget.Field4D`) inherit it, and so may a user's own source; any other object with the
    four required members is wrapped once by `as_source` in a `UserSource`, which reads each
    optional member from the object when it has it and gives this default otherwise.  So the
    package reads ``source.levels``, never ``getattr(source, "levels", None)``.

    Defaults are plain class attributes (None where "absent" has a meaning of its own: a source
    without ``sample`` has only surfaces, one without ``levels`` no iso levels) and methods doing
    what a source without the member gets; a subclass overrides any of them with an attribute, a
    property or a method (put this class last among the bases: a mixin's property wins).
    """

    # -- the protocol's optional members ------------------------------------------------------
    actions: Mapping = _NO_MAPPING  #: key -> SourceAction: none
    w_frame: tuple = (0.0, 1.0)  #: (origin, per_unit): c0 is the source's own w
    wraps = None  #: the source this one is made around (a stack's): none
    settings: Mapping = _NO_MAPPING  #: {name: JSON-able value} a recording keeps: none
    coarse_steps = None  #: None: whether ``slice`` takes ``coarse=`` is read from its signature
    sample = None  #: sample(matrix, c0, resolution=None, *, coarse=False) -> FieldGrid: surfaces only

    def w_range(self, matrix) -> tuple:
        """(lowest, highest) c0 that still touches the rotated object: (-size, size) by default."""
        return -float(self.size), float(self.size)

    def apply_setting(self, name: str, value) -> None:
        """Set one of `settings`: a source without settings has none to set."""
        raise ValueError(f"{source_title(self)} has no setting {name!r}; its settings: "
                         f"{', '.join(sorted(self.settings)) or 'none'}")

    def outline(self, matrix, c0):
        """The slice's balls and bars without reading data: by default the slice itself."""
        return self.slice(matrix, c0)

    def prepare(self, progress: bool = True):
        """Start background work; None: nothing to do."""
        return None

    def note_matrix(self, matrix) -> None:
        """The orientation the view shows now: nothing to note by default."""

    # -- descriptions read when a source has them ----------------------------------------------
    name = None  #: a title (else its class's name, `source_title`)
    edge_length = None  #: sets the default ball radius (else the first outline's median bar)
    polytope = None  #: the `Polytope` shown (a polytope source's)
    levels = None  #: iso levels (a field's); None: a source without levels
    level_step = None
    inside = None  #: "above" / "below" (a field's)
    caps = None  #: close the cut surfaces at the box (a field's)
    units = None  #: the data's units (colour bar, readout)
    long_name = None  #: the colour bar's label
    data_range = None  #: (lo, hi) of the data, when known
    known_range = None  #: (lo, hi) known without reading all the data (`known_range`)
    extent = None  #: ((x0, x1), ... (w0, w1)): a data box; None: not a record (a polytope's own w)
    half_widths = None  #: the data box's half widths in slice units
    dims = None  #: the data's dim names, in the array's order
    axes = None  #: which of x, y, z, w each array axis is ("wzyx")
    space_units = None
    w_units = None
    w_epoch = None  #: w = 0's date (numpy datetime64) when w was datetime64
    w_per_unit = None  #: w units per unit of space
    to_data = None  #: to_data(points, matrix, c0) -> (n, 4) data coordinates; None: no data box
    coarse_ready = True  #: held keys can take coarse slices now
    coarse_resolution = None

    # -- parallel slices' (a stack's) -----------------------------------------------------------
    slices = 1  #: how many parallel cuts a view shows
    spacing = None  #: their spacing in w
    spacing_is_default = False
    cuts_at = None  #: cuts_at(c0) -> the cuts' w; None: one cut at c0
    color_by = "w"


class UserSource(SourceBase):
    """A user's source as the package reads it: `as_source` wraps any object with ``slice``,
    ``size``, ``n_groups`` and ``describe()`` that does not inherit `SourceBase` in one of these.

    The required members and each optional one the object has are read from it every time (a
    user changing their object and calling `Rot4DWidget.refresh` is seen); an optional member it
    lacks has `SourceBase`'s default.  Any other attribute is the object's (``src.thickness``), and
    every attribute set goes to the object (``src.levels = ...``).  ``user_object`` is the object
    itself; ``copy.copy`` copies it.  This is the only place the package probes a user's object.
    """

    def __init__(self, obj):
        object.__setattr__(self, "_user", obj)

    @property
    def user_object(self):
        """The object given (`Rot4DWidget.source` of a user's source is this wrapper around it)."""
        return self._user

    size = property(lambda self: self._user.size)
    n_groups = property(lambda self: self._user.n_groups)
    slice = property(lambda self: self._user.slice, doc="The object's own ``slice`` (its signature too).")
    describe = property(lambda self: self._user.describe)

    @property
    def wraps(self):
        """The object's ``wraps``, read through its own `UserSource` (the same one while it is the same)."""
        inner = getattr(self._user, "wraps", None)
        if inner is None:
            return None
        kept = self.__dict__.get("_wrapped")
        if kept is None or kept[0] is not inner:
            kept = (inner, as_source(inner))
            self.__dict__["_wrapped"] = kept
        return kept[1]

    @property
    def w_frame(self):
        """The object's ``w_frame``; without one, a source made around another answers for it."""
        frame = getattr(self._user, "w_frame", None)
        if frame is None and self.wraps is not None:
            return self.wraps.w_frame
        return SourceBase.w_frame if frame is None else frame

    def __getattr__(self, name):
        if name.startswith("__") or name == "_user":
            raise AttributeError(name)
        return getattr(self._user, name)

    def __setattr__(self, name, value) -> None:
        setattr(self._user, name, value)

    def __delattr__(self, name) -> None:
        delattr(self._user, name)

    def __copy__(self) -> "UserSource":
        return UserSource(copy.copy(self._user))

    def __deepcopy__(self, memo) -> "UserSource":
        return UserSource(copy.deepcopy(self._user, memo))

    def __reduce__(self):
        return UserSource, (self._user,)

    def __repr__(self) -> str:
        return f"UserSource({self._user!r})"


def _forward(name: str):
    default = getattr(SourceBase, name)
    if name in _METHODS:
        def get(self):
            own = getattr(self._user, name, None)
            return default.__get__(self) if own is None else own
    else:
        def get(self):
            return getattr(self._user, name, default)
    return property(get, lambda self, value: setattr(self._user, name, value),
                    doc=f"The object's ``{name}``, else `SourceBase`'s default.")


for _name in OPTIONAL_MEMBERS:
    if _name not in ("wraps", "w_frame"):
        setattr(UserSource, _name, _forward(_name))
del _name


def user_object(source):
    """The object a user gave (a `UserSource`'s), else ``source`` itself."""
    return source.user_object if isinstance(source, UserSource) else source


def class_name(source) -> str:
    """The class's name of what a user gave as ``source`` (a `UserSource`'s object's), for messages."""
    return type(user_object(source)).__name__


def source_title(source) -> str:
    """What a message calls ``source``: its ``name``, else its class's name (a user's object's)."""
    source = as_source(source)
    return str(source.name) if source.name else class_name(source)


@dataclass(frozen=True)
class SourceAction:
    """An extra key action a source brings.

    ``run(sign)`` changes the source (+1 for the key, -1 for Shift+key); the
    widget then re-slices.  ``run`` returns False when it
    changed nothing (a bound reached: the widget records no step and the key's
    opposite still undoes every step made).  ``repeat``: the action repeats
    while the key is held, like a rotation.
    """

    name: str
    description: str
    run: Callable[[int], Any]
    repeat: bool = True


def _readonly(a, dtype, shape_tail, name):
    if np.issubdtype(dtype, np.integer):  # indices: never cast from floats (0.7 would point at 0)
        given = np.asarray(a)
        if given.size and given.dtype.kind not in "iu":
            raise ValueError(f"Expected `{name}` to be integer indices, got an array of {given.dtype}")
    arr = np.array(a, dtype=dtype, copy=True)
    if arr.ndim != 1 + len(shape_tail) or tuple(arr.shape[1:]) != shape_tail:
        want = "(n" + "".join(f", {s}" for s in shape_tail) + ")"
        raise ValueError(f"Expected `{name}` to have shape {want}, got {arr.shape}")
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False)
class SliceData:
    """One slice as the widget draws it; every array read-only, in the source's units.

    A kind of slice with more to say is a subclass with typed fields (`PolytopeSlice`,
    `rot4d_widget.sources.field.surface.FieldSliceData`, `rot4d_widget.sources.tomography.StackSliceData`);
    readers tell the kinds apart by class.  A source may return any object with the four required
    members: `as_slice` makes it one of these where it enters the package.

    points : (n, 3) float64 -- balls (and the corners that triangles and segments index)
    segments : (m, 2) intp -- bars, as pairs of indices into ``points``
    triangles : (k, 3) intp -- faces, indices into ``points``, counter-clockwise
        seen from outside
    groups : (k,) intp -- colour group of each triangle, in ``[0, n_groups)``
    normals : (n, 3) float64 or None -- unit normals at ``points`` (smooth shading)
    volume : float or None -- 3-volume enclosed, None if it has no meaning
    readout : tuple of (label, text) -- rows for the widget's readout
    convex : bool -- the triangles bound one convex solid: back-facing then
        front-facing order blends exactly; otherwise triangles are sorted by depth
    show_points : bool -- draw balls at ``points`` (False: points only carry corners)
    corner_only : (n,) bool or None -- True where a point only carries a corner of a filled face
        (the extra corners of a non-convex section's even-odd fill, `Slice.n_fill`): no ball there
    """

    points: np.ndarray
    segments: np.ndarray
    triangles: np.ndarray
    groups: np.ndarray
    normals: np.ndarray | None = None
    volume: float | None = None
    readout: tuple = ()
    convex: bool = False
    show_points: bool = True
    corner_only: np.ndarray | None = None

    def turned(self, rotation) -> "SliceData":
        """The same slice turned by the 3-D ``rotation`` (3, 3): points and normals turned, every
        other field kept (a subclass turns what else it must: a stack's slices about their centres).

        The slice at ``R3 @ matrix`` equals the slice at ``matrix`` turned by R3 when R3 leaves w
        alone, so a view can turn what it shows without slicing again.
        """
        r = rotation_3d(rotation)
        return self.replaced(points=self.points @ r.T, normals=None if self.normals is None else self.normals @ r.T)

    def replaced(self, **changes) -> "SliceData":
        """A copy of the same type with ``changes`` (field name -> value), validated and sealed as
        `build` does; every other field, a subclass's too, kept as it is."""
        kept = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        kept.update(changes)
        return type(self).build(**kept)

    @classmethod
    def build(cls, points, segments=None, triangles=None, groups=None, **kwargs) -> "SliceData":
        """Validate and copy: shapes, index ranges, finiteness; arrays made read-only."""
        p = _readonly(np.zeros((0, 3)) if points is None else points, np.float64, (3,), "points")
        s = _readonly(np.zeros((0, 2)) if segments is None else segments, np.intp, (2,), "segments")
        t = _readonly(np.zeros((0, 3)) if triangles is None else triangles, np.intp, (3,), "triangles")
        g = _readonly(np.zeros(len(t), dtype=np.intp) if groups is None else groups, np.intp, (), "groups")
        if g.shape != (len(t),):
            raise ValueError(f"Expected `groups` to have shape ({len(t)},), one per triangle, got {g.shape}")
        normals = kwargs.pop("normals", None)
        if normals is not None:
            normals = _readonly(normals, np.float64, (3,), "normals")
            if len(normals) != len(p):
                raise ValueError(f"Expected `normals` to have one row per point ({len(p)}), got {len(normals)}")
        corner = kwargs.pop("corner_only", None)
        if corner is not None:
            corner = np.array(corner, dtype=bool, copy=True).reshape(-1)
            if corner.shape != (len(p),):
                raise ValueError(f"Expected `corner_only` to have one flag per point ({len(p)}), got {corner.shape}")
            corner.flags.writeable = False
            kwargs["corner_only"] = corner if corner.any() else None
        data = cls(p, s, t, g, normals, **kwargs)
        check_slice(data)
        return data


def _read(source):
    """``source`` as the package reads it: itself when it inherits `SourceBase`, else `as_source`'s."""
    return source if isinstance(source, SourceBase) else as_source(source)


def w_frame(source) -> tuple:
    """``(origin, per_unit)`` of ``source``'s c0 (its ``w_frame``, default ``(0.0, 1.0)``): c0 =
    origin + per_unit * d, d the offset in the drawn units.  A stack answers for its inner source.
    TypeError / ValueError when a source offers a frame that is not two finite numbers, per_unit > 0."""
    frame = _read(source).w_frame
    if frame is None:
        return 0.0, 1.0
    try:
        origin, per = (float(v) for v in frame)
    except (TypeError, ValueError):
        raise TypeError(f"Expected a source's `w_frame` to be (origin, per_unit), two numbers, got {frame!r}") from None
    if not (math.isfinite(origin) and math.isfinite(per) and per > 0):
        raise ValueError(f"Expected a source's `w_frame` (origin, per_unit) finite with per_unit > 0, got {frame!r}")
    return origin, per


def inner_source(source):
    """The source whose geometry ``source`` shows: its ``wraps`` (a stack's inner source), else
    ``source`` itself, as given."""
    inner = _read(source).wraps
    return source if inner is None else inner


def settings_of(source) -> dict:
    """A copy of ``source``'s ``settings`` ({} for a source without), JSON-able values (tuples as lists)."""
    settings = _read(source).settings
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise TypeError(f"Expected a source's `settings` to be a dict of name -> value, got {type(settings).__name__}")
    return {str(k): list(v) if isinstance(v, tuple) else v for k, v in settings.items()}


def apply_setting(source, name: str, value) -> None:
    """Set one of ``source``'s `settings` (its ``apply_setting``); ValueError for a source without
    that setting, naming the ones it has."""
    source = _read(source)
    names = settings_of(source)
    if name not in names:
        raise ValueError(f"{source_title(source)} has no setting {name!r}; its settings: "
                         f"{', '.join(sorted(names)) or 'none'}")
    source.apply_setting(name, value)


def takes_coarse(source) -> bool:
    """True when ``source.slice`` takes ``coarse=`` (its ``coarse_steps``, else its signature)."""
    source = _read(source)
    declared = source.coarse_steps
    if declared is not None:
        return bool(declared)

    try:
        return "coarse" in inspect.signature(source.slice).parameters
    except (TypeError, ValueError):
        return False


def outline_of(source, matrix, c0):
    """``source.outline(matrix, c0)`` (the slice's balls and bars, no surface, nothing read; a
    source without one: ``source.slice(matrix, c0)``, `SourceBase.outline`)."""
    return _read(source).outline(matrix, c0)


def note_matrix(source, matrix) -> None:
    """Tell ``source`` the orientation the view shows now (its optional ``note_matrix``: a stack
    spreads its default spacing along that w when N next changes); nothing for a source without one.
    Whoever runs a source's action or changes its settings (the widget, a replay) tells it first."""
    _read(source).note_matrix(matrix)


def known_range(source, default) -> tuple:
    """``(lo, hi)`` of ``source``'s data as far as it is known without reading all of it: its
    optional ``known_range`` (a chunked field's first cut until its background read is done), else
    its ``data_range``, else ``default``.  What a view asks for colours: never a whole read."""
    source = _read(source)
    rng = source.known_range
    if rng is None:
        rng = source.data_range
    return default if rng is None else rng


def prepare_in_background(source, progress: bool = True):
    """Start ``source``'s background work (its ``prepare``: a field's read into memory and coarse
    copy) and return what counts it, a `rot4d_widget.core.progress.Progress`, or None (a source
    without ``prepare``, or nothing left to do).  ``progress``: also show the kernel's own bar
    (in the cell's output); the widget passes False and shows the returned progress in its own."""
    return _read(source).prepare(progress=progress)


def data_w_text(source, w: float, matrix=None) -> str:
    """A cut's label in the source's own w, c0's units: ``"time 30 s"`` for a field (w's name -- its
    dim's, "w" without one -- and its time in its ``w_units``), ``"w +0.5"`` for a polytope.  ``w``
    is a c0 (`w_frame`).  With ``matrix``, a field's cut that misses its data (``w`` outside
    ``w_range(matrix)``: before or after the record along that w) says so: ``"time 0.5 s (outside
    the data)"``."""
    source = _read(source)
    inner = inner_source(source)
    if inner.extent is None:
        text = number_text(w, source.size, 3)
        return f"w {'+' if not text.startswith('-') else ''}{text}"
    text = f"{axis_names(inner)[3]} {w_value_text(inner, w)}"
    if matrix is not None:
        lo, hi = (float(v) for v in inner.w_range(matrix))
        slack = 1e-9 * max(abs(lo), abs(hi), hi - lo)
        if not lo - slack <= float(w) <= hi + slack:
            text += " (outside the data)"
    return text


def w_value_text(source, w: float) -> str:
    """A field's w as a number in its ``w_units`` ("30 s"), 4 significant digits -- or, for times
    that were datetime64 (``w_epoch``), the date and time."""
    inner = inner_source(_read(source))
    lo, hi = (float(v) for v in inner.extent[3])
    if inner.w_epoch is not None:
        return coordinate_text(inner, 3, float(w), max(abs(lo), abs(hi)))
    unit = inner.w_units
    return f"{number_text(float(w), max(abs(lo), abs(hi)), 4)}{' ' + unit if unit else ''}"


def c0_text(source, c0: float):
    """How c0 reads for ``source`` when a number with its unit would not do: the date and time for a
    field whose times were datetime64 (``w_epoch``; c0 counts seconds from it), with those seconds
    -- "2021-03-04 12:05:00 (c0 = 300 s)" -- else None."""
    inner = inner_source(_read(source))
    if inner.w_epoch is None:
        return None
    return f"{w_value_text(inner, c0)} (c0 = {number_text(float(c0), 0.0, 6)} s)"


def w_span_text(source, a: float, b: float) -> str:
    """Two of a field's w as a range: "0.0021 … 0.0026 s" (the unit once), or two date-times."""
    inner = inner_source(_read(source))
    if inner.w_epoch is not None:
        return f"{w_value_text(inner, a)} \u2026 {w_value_text(inner, b)}"
    lo, hi = (float(v) for v in inner.extent[3])
    unit = inner.w_units
    big = max(abs(lo), abs(hi))
    return f"{number_text(float(a), big, 4)} \u2026 {number_text(float(b), big, 4)}{' ' + unit if unit else ''}"


class BadSlice(ValueError):
    """A source's ``slice`` returned something that breaks the protocol (the message names the
    source and the member that is wrong).  Never drawn; the widget shows the message alone."""


def check_slice(data, n_groups: int | None = None) -> None:
    """Raise ValueError (naming the member) if a slice object breaks the protocol."""
    try:
        p = np.asarray(data.points)
        s = np.asarray(data.segments)
        t = np.asarray(data.triangles)
        g = np.asarray(data.groups)
    except AttributeError as exc:
        raise TypeError(
            "Expected a slice with `points` (n, 3), `segments` (m, 2), `triangles` (k, 3) and `groups` (k,); "
            f"{exc}"
        ) from None
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"Expected `points` to have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("Expected `points` to be finite")
    for name, a, k in (("segments", s, 2), ("triangles", t, 3)):
        if a.ndim != 2 or a.shape[1] != k:
            raise ValueError(f"Expected `{name}` to have shape (m, {k}), got {a.shape}")
        if a.size and (not np.issubdtype(a.dtype, np.integer) or a.min() < 0 or a.max() >= len(p)):
            raise ValueError(f"Expected `{name}` to be integer indices into the {len(p)} points")
    if g.shape != (len(t),):
        raise ValueError(f"Expected `groups` to have shape ({len(t)},), one per triangle, got {g.shape}")
    if g.size and (not np.issubdtype(g.dtype, np.integer) or g.min() < 0):
        raise ValueError("Expected `groups` to be integers >= 0")
    if n_groups is not None and g.size and g.max() >= n_groups:
        raise ValueError(f"Expected `groups` < n_groups = {n_groups}, got {int(g.max())}")
    if isinstance(data, SliceData):  # any other object: its volume is checked as `as_slice` takes it
        _check_volume(data.volume)


def _check_volume(vol) -> None:
    if vol is not None and not (isinstance(vol, (int, float, np.floating, np.integer)) and math.isfinite(vol)):
        raise ValueError(f"Expected `volume` to be a finite number or None, got {vol!r}")


#: A slice's optional members and what a slice without one means (`SliceData`'s defaults).
_OPTIONAL_MEMBERS = {"normals": None, "volume": None, "readout": (), "convex": False, "show_points": True,
                     "corner_only": None}


def as_slice(data) -> SliceData:
    """``data`` as a `SliceData`: itself when it is one, else (any object with ``points``,
    ``segments``, ``triangles`` and ``groups``: a user's source's slice) one built from it, its
    optional members (``normals``, ``volume``, ``readout``, ``convex``, ``show_points``,
    ``corner_only``) read here, once, with `SliceData`'s defaults for those it lacks.  Where a
    slice enters the package (the view, the mesh and picture exports, a stack's pieces) it is made
    one, so that everything after reads those members directly.  TypeError / ValueError, naming
    the member, for an object that breaks the protocol (`check_slice`)."""
    if isinstance(data, SliceData):
        return data
    check_slice(data)
    members = {name: getattr(data, name, default) for name, default in _OPTIONAL_MEMBERS.items()}
    _check_volume(members["volume"])
    members["readout"] = tuple(members["readout"] or ())
    members["convex"], members["show_points"] = bool(members["convex"]), bool(members["show_points"])
    return SliceData.build(data.points, data.segments, data.triangles, data.groups, **members)


def rotation_3d(rotation) -> np.ndarray:
    """``rotation`` as a (3, 3) float64 rotation matrix; ValueError for anything else."""
    r = np.asarray(rotation, dtype=np.float64)
    if r.shape != (3, 3) or not np.allclose(r @ r.T, np.eye(3), atol=1e-9):
        raise ValueError(f"Expected `rotation` to be a (3, 3) rotation matrix, got shape {r.shape}")
    return r


# ----------------------------------------------------------------- polytopes
_POLYGON_NAMES = {
    3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon",
    7: "heptagon", 8: "octagon", 9: "nonagon", 10: "decagon",
}


def winding_row(polytope) -> tuple:
    """Readout rows for a self-intersecting polytope (`Polytope.self_intersecting`): what its
    volume means there; for one with no inside (`Polytope.volume_defined` False: hemi cells, or
    not orientable) that it has none, and why (`no_volume_row`)."""
    if not getattr(polytope, "self_intersecting", False):
        return ()
    if not getattr(polytope, "volume_defined", True):
        return (("self-intersecting", "yes"),) + no_volume_row(polytope)
    return (("self-intersecting", "yes: the volume counts each region as often as the boundary winds round it"),)


def no_volume_row(polytope) -> tuple:
    """``(("volume", "none (not orientable)"),)`` or ``"none (hemi cells)"`` for a polytope whose
    slices have no volume (`Polytope.volume_defined` False: `Slice.volume` is None), else ``()``."""
    if getattr(polytope, "volume_defined", True):
        return ()
    return (("volume", f"none ({getattr(polytope, 'why_no_volume', None) or 'not defined'})"),)


def _volume_or_none(s):
    """A polytope slice's volume, or None where it has none (a hemi or non-orientable polytope's:
    `Slice.volume` None) or left float64's range (inf beyond coordinates of about 1e102, or a solid
    slice's volume underflowed below about 1e-102)."""
    if s.volume is None:
        return None
    v = float(s.volume)
    if not math.isfinite(v) or (s.dim == 3 and abs(v) < sys.float_info.min):
        return None
    return v


def census_text(s) -> str:
    """A polytope slice's faces in words: ``"8 triangles, 6 quadrilaterals"``."""
    if s.dim < 0:
        return "empty (w = c0 misses it)"
    census = s.face_census()
    if not census:
        return f"touches it ({'vertex' if s.dim == 0 else 'edge' if s.dim == 1 else 'face'})"
    parts = []
    for n, count in sorted(census.items()):
        name = _POLYGON_NAMES.get(n, f"{n}-gon")
        parts.append(f"{count} {name}{'' if count == 1 else 's'}")
    return ", ".join(parts)


@dataclass(frozen=True, eq=False)
class PolytopeSlice(SliceData):
    """`SliceData` of a polytope, keeping the full `Slice` as ``slice``.  `turned` keeps ``slice`` as it
    is, the unturned cut.  The `Slice`'s own members users read (``w.slice.face_census()``,
    ``.vertices``, ``.cell_ids``, ``.dim`` ...) are named here one by one, each the unturned cut's."""

    slice: Slice | None = None

    vertices = property(lambda self: self.slice.vertices, doc="The cut's vertices (`Slice.vertices`).")
    edges = property(lambda self: self.slice.edges, doc="The cut's edges (`Slice.edges`).")
    polygon_indices = property(lambda self: self.slice.polygon_indices, doc="`Slice.polygon_indices`.")
    polygon_offsets = property(lambda self: self.slice.polygon_offsets, doc="`Slice.polygon_offsets`.")
    cell_ids = property(lambda self: self.slice.cell_ids, doc="Each polygon's 4-D cell (`Slice.cell_ids`).")
    triangle_cells = property(lambda self: self.slice.triangle_cells, doc="`Slice.triangle_cells`.")
    dim = property(lambda self: self.slice.dim, doc="The cut's dimension (`Slice.dim`).")
    n_fill = property(lambda self: self.slice.n_fill, doc="Fill corners at the end of ``vertices``.")

    def polygons(self) -> list:
        """`Slice.polygons`: each polygon's vertex indices."""
        return self.slice.polygons()

    def polygon_sizes(self) -> np.ndarray:
        """`Slice.polygon_sizes`."""
        return self.slice.polygon_sizes()

    def face_census(self) -> dict:
        """`Slice.face_census`: ``{sides: how many polygons}``."""
        return self.slice.face_census()

    def __repr__(self) -> str:
        return f"PolytopeSlice({self.slice!r})"


def fill_flags(s):
    """(n,) bool, read-only, True at a `Slice`'s last ``n_fill`` vertices (fill corners), or None."""
    n_fill = int(s.n_fill)
    if not n_fill:
        return None
    flags = np.zeros(len(s.vertices), dtype=bool)
    flags[len(flags) - n_fill:] = True
    flags.flags.writeable = False
    return flags


class PolytopeSource(SourceBase):
    """A 4-polytope (convex or not) as a source: groups are its cells, the slice is exact."""

    def __init__(self, polytope):
        self.polytope = get_polytope(polytope)

    @property
    def size(self) -> float:
        return float(self.polytope.circumradius)

    @property
    def n_groups(self) -> int:
        return max(1, len(self.polytope.cells))

    @property
    def name(self) -> str:
        return self.polytope.name

    @property
    def edge_length(self) -> float:
        """Length of the polytope's first edge (sets the default ball radius)."""
        v, e = self.polytope.vertices, self.polytope.edges
        return float(np.linalg.norm(v[e[0, 0]] - v[e[0, 1]])) if len(e) else self.size

    def w_range(self, matrix) -> tuple:
        w = self.polytope.vertices @ np.asarray(matrix)[3]
        return float(w.min()), float(w.max())

    def slice(self, matrix, c0) -> PolytopeSlice:
        s = slice_polytope(self.polytope, matrix, c0)
        return PolytopeSlice(
            points=s.vertices,
            segments=s.edges,
            triangles=s.triangles,
            groups=s.triangle_cells,
            normals=None,
            volume=_volume_or_none(s),
            readout=(("slice", census_text(s)),) + winding_row(self.polytope),
            convex=bool(self.polytope.convex),  # the slice of a non-convex polytope may be non-convex
            slice=s,
            corner_only=fill_flags(s),
        )

    def describe(self) -> dict:
        """``{"kind": "polytope", "name": ...}``; a polytope that is not one of the named six as
        `polytope(name)` builds them (a scaled pentachoron, a uniform polychoron, one read from 4OFF,
        possibly non-convex) adds its vertices, faces and cells (a non-convex polytope is not the
        hull of its vertices).  Always rebuildable: no ``"rebuild"`` key (the protocol's default)."""
        p = self.polytope
        d = {"kind": "polytope", "name": p.name}
        if p.name not in POLYTOPE_NAMES or not np.array_equal(np.asarray(p.vertices),
                                                              np.asarray(get_polytope(p.name).vertices)):
            d["vertices"] = np.asarray(p.vertices).tolist()
            d["faces"] = [np.asarray(f).tolist() for f in p.faces]
            d["cells"] = [np.asarray(c).tolist() for c in p.cells]
        return d

    def __repr__(self) -> str:
        return f"PolytopeSource({self.polytope.name!r})"


def _data_hint(obj) -> str:
    """What to write instead when ``obj`` is data rather than a source: an xarray DataArray or
    Dataset, or an array (numpy, dask, zarr) -- "" for anything else."""
    kind = type(obj)
    module = (kind.__module__ or "").split(".")[0]
    if module == "xarray" and kind.__name__ == "DataArray":
        return ("; an xarray.DataArray is a field: Rot4DWidget(Field4D.from_xarray(da)) (dims found by name, "
                "or named: Field4D.from_xarray(da, w='time'))")
    if module == "xarray" and kind.__name__ == "Dataset":
        return ("; an xarray.Dataset holds fields: Rot4DWidget(Field4D.from_xarray(ds, 'T')) with the "
                "variable's name (a state file can then reopen its file)")
    if isinstance(obj, np.ndarray) or module in ("dask", "zarr"):
        return ("; a 4-D array is a field: Rot4DWidget(Field4D(a, axes='wzyx')) (axes: which of x, y, z, w "
                "each array axis is), or Field4D.from_xarray for a DataArray")
    return ""


def as_source(obj):
    """A polytope name, a `Polytope` or any `Source` -> a source the package reads by plain
    attributes: a `SourceBase` as it is (the package's own sources, or a user's that inherits it),
    any other object with the required members wrapped in a `UserSource` (once: as_source of a
    `UserSource` is itself).

    Raises TypeError naming what is allowed.
    """
    if isinstance(obj, (str, Polytope)):
        return PolytopeSource(obj)
    if isinstance(obj, UserSource):  # checked when it was made
        return obj
    missing = [m for m in ("slice", "size", "n_groups", "describe") if not hasattr(obj, m)]
    if missing:
        raise TypeError(
            "Expected a polytope name (e.g. '24-cell'), a rot4d_widget.Polytope or a source with "
            f"slice(matrix, c0), size, n_groups and describe(); {type(obj).__name__} lacks {', '.join(missing)}"
            + _data_hint(obj)
        )
    if not callable(obj.slice) or not callable(obj.describe):
        raise TypeError("Expected `source.slice` and `source.describe` to be methods")
    size = obj.size
    if isinstance(size, bool) or not isinstance(size, (int, float, np.integer, np.floating)) or not (
        math.isfinite(size) and size > 0
    ):
        raise ValueError(f"Expected `source.size` to be a finite number > 0, got {size!r}")
    n = obj.n_groups
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"Expected `source.n_groups` to be an int >= 1, got {n!r}")
    return obj if isinstance(obj, SourceBase) else UserSource(obj)
