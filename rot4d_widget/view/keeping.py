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
from .showing import fit_c0_range
from .stacking import is_stack

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

    def __init__(self, traits, showing, state, pump):
        self.traits = traits  # the widget's traits: its settings, kept, recorded and loaded
        self.showing, self.state, self.pump = showing, state, pump
        self.painter = self.keys = self.sync = self.scene = None  # `connect`
        view = _view_now(traits)  # the traits' defaults: the constructor's values are recorded at t = 0
        self.recorder = Recorder(state, clock=pump.clock, source_settings=settings_of(showing.source),
                                 view_settings=view)
        self.recorded_settings = settings_of(showing.source)  # the source's settings as last recorded
        self.recorded_view = view  # the view settings as last recorded
        # every change of a view trait is recorded (the constructor's too: watched from before it
        # sets them); the widget's keys and observers may say so as well: recorded once
        traits.observe(self._on_view_trait, names=[n for n in VIEW_SETTINGS if traits.has_trait(n)])

    def connect(self, painter, keys, sync, scene) -> None:
        """The painter (the slice a mesh export takes), the keys (a loaded file's key table), the
        trait sync (the traits say what a replay or a loaded file made) and the scene (its size is
        a picture's default)."""
        self.painter, self.keys, self.sync, self.scene = painter, keys, sync, scene

    # -- recording --------------------------------------------------------------------------
    def restart(self) -> None:
        """Forget what was recorded; record from the current state and source settings on."""
        view = _view_now(self.traits)
        self.recorder.restart(self.state, settings_of(self.showing.source), view)
        self.recorded_settings = settings_of(self.showing.source)
        self.recorded_view = view

    def refresh(self) -> None:
        """`Rot4DWidget.refresh`: the state and the source may have been changed directly -- the
        state's parameters and the source's changed settings recorded, the traits synced, redrawn."""
        with self.pump.lock:
            self.pump.check_open()
            self.showing.changed()
            st = self.state
            fit_c0_range(st, self.showing.source)  # a field's w_per_unit may have changed
            for name in ("c0_step", "theta0", "alpha", "c0", "matrix"):  # `state` may have been set directly
                self.recorder.record_set(name, getattr(st, name))
            self.record_changed_settings()
            self.sync.state_traits()
            self.pump.mark_dirty()
            self.pump.flush()

    def record_source(self, name, value) -> None:
        """A source setting changed (a trait, a key): recorded, and remembered as recorded."""
        self.recorder.record_source(name, value)
        self.recorded_settings = settings_of(self.showing.source)

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
        samples = callable(inner_source(self.showing.source).sample)  # the protocol's optional grid
        if name == "rendering" and new != "surface" and not samples:
            return  # refused by the widget's own observer (only a field has more than the surface)
        self.record_view(name, new)

    def note_settings(self) -> None:
        """The source changed through a recorded step (its own key): its settings are as recorded."""
        self.recorded_settings = settings_of(self.showing.source)

    def record_changed_settings(self) -> list:
        """The source's settings that changed since last recorded (a user's source changed in
        code, then `refresh`), recorded as source settings; returns their names.  (The view
        settings are traits, recorded as they change: `record_view`.)"""
        now = settings_of(self.showing.source)
        changed = [k for k, v in now.items() if self.recorded_settings.get(k, _MISSING) != v]
        for name in changed:
            self.recorder.record_source(name, now[name])
        self.recorded_settings = now
        return changed

    def replay(self, recording) -> None:
        if not isinstance(recording, Recording):
            if not isinstance(recording, (str, os.PathLike)):
                raise TypeError(f"Expected a Recording or a path to one, got {type(recording).__name__}")
            recording = Recording.load(recording)
        with self.pump.lock:
            self.pump.check_open()
            recording.replay(self.state, _LiveSource(self.showing), set_source=self.set_source_setting,
                             set_view=self.set_view_setting)
            self.showing.changed()
            self.sync.source_traits()
            self.restart()
            self.sync.state_traits()
            self.pump.mark_dirty()
            self.pump.flush()

    def set_source_setting(self, name, value) -> None:
        """A recorded source setting, applied as its trait would be (a stack made if needed); a
        setting with no trait of that name goes to the source (`apply_setting`)."""
        if isinstance(value, list):
            value = tuple(value)
        self.sync.source_traits()  # the replay's steps changed the source: the traits must say what it is
        if self.traits.has_trait(name):
            setattr(self.traits, name, value)
            return
        with self.showing.lock:
            apply_setting(self.showing.source, name, value)
        self.showing.changed()

    def set_view_setting(self, name, value) -> None:
        """A recorded view setting, set on its trait (skipped if this widget has no such trait)."""
        if isinstance(value, list):
            value = tuple(value)
        if self.traits.has_trait(name) and getattr(self.traits, name) != value:
            setattr(self.traits, name, value)

    # -- figures, meshes, animations ------------------------------------------------------------
    def render_animation(self, path, *, recording=None, fps: float = 10.0, per: str = "step", **options) -> int:
        rec = self.recorder.recording() if recording is None else recording
        kwargs = {**_taken_by_render_state(widget_settings(self.traits)), **options}
        return render_animation(rec, None, inner_source(self.showing.source), path, fps=fps, per=per, **kwargs)

    def render(self, path=None, *, size=None, dpi: float = 100, **options):
        with self.pump.lock:
            state = self.state.copy()
            kwargs = {**_taken_by_render_state(widget_settings(self.traits)), **options}
            if kwargs.get("slices") is not None and "spacing" not in options:
                kwargs["spacing"] = self.traits.spacing  # the slices the view shows, its default spread where it was
        size = (self.scene.width, self.scene.height) if size is None else size
        from ..keep.pictures.state_picture import render_state  # matplotlib: imported when a figure is drawn

        return render_state(state, inner_source(self.showing.source), path, size=size, dpi=dpi, **kwargs)

    def slice_mesh(self, **options):
        with self.pump.lock:
            data = self.painter.current_slice()
            colors = self.painter.group_colors()
        kwargs = {"color_by": self.traits.color_by, **options}
        if colors is not None and "group_colors" not in options:
            kwargs["group_colors"] = colors
        return slice_mesh(data, **kwargs)

    # -- state files ------------------------------------------------------------------------
    def save_state(self, path) -> dict:
        with self.pump.lock:
            state = self.state.copy()
            settings = view_settings(self.traits)
        return save_state(path, state, self.showing.source, settings)

    def load_state(self, path) -> None:
        loaded = load_state(path, source=self.showing.source)
        self.apply_loaded(loaded.state, loaded.settings)

    @staticmethod
    def widget_arguments(cls, path, source=None, *, allow_code: bool = False, **kwargs):
        """What `Rot4DWidget.from_state` makes a widget of class ``cls`` from: ``(loaded, arguments,
        late)`` -- the loaded file, the constructor's arguments and the view settings the
        constructor does not take (set by `apply_loaded` once the widget is made)."""
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
        # view settings the constructor does not take (a trait only) are set once it is made
        late = {k: settings[k] for k in VIEW_SETTINGS if k in settings and k not in init and k not in kwargs}
        return loaded, {**init, **kwargs}, late

    def apply_loaded(self, state, settings, *, defaults: bool = True) -> None:
        """Set the loaded ``state`` and ``settings`` on the widget, which then records from there.
        ``defaults``: a view setting the file lacks (one from before it existed) is set to its
        default, as the file's view was drawn."""
        if defaults:
            defaults = {**VIEW_DEFAULTS, **_OPTIONAL_VIEW}  # a file from before `projection`: off
            settings = {**{k: v for k, v in defaults.items() if self.traits.has_trait(k)}, **settings}
        d = state.to_dict()
        d.pop("keymap")
        with self.pump.lock:
            self.pump.check_open()
            self.state.restore(d)  # the loaded state becomes what r resets to
            self.keys.use_keymap(without_source_keys(state.keymap), self.showing.source)
        for name in SETTING_NAMES:  # slices before spacing and arrangement
            value = settings.get(name)
            if not self.traits.has_trait(name) or (value is None and name not in VIEW_SETTINGS) or name not in settings:
                continue  # a None clim is the data's range: loaded too
            if isinstance(value, list):
                value = tuple(value)
            if getattr(self.traits, name) != value:
                setattr(self.traits, name, value)
        if is_stack(self.showing.source) and settings.get("spacing") is None:  # made now: spread along the loaded w
            with self.pump.lock, self.showing.lock:
                note_matrix(self.showing.source, self.state.matrix)
                apply_setting(self.showing.source, "spacing", None)
        self.refresh()
        with self.pump.lock:
            self.restart()


_MISSING = object()


class _LiveSource:
    """The widget's source as it is at each moment (a replay may turn it into a stack midway)."""

    def __init__(self, showing):
        self._showing = showing

    def __getattr__(self, name):
        return getattr(self._showing.source, name)
