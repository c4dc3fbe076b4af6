"""Keep what you see: the widget's façade over `rot4d_widget.keep` (figures, meshes, state files,
recordings).

`Keeper` renders the view without a browser, exports its slice as a mesh, saves and loads the
state, records every step and setting (also a user's source's own settings, read through the
source protocol's ``settings``, and the view settings: ``rendering``, ``cmap``, ``clim``,
``sections``, ``projection``) and replays recordings onto the widget.
"""

from __future__ import annotations

import inspect
import os

from ..core.state import without_source_keys
from ..keep.animation import render_animation
from ..keep.meshes import slice_mesh
from ..keep.recorder import VIEW_DEFAULTS, VIEW_SETTINGS, Recorder, Recording, check_view_setting
from ..keep.statefile import SETTING_NAMES, load_state, save_state
from ..keep.statefile import settings_of as widget_settings
from ..sources.protocol import apply_setting, inner_source, note_matrix, settings_of

__all__ = ["Keeper", "view_settings"]


def view_settings(widget) -> dict:
    """What a state file keeps of the widget's settings (`keep.statefile.settings_of`: its
    `SETTING_NAMES`, the view settings among them; a tuple as a list)."""
    return widget_settings(widget)


#: View settings a recording's ``initial_view`` holds only when they differ from this default (a
#: recording or file without them -- from before they existed -- means the default: off).
_OPTIONAL_VIEW = {"projection": False}


def _view_now(widget) -> dict:
    """The widget's view settings (those of `VIEW_SETTINGS` it has as traits), as recorded;
    ``projection`` only when on (`_OPTIONAL_VIEW`)."""
    view = {n: check_view_setting(n, getattr(widget, n)) for n in VIEW_SETTINGS if widget.has_trait(n)}
    return {n: v for n, v in view.items() if _OPTIONAL_VIEW.get(n, _MISSING) != v}


def _taken_by_render_state(settings: dict) -> dict:
    """``settings`` less the names `render_state` does not take (a trait newer than it)."""
    from ..keep.pictures.state_picture import render_state  # matplotlib: imported when a figure is drawn

    takes = inspect.signature(render_state).parameters
    return {k: v for k, v in settings.items() if k in takes}


class Keeper:
    """One widget's recorder and the keep-what-you-see methods it delegates to."""

    def __init__(self, widget, state, clock):
        self.w = widget
        view = _view_now(widget)  # the traits' defaults: the constructor's values are recorded at t = 0
        self.recorder = Recorder(state, clock=clock, source_settings=settings_of(widget.source), view_settings=view)
        self.recorded_settings = settings_of(widget.source)  # the source's settings as last recorded
        self.recorded_view = view  # the view settings as last recorded
        # every change of a view trait is recorded (the constructor's too: watched from before it
        # sets them); the widget's keys and observers may say so as well: recorded once
        widget.observe(self._on_view_trait, names=[n for n in VIEW_SETTINGS if widget.has_trait(n)])

    # -- recording --------------------------------------------------------------------------
    def restart(self) -> None:
        """Forget what was recorded; record from the current state and source settings on."""
        w = self.w
        view = _view_now(w)
        self.recorder.restart(w.state, settings_of(w.source), view)
        self.recorded_settings = settings_of(w.source)
        self.recorded_view = view

    def record_source(self, name, value) -> None:
        """A source setting changed (a trait, a key): recorded, and remembered as recorded."""
        self.recorder.record_source(name, value)
        self.recorded_settings = settings_of(self.w.source)

    def record_view(self, name, value) -> None:
        """A view setting (``rendering``, ``cmap``, ``clim``, ``sections``) a user changed (a
        trait, a key): recorded, and remembered as recorded; a value equal to the one last
        recorded is not recorded again (a trait's observer and the key that set it both say so)."""
        if self.recorded_view.get(name, _OPTIONAL_VIEW.get(name, _MISSING)) == check_view_setting(name, value):
            return
        event = self.recorder.record_view(name, value)
        self.recorded_view[name] = event.value

    def _on_view_trait(self, change) -> None:
        name, new = change["name"], change["new"]
        samples = callable(getattr(inner_source(self.w.source), "sample", None))  # the protocol's optional grid
        if name == "rendering" and new != "surface" and not samples:
            return  # refused by the widget's own observer (only a field has more than the surface)
        self.record_view(name, new)

    def note_settings(self) -> None:
        """The source changed through a recorded step (its own key): its settings are as recorded."""
        self.recorded_settings = settings_of(self.w.source)

    def record_changed_settings(self) -> list:
        """The source's settings that changed since last recorded (a user's source changed in
        code, then `refresh`), recorded as source settings; returns their names.  (The view
        settings are traits, recorded as they change: `record_view`.)"""
        now = settings_of(self.w.source)
        changed = [k for k, v in now.items() if self.recorded_settings.get(k, _MISSING) != v]
        for name in changed:
            self.recorder.record_source(name, now[name])
        self.recorded_settings = now
        return changed

    def replay(self, recording) -> None:
        w = self.w
        if not isinstance(recording, Recording):
            if not isinstance(recording, (str, os.PathLike)):
                raise TypeError(f"Expected a Recording or a path to one, got {type(recording).__name__}")
            recording = Recording.load(recording)
        with w._pump.lock:
            w._check_open()
            recording.replay(w.state, _LiveSource(w), set_source=self.set_source_setting,
                             set_view=self.set_view_setting)
            w._source_version += 1
            w._sync.source_traits()
            self.restart()
            w._sync.state_traits()
            w._pump.mark_dirty()
            w._pump.flush()

    def set_source_setting(self, name, value) -> None:
        """A recorded source setting, applied as its trait would be (a stack made if needed); a
        setting with no trait of that name goes to the source (`apply_setting`)."""
        w = self.w
        if isinstance(value, list):
            value = tuple(value)
        w._sync.source_traits()  # the replay's steps changed the source: the traits must say what it is
        if w.has_trait(name):
            setattr(w, name, value)
            return
        with w._source_lock:
            apply_setting(w.source, name, value)
        w._source_version += 1

    def set_view_setting(self, name, value) -> None:
        """A recorded view setting, set on its trait (skipped if this widget has no such trait)."""
        if isinstance(value, list):
            value = tuple(value)
        if self.w.has_trait(name) and getattr(self.w, name) != value:
            setattr(self.w, name, value)

    # -- figures, meshes, animations ------------------------------------------------------------
    def render_animation(self, path, *, recording=None, fps: float = 10.0, per: str = "step", **options) -> int:
        w = self.w
        rec = w.recording if recording is None else recording
        kwargs = {**_taken_by_render_state(widget_settings(w)), **options}
        return render_animation(rec, None, inner_source(w.source), path, fps=fps, per=per, **kwargs)

    def render(self, path=None, *, size=None, dpi: float = 100, **options):
        w = self.w
        with w._pump.lock:
            state = w.state.copy()
            kwargs = {**_taken_by_render_state(widget_settings(w)), **options}
            if kwargs.get("slices") is not None and "spacing" not in options:
                kwargs["spacing"] = w.spacing  # the slices the view shows, its default spread where it was
        size = (w.scene.width, w.scene.height) if size is None else size
        from ..keep.pictures.state_picture import render_state  # matplotlib: imported when a figure is drawn

        return render_state(state, inner_source(w.source), path, size=size, dpi=dpi, **kwargs)

    def slice_mesh(self, **options):
        w = self.w
        with w._pump.lock:
            data = w._painter.current_slice()
            colors = w._painter.group_colors()
        kwargs = {"color_by": w.color_by, **options}
        if colors is not None and "group_colors" not in options:
            kwargs["group_colors"] = colors
        return slice_mesh(data, **kwargs)

    # -- state files ------------------------------------------------------------------------
    def save_state(self, path) -> dict:
        w = self.w
        with w._pump.lock:
            state = w.state.copy()
            settings = view_settings(w)
        return save_state(path, state, w.source, settings)

    def load_state(self, path) -> None:
        loaded = load_state(path, source=self.w.source)
        self.apply_loaded(loaded.state, loaded.settings)

    @staticmethod
    def from_state(cls, path, source=None, *, allow_code: bool = False, **kwargs):
        """A widget of class ``cls`` for a `save_state` file (`Rot4DWidget.from_state`)."""
        loaded = load_state(path, source=source, allow_code=allow_code)
        if loaded.source is None:
            raise ValueError(f"{path!r} does not say how to rebuild its source: pass it, "
                             "Rot4DWidget.from_state(path, source=...)")
        settings = dict(loaded.settings)
        if inner_source(loaded.source) is not loaded.source:  # already parallel slices: not wrapped twice
            for name in ("slices", "spacing", "arrangement"):
                settings.pop(name, None)
        allowed = set(inspect.signature(cls.__init__).parameters)
        init = {k: v for k, v in settings.items() if k in allowed and v is not None}
        w = cls(loaded.source, **{**init, **kwargs})
        # view settings the constructor does not take (a trait only) are set once it is made
        late = {k: settings[k] for k in VIEW_SETTINGS if k in settings and k not in init and k not in kwargs}
        w._keeper.apply_loaded(loaded.state, late, defaults=False)
        return w

    def apply_loaded(self, state, settings, *, defaults: bool = True) -> None:
        """Set the loaded ``state`` and ``settings`` on the widget, which then records from there.
        ``defaults``: a view setting the file lacks (one from before it existed) is set to its
        default, as the file's view was drawn."""
        w = self.w
        if defaults:
            defaults = {**VIEW_DEFAULTS, **_OPTIONAL_VIEW}  # a file from before `projection`: off
            settings = {**{k: v for k, v in defaults.items() if w.has_trait(k)}, **settings}
        d = state.to_dict()
        d.pop("keymap")
        with w._pump.lock:
            w._check_open()
            w.state.restore(d)  # the loaded state becomes what r resets to
            w._keys.use_keymap(without_source_keys(state.keymap), w.source)
        for name in SETTING_NAMES:  # slices before spacing and arrangement
            value = settings.get(name)
            if not w.has_trait(name) or (value is None and name not in VIEW_SETTINGS) or name not in settings:
                continue  # a None clim is the data's range: loaded too
            if isinstance(value, list):
                value = tuple(value)
            if getattr(w, name) != value:
                setattr(w, name, value)
        if w._stacking.is_stack and settings.get("spacing") is None:  # made now: spread along the loaded w
            with w._pump.lock, w._source_lock:
                note_matrix(w.source, w.state.matrix)
                apply_setting(w.source, "spacing", None)
        w.refresh()
        with w._pump.lock:
            self.restart()


_MISSING = object()


class _LiveSource:
    """The widget's source as it is at each moment (a replay may turn it into a stack midway)."""

    def __init__(self, widget):
        self._widget = widget

    def __getattr__(self, name):
        return getattr(self._widget.source, name)
