"""Keep what you see as a JSON state file: the state, what the source is, the widget's settings.

`save_state(path, state, source, settings)` writes a JSON file with the `RotationState`
(`RotationState.to_dict`), what the source is (`describe_source`: the source's
``describe()`` plus what rebuilding it needs), the widget's settings (levels, slices,
display options: any JSON-able dict) and a format version; `load_state(path)` reads it
back as ``(state, source or None, settings)``.  A polytope is rebuilt from its name (or its
vertices); a stack from its inner source and its settings; a `Field4D` from a module-level
function (``module.name``) or from the file it was opened from (``field.origin``:
`Field4D.open` / `open_field`, or `Field4D.from_xarray` when xarray's encoding names the
file), by its path relative to the state file when the data sit in its folder, else its
absolute path, with the selection and dims it was opened with; its levels, ``inside``,
``caps``, ``w_per_unit`` and resolution restored.  An in-memory array is not written into
the file: saving says so (`SourceNotRebuildable` warning) and loading then needs the source
passed in (``load_state(path, source=field)``).  Files are written as version 1 unless a
field needs what a version-1 reader would silently drop (a selection, ``inside="below"``,
``caps=False``: version 2); both versions load.  The view settings (``rendering``, ``cmap``,
``clim``, ``sections``: `rot4d_widget.keep.recorder.VIEW_SETTINGS`) are checked when a file is
loaded (a ValueError naming what is allowed); a file without them (from before they existed)
means their defaults (`rot4d_widget.keep.recorder.VIEW_DEFAULTS`).

A state file is data, never code: loading one imports no module and calls nothing the file
names.  A field made from a function is described by the function's name
(``"module:qualname"``); `load_state` refuses to import it (`CodeNotAllowed`, a ValueError
saying how to allow it) unless asked: ``load_state(path, allow_code=True)`` for a file you
trust, ``load_state(path, function=f)`` to give the function yourself, or
``load_state(path, source=field)``.
"""

from __future__ import annotations

import json
import os
import secrets
import stat
import warnings
from typing import Mapping, NamedTuple

from ..core.state import RotationState, spacing_factor
from ..core.version import __version__
from ..sources.protocol import as_source, user_object
from .jsonfile import read_json
from .rebuild import (
    CannotRebuild,
    CodeNotAllowed,
    SourceNotRebuildable,
    describe_source,
    described_w_frame,
    inner_identity,
    jsonable,
    made_by_function,
    rebuild_source,
)
from .recorder import VIEW_SETTINGS, check_view_setting

#: The widget's settings a state file keeps, by their trait names (`settings_of` reads them;
#: `rot4d_widget.keep.pictures.state_picture.render_state` takes them as keywords).
SETTING_NAMES = ("levels", "inside", "caps", "slices", "spacing", "arrangement", "color_by", "face_opacity",
                 "ball_radius", "bar_radius", "background", "show_balls", "show_bars", "show_faces", "cmap", "clim",
                 "rendering", "sections", "projection")

#: ``"format"`` and ``"version"`` of a state file.
STATE_FILE_FORMAT = "rot4d_widget state"
STATE_FILE_VERSION = 2


def settings_of(widget) -> dict:
    """The `SETTING_NAMES` a widget (or any object) has, as JSON-able values: what `save_state`
    stores and `rot4d_widget.keep.pictures.state_picture.render_state` takes (``render_state(w.state, w.source,
    **settings_of(w))``).  A stack's ``spacing`` is None while it follows its default."""
    out = {}
    for name in SETTING_NAMES:
        if hasattr(widget, name):
            out[name] = getattr(widget, name)
    src = getattr(widget, "source", None)  # a widget's, or None for another object
    if out.get("spacing") is not None and src is not None and as_source(src).spacing_is_default:
        out["spacing"] = None
    return jsonable(out, "settings")


class LoadedState(NamedTuple):
    """What `load_state` returns: ``state, source, settings = load_state(path)``."""

    state: RotationState
    source: object
    settings: dict


def save_state(path, state: RotationState, source=None, settings: Mapping | None = None) -> dict:
    """Write ``state``, what ``source`` is and the widget's ``settings`` to the JSON file ``path``.

    ``settings`` is any dict of JSON-able values (tuples and numpy numbers are converted), for
    the widget: its traits (``levels``, ``slices``, ``spacing``, ``arrangement``,
    ``face_opacity``, ``ball_radius``, ``bar_radius``, ``background``, ``show_balls``,
    ``show_bars``, ``show_faces``, ``color_by``, ``cmap``, ``clim``, ``rendering``, ``sections``)
    -- `rot4d_widget.keep.pictures.state_picture.render_state` takes the same names; the view settings are
    checked (as `load_state` will), so no file is written that cannot be loaded.  A source that
    cannot be rebuilt (an in-memory array, a lambda) is described anyway, with a
    `SourceNotRebuildable` warning saying so.  Returns the dict written.
    The file is replaced atomically (written beside it, then renamed).
    """
    if not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    src = None
    if source is not None:
        src = describe_source(as_source(source))
        if src["rebuild"] is not True:
            warnings.warn(f"The source is described in {os.fspath(path)!r} but cannot be rebuilt from it: "
                          f"{src['rebuild']}. Loading the file will need it passed in: "
                          "load_state(path, source=...)", SourceNotRebuildable, stacklevel=2)
    settings = dict(settings or {})
    for name in VIEW_SETTINGS:
        if name in settings:
            settings[name] = check_view_setting(name, settings[name])
    if src is not None:
        _add_relative_paths(src, os.path.dirname(os.path.abspath(os.fspath(path))))
    doc = {
        "format": STATE_FILE_FORMAT,
        "version": _version_needed(src),
        "state": state.to_dict(),
        "source": src,
        "settings": jsonable(settings, "settings"),
    }

    doc["rot4d_widget"] = __version__
    text = json.dumps(doc, indent=1, allow_nan=False)
    _write_atomically(os.fspath(path), text + "\n")
    return doc


def _convert_spacing(doc, factor: float) -> None:
    """Multiply the parallel slices' spacing a state file holds (its settings', its stacks') by
    ``factor`` (`spacing_factor`: drawn units -> the source's w units), in place."""
    if factor == 1.0:
        return
    settings = doc["settings"]
    if isinstance(settings.get("spacing"), (int, float)) and not isinstance(settings["spacing"], bool):
        settings["spacing"] = float(settings["spacing"]) * factor
    d = doc.get("source")
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        if isinstance(d.get("spacing"), (int, float)) and not isinstance(d["spacing"], bool):
            d["spacing"] = float(d["spacing"]) * factor
        d = d.get("source")


def _fields_in(d):
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        d = d.get("source")
    return [d] if isinstance(d, Mapping) and d.get("kind") == "field" else []


def _add_relative_paths(desc, folder: str) -> None:
    """Give a file field's origin its path relative to the state file's ``folder`` when the data
    sit there or below it (so the folder can move, or be copied, with its data)."""
    for d in _fields_in(desc):
        origin = d.get("origin")
        if isinstance(origin, dict):
            origin.pop("relative_path", None)
        if isinstance(origin, dict) and isinstance(origin.get("path"), str):
            rel = os.path.relpath(origin["path"], folder)
            if rel != os.pardir and not rel.startswith(os.pardir + os.sep) and not os.path.isabs(rel):
                origin["relative_path"] = rel.replace(os.sep, "/")


def _version_needed(desc) -> int:
    """1 unless a field needs what version 1 readers would drop without a word: a selection of
    its file (``isel``, ``sel``: they would open the whole variable), ``inside="below"`` or
    ``caps=False`` (they would draw the other side, or close it)."""
    for d in _fields_in(desc):
        origin = d.get("origin") or {}
        if any(origin.get(k) for k in ("isel", "sel")) or d.get("inside", "above") != "above" \
                or d.get("caps", True) is not True:
            return 2
    return 1


def _write_atomically(path: str, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file beside it and `os.replace`.

    The file gets the mode ``open(path, "w")`` would leave: a replaced file keeps its own; a new
    one gets 0o666 less the umask (the temporary file is created with mode 0o666, so the
    kernel applies the umask, and default ACLs, itself -- never read or changed here)."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        keep = stat.S_IMODE(os.stat(path).st_mode)
    except FileNotFoundError:
        keep = None
    for _ in range(100):
        tmp = os.path.join(folder, f".rot4d-state-{secrets.token_hex(8)}.json")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
            break
        except FileExistsError:
            continue
    else:
        raise FileExistsError(f"Could not create a temporary file in {folder!r}")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            if keep is not None:
                os.chmod(tmp, keep)
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load_state(path, source=None, *, allow_code: bool = False, function=None) -> LoadedState:
    """Read a `save_state` file: ``(state, source, settings)``.

    The state is validated (`RotationState.from_dict`: an orientation within 1e-6 of orthogonal
    is re-orthonormalised, further off refused) and is what its ``reset()`` returns to.  The
    source is ``source`` if given -- then it must be of the kind the file describes (a
    polytope of the same name), else ``ValueError`` -- or rebuilt from the file; when it cannot
    be (an in-memory array), the source is None and a `SourceNotRebuildable` warning says why.
    ``ValueError`` names what is wrong with a file that is not a state file, or a newer one.

    A state file is data: loading it imports no module and calls no code it names.  A field
    the file describes by a function's name (``"module:qualname"``) is rebuilt with
    ``function`` (a callable ``f(x, y, z, w)``) if given, or by importing that name only when
    ``allow_code=True`` (for a file you trust: importing runs the module's code); otherwise
    `CodeNotAllowed` (a ValueError) says so and how to allow it.
    """
    if source is not None and function is not None:
        raise TypeError("Expected `source` or `function`, not both (the source already has its function)")
    allow_code = bool(allow_code)
    path = os.fspath(path)
    doc = read_json(path, "rot4d_widget state file")
    if not isinstance(doc, dict) or doc.get("format") != STATE_FILE_FORMAT:
        raise ValueError(f"{path!r} is not a rot4d_widget state file (no \"format\": \"{STATE_FILE_FORMAT}\")")
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= STATE_FILE_VERSION:
        raise ValueError(f"{path!r} is a state file of version {version!r}; this rot4d_widget reads versions "
                         f"1 ... {STATE_FILE_VERSION}")
    missing = [k for k in ("state", "source", "settings") if k not in doc]
    if missing:
        raise ValueError(f"{path!r} lacks {', '.join(map(repr, missing))}")
    frame = described_w_frame(doc.get("source"))
    try:  # a state from before c0 followed the data's units: converted by the file's own source
        state = RotationState.from_dict(doc["state"], w_frame=frame)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path!r}: bad state: {exc}") from None
    settings = doc["settings"]
    if not isinstance(settings, dict):
        raise ValueError(f"{path!r}: expected 'settings' to be a dict, got {type(settings).__name__}")
    # a spacing from before it followed the data's w units (state format 1 or 2): converted likewise
    _convert_spacing(doc, spacing_factor(doc["state"].get("format") if isinstance(doc["state"], dict) else None,
                                         frame))
    for name in VIEW_SETTINGS:  # checked here, so that nothing is set from a bad file
        if name in settings:
            try:
                settings[name] = check_view_setting(name, settings[name])
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{path!r}: bad setting {name!r}: {exc}") from None
    desc = doc["source"]
    if source is not None:  # a user's object is handed back as given, not its `UserSource`
        source = user_object(as_source(source))
        if desc is not None:
            want, got = inner_identity(desc), inner_identity(describe_source(source))
            if want != got:
                raise ValueError(f"{path!r} was saved with a source of kind {want[0]!r}"
                                 f"{'' if want[1] is None else f' ({want[1]})'}, got {got[0]!r}"
                                 f"{'' if got[1] is None else f' ({got[1]})'}")
        return LoadedState(state, source, settings)
    if function is not None and not made_by_function(desc):
        raise ValueError(f"{path!r}: `function` rebuilds a field the file describes by a function's name; "
                         f"its source is {inner_identity(desc or {})[0]!r}")
    if desc is None:
        return LoadedState(state, None, settings)
    try:
        rebuilt = rebuild_source(desc, allow_code=allow_code, function=function,
                                 base=os.path.dirname(os.path.abspath(path)))
    except CodeNotAllowed as exc:
        raise CodeNotAllowed(f"{path!r}: {exc}") from None
    except CannotRebuild as exc:
        warnings.warn(str(exc), SourceNotRebuildable, stacklevel=2)
        rebuilt = None
    except (TypeError, ValueError, KeyError) as exc:
        raise ValueError(f"{path!r}: bad source description: {exc}") from None
    return LoadedState(state, rebuilt, settings)
