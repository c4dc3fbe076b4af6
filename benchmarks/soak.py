"""Soak: many random front-end events through Rot4DWidget's own comms, invariants after each.

The driver plays the page.  Every event reaches the widget the way the front end delivers it:
a comm message to the model (``model.comm.handler(msg)``, i.e. ipywidgets'
``Widget._handle_msg`` -> ``method: "custom"`` -> ``_handle_custom_msg`` -> the model's
``on_msg`` callbacks).  For the ipyevents ``Event`` of the canvas and of the key pad buttons
that callback is ``Event._handle_mouse_msg(widget, content, buffers)``, which calls the
``on_dom_event`` callbacks with the event dict; for the companion it is its message handler
("drawn", "focus_lost", "screenshot" answers).  Key event dicts carry ipyevents 2.0.4's
fields (type, key, code, shiftKey, altKey, ctrlKey, metaKey, repeat, timeStamp in page
milliseconds, location, target).  Nothing calls the widget's private handlers.

What the kernel sends goes through `SoakComm` (installed as ``comm.create_comm``): it hands
each message to `Page`, which keeps every model's state as the page would and acknowledges
the pictures it receives (the scene buffer's ``_rot4d_seq``), sometimes late, twice, never,
or with a malformed id.  During "comm failure" phases a share of ``send`` calls raise
`InjectedSendError` before anything reaches the page.

Time is a fake clock (widgets made with ``_clock=clock, _autotick=False``); between events
the driver advances it and calls ``w._pump.service(now)``, as the ticker thread would.  The
run is a sequence of sessions, each one widget of one source kind (a polytope, a `Field4D`,
a stack of parallel slices; a session may also switch to a stack by ``slices`` or key n).
At the end of a session every key is released, the page acknowledges, time runs past the
acknowledgement timeout, and the session is checked: nothing held, the page's picture equal
to the kernel's, a replay of ``w.recording`` on a fresh widget of the same kind equal to the
live state (orientation, theta0, alpha, c0, levels, slices, spacing, arrangement), and no
widget model left after closing both.

Checked after every event: no exception escaped (front-end paths must never raise; a Python
API call may raise only TraitError/ValueError/TypeError for an invalid value, or the injected
comm error), nothing in ``w.errors`` or the log but injected errors, ``‖RRᵀ − I‖`` small,
``n_in_flight <= max_in_flight``, theta0 / alpha / c0 / spacing / levels finite and within
`BOUNDS`.  At the end: RSS growth after warm-up within a bound proportional to the events.

A failed check is recorded once per kind (first event, message, the last events) and the run
goes on, so one run lists every kind of failure; `SoakReport.failures` holds them.

    python benchmarks/soak.py [--events 100000] [--seed 1] [--no-threads]

tests/view/test_soak.py runs the same driver at a small scale (marked slow).
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import gc
import logging
import math
import random
import re
import sys
import threading
import time
import traceback

import comm as comm_package
import ipywidgets
import numpy as np
import traitlets
from ipywidgets.widgets.widget import _remove_buffers

__all__ = ["InjectedSendError", "SoakComm", "Page", "Soak", "SoakReport", "run_soak", "main",
           "threaded_phase", "BOUNDS"]

ORTHO_TOL = 1e-9
REPLAY_TOL = 1e-9
#: How far the repeating values may go, in units of the source's size (circumradius) where it
#: applies.  A value beyond these is reported: held keys must not run a value away.
BOUNDS = {
    "theta0": (0.0, math.pi),  # (0, pi]
    "alpha": 2.0 * math.pi,  # |alpha|
    "c0": 2.0,  # |c0| <= 2 size: the slice is empty beyond size
    "spacing": (1e-6, 8.0),  # spacing / size
    "levels_span": 1.0,  # levels within the data range widened by one span each side
}
#: RSS growth allowed after warm-up: a fixed slack plus so much per 10^4 events.
RSS_SLACK_MB = 12.0
RSS_MB_PER_10K = 4.0
LAST_EVENTS = 25

_SHIFT_DIGITS = {"2": "@", "3": "#", "4": "$", "6": "^", "8": "*", "1": "!", "5": "%"}
#: (key, code, shifted key) on a US keyboard; keys the keymap binds and a few it does not.
_KEYS = [
    ("2", "Digit2"), ("3", "Digit3"), ("4", "Digit4"), ("6", "Digit6"), ("8", "Digit8"), ("c", "KeyC"),
    ("y", "KeyY"), ("z", "KeyZ"), ("w", "KeyW"), ("k", "KeyK"), ("j", "KeyJ"), ("l", "KeyL"), ("h", "KeyH"),
    ("r", "KeyR"), ("=", "Equal"), ("-", "Minus"), ("/", "Slash"), ("n", "KeyN"), ("b", "KeyB"),
    ("g", "KeyG"), ("f", "KeyF"), ("o", "KeyO"), ("i", "KeyI"), ("p", "KeyP"), ("q", "KeyQ"), ("1", "Digit1"),
]
_KEY_WEIGHTS = {"r": 0.15, "p": 0.1, "/": 0.2, "=": 0.4, "-": 0.4, "q": 0.3, "1": 0.3, "n": 0.6, "b": 0.8,
                "g": 1.5, "f": 1.0, "l": 1.5, "h": 1.5, "k": 1.2, "j": 1.2}
_SHIFTED = {"=": "+", "-": "_", "/": "?"}


class InjectedSendError(RuntimeError):
    """What `SoakComm.send` raises on purpose during a comm failure phase."""


class SoakFailure(AssertionError):
    pass


# ============================================================================ the comm and the page
class SoakComm:
    """A stand-in for ipykernel's comm: messages go to `SoakComm.page`; sometimes ``send`` raises."""

    kernel = "Truthy"  # ipywidgets sends only when the comm has a kernel
    page = None
    fail_rate = 0.0
    rng = random.Random(0)
    sends = 0
    injected = 0

    def __init__(self, *args, comm_id=None, data=None, buffers=None, **kwargs):
        import uuid

        self.comm_id = comm_id or uuid.uuid4().hex
        self.handler = None
        self.closed = False
        if SoakComm.page is not None:
            SoakComm.page.opened(self.comm_id, data, buffers)

    def open(self, *args, **kwargs):
        pass

    def on_msg(self, callback):
        self.handler = callback

    def on_close(self, callback):
        pass

    def send(self, data=None, metadata=None, buffers=None):
        SoakComm.sends += 1
        if SoakComm.fail_rate and SoakComm.rng.random() < SoakComm.fail_rate:
            SoakComm.injected += 1
            raise InjectedSendError("injected: the comm could not send")
        if SoakComm.page is not None:
            SoakComm.page.received(self.comm_id, data, buffers)

    def close(self, *args, **kwargs):
        self.closed = True
        if SoakComm.page is not None:
            SoakComm.page.closed(self.comm_id)


class install_comm:
    """Context manager: new widgets use `SoakComm` talking to ``page``; restores on exit."""

    def __init__(self, page):
        self.page = page

    def __enter__(self):
        self._saved = comm_package.create_comm
        SoakComm.page = self.page
        comm_package.create_comm = lambda *a, **k: SoakComm(*a, **k)
        return self.page

    def __exit__(self, *exc):
        comm_package.create_comm = self._saved
        SoakComm.page = None
        SoakComm.fail_rate = 0.0


def _put_buffers(state, paths, buffers):
    for path, buf in zip(paths or (), buffers or ()):
        obj = state
        for k in path[:-1]:
            obj = obj[k]
        obj[path[-1]] = bytes(buf)


class Page:
    """What the page knows: each model's state as received, and the pictures it may acknowledge."""

    def __init__(self):
        self.models = {}  # comm id -> state dict (buffers as bytes)
        self.arrived = collections.defaultdict(list)  # buffer model id -> seqs arrived, not acknowledged
        self.screenshot_asks = collections.defaultdict(list)  # companion model id -> request ids
        self.messages = 0
        self.bytes = 0

    def opened(self, comm_id, data, buffers):
        data = data or {}
        state = dict(data.get("state", {}))
        _put_buffers(state, data.get("buffer_paths"), buffers)
        self.models[comm_id] = state

    def received(self, comm_id, data, buffers):
        self.messages += 1
        self.bytes += sum(len(memoryview(b).cast("B")) for b in (buffers or ()))
        if not isinstance(data, dict):
            return
        if data.get("method") == "update":
            state = dict(data.get("state", {}))
            _put_buffers(state, data.get("buffer_paths"), buffers)
            self.models.setdefault(comm_id, {}).update(state)
            if "_rot4d_seq" in state and ("array" in state or "_rot4d_turn" in state):
                self.arrived[comm_id].append(int(state["_rot4d_seq"]))
        elif data.get("method") == "custom":
            content = data.get("content")
            if isinstance(content, dict) and content.get("event") == "screenshot" and "id" in content:
                self.screenshot_asks[comm_id].append(content["id"])

    def closed(self, comm_id):
        self.models.pop(comm_id, None)
        self.arrived.pop(comm_id, None)
        self.screenshot_asks.pop(comm_id, None)


def custom_msg(content):
    """A front-end custom message as ipykernel hands it to ``comm.handler``."""
    return {"content": {"data": {"method": "custom", "content": content}}, "buffers": []}


def wire_state(model) -> dict:
    """The model's state as it goes over the wire (buffers as bytes): what the page should hold."""
    state, paths, buffers = _remove_buffers(model.get_state())
    state = dict(state)
    _put_buffers(state, paths, buffers)
    return state


def rss_mb() -> float:
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# ============================================================================ sources
def ball_field():
    """A small 4-D field (f = 0.64 - |q|^2 on [-1, 1]^4), two iso levels, cheap to slice."""
    from rot4d_widget.sources.field.container import Field4D

    return Field4D.from_function(lambda x, y, z, w: 0.64 - (x * x + y * y + z * z + w * w),
                                 [(-1.0, 1.0)] * 4, levels=[0.0, 0.3], resolution=12, coarse_resolution=8)


#: Session kinds: (name, widget arguments factory); replay builds the same kind again.
KINDS = {
    "polytope": lambda rng: (("24-cell",), {}),
    "5-cell": lambda rng: (("5-cell",), {}),
    "field": lambda rng: ((ball_field(),), {}),
    "stack": lambda rng: (("24-cell",), {"slices": 3}),
    "keypad": lambda rng: (("8-cell",), {"keypad": True}),
}
KIND_ORDER = ("polytope", "field", "stack", "keypad", "5-cell")


class FakeClock:
    def __init__(self, t=100.0):
        self.t = t

    def __call__(self):
        return self.t


# ============================================================================ the report
@dataclasses.dataclass
class Failure:
    check: str
    event: int
    message: str
    last_events: list
    count: int = 1

    def describe(self, seed) -> str:
        tail = "\n".join(f"    {e}" for e in self.last_events)
        return (f"[{self.check}] first at event {self.event} (seed {seed}, {self.count} time(s)): {self.message}\n"
                f"  last events:\n{tail}")


@dataclasses.dataclass
class SoakReport:
    seed: int
    events: int = 0
    seconds: float = 0.0
    sessions: int = 0
    max_in_flight: int = 0
    max_in_flight_allowed: int = 0
    max_ortho: float = 0.0
    rss_start: float = float("nan")
    rss_end: float = float("nan")
    rss_allowed: float = float("nan")
    gc_start: int = 0
    gc_end: int = 0
    steps: int = 0
    updates: int = 0
    acks: int = 0
    timeouts: int = 0
    injected: int = 0
    injected_caught: int = 0
    injected_raised: int = 0
    invalid_sets: int = 0
    valid_sets: int = 0
    replay_max_diff: float = 0.0
    page_messages: int = 0
    page_mbytes: float = 0.0
    threaded: str = "not run"
    failures: dict = dataclasses.field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.failures

    def failure_text(self) -> str:
        if not self.failures:
            return "no failures"
        fs = sorted(self.failures.values(), key=lambda f: f.event)
        head = f"{len(fs)} kind(s) of failure in the soak (seed {self.seed}); the first:\n"
        return head + "\n\n".join(f.describe(self.seed) for f in fs)

    def table(self) -> str:
        rate = self.events / self.seconds if self.seconds else float("nan")
        rows = [
            ("events", f"{self.events}"),
            ("sessions (widgets)", f"{self.sessions}"),
            ("wall time", f"{self.seconds:.1f} s"),
            ("events/s", f"{rate:.0f}"),
            ("max in flight (bound)", f"{self.max_in_flight} ({self.max_in_flight_allowed})"),
            ("max ‖RRᵀ−I‖", f"{self.max_ortho:.2e}"),
            ("RSS after warm-up / end", f"{self.rss_start:.1f} / {self.rss_end:.1f} MB "
                                        f"(growth allowed {self.rss_allowed:.1f} MB)"),
            ("gc objects after warm-up / end", f"{self.gc_start} / {self.gc_end}"),
            ("steps applied (recorded)", f"{self.steps}"),
            ("updates / acks / timeouts", f"{self.updates} / {self.acks} / {self.timeouts}"),
            ("page messages / MB", f"{self.page_messages} / {self.page_mbytes:.1f}"),
            ("sends failed (injected)", f"{self.injected}"),
            ("errors caught, shown / raised to API", f"{self.injected_caught} / {self.injected_raised}"),
            ("trait sets valid / invalid", f"{self.valid_sets} / {self.invalid_sets}"),
            ("replay max difference", f"{self.replay_max_diff:.2e}"),
            ("threaded phase", self.threaded),
            ("failures (kinds)", f"{len(self.failures)}"),
        ]
        w = max(len(k) for k, _ in rows)
        return "\n".join(f"{k:<{w}}  {v}" for k, v in rows)


# ============================================================================ log capture
class _LogCapture(logging.Handler):
    def __init__(self):
        super().__init__(level=logging.WARNING)
        self.records = []

    def emit(self, record):
        try:
            text = record.getMessage()
            if record.exc_info:
                text += "\n" + "".join(traceback.format_exception(*record.exc_info))
        except Exception:  # never let logging break the run
            text = repr(record.msg)
        self.records.append((record.name, record.levelname, text))


# ============================================================================ the driver
class Soak:
    """One seeded soak run; `run()` returns a `SoakReport`."""

    def __init__(self, events=5000, seed=1, *, session_events=(400, 1200), fail_phase=(40, 160),
                 fail_rate=0.3, kinds=KIND_ORDER, stop_at_first=False, verbose=False):
        self.n_events = int(events)
        self.seed = int(seed)
        self.rng = random.Random(self.seed)
        self.session_events = session_events
        self.fail_phase = fail_phase
        self.fail_rate = fail_rate
        self.kinds = tuple(kinds)
        self.stop_at_first = stop_at_first
        self.verbose = verbose
        self.clock = FakeClock()
        self.page = Page()
        self.report = SoakReport(seed=self.seed)
        self.last = collections.deque(maxlen=LAST_EVENTS)
        self.i = 0
        self.w = None
        self.held = {}  # code -> (key, shift) of keys down on the canvas
        self.pad_held = set()  # key pad Event widgets whose button is down
        self.pad = []  # (Event widget, key, shift)
        self.page_t0 = self.clock.t - 12.5  # the page loaded 12.5 s before the kernel's clock start
        self.injecting = 0  # events left in the current comm failure phase
        self._seen_errors = 0
        self._seen_outputs = None
        self._last_acked = 0

    # -- failures ---------------------------------------------------------------
    def fail(self, check, message):
        check = re.sub(r"\(?\d+(,\d*)?\)?", "N", check)  # one kind whatever the numbers (shapes, counts)
        f = self.report.failures.get(check)
        if f is not None:
            f.count += 1
            return
        if self.injecting:
            message += f"\n  (during a comm failure phase; {SoakComm.injected} sends failed so far)"
        self.report.failures[check] = Failure(check, self.i, message, list(self.last))
        if self.verbose:
            print(f"FAIL {self.report.failures[check].describe(self.seed)}", file=sys.stderr)
        if self.stop_at_first:
            raise SoakFailure(self.report.failure_text())

    def note(self, text):
        self.last.append(f"#{self.i} t={self.clock.t:.3f} {text}")

    # -- time -------------------------------------------------------------------
    def advance(self, dt):
        self.clock.t += dt
        try:
            self.w._pump.service(self.clock.t)
        except Exception as exc:
            self.fail("service raised", f"w._pump.service raised {exc!r}")

    def timestamp(self):
        return round((self.clock.t - self.page_t0) * 1000.0 + self.rng.uniform(0, 2), 3)

    # -- delivering what the page sends -------------------------------------------
    def deliver(self, model, content, what):
        self.note(what)
        try:
            model.comm.handler(custom_msg(content))
        except Exception as exc:
            self.fail("front-end message raised", f"{what}: {type(exc).__name__}: {exc}")

    def key_event(self, kind, key, code, shift, repeat=False):
        typed = key
        if shift:
            typed = _SHIFT_DIGITS.get(key) or _SHIFTED.get(key) or key.upper()
        return {"type": kind, "event": kind, "key": typed, "code": code, "shiftKey": bool(shift),
                "altKey": False, "ctrlKey": False, "metaKey": False, "repeat": bool(repeat),
                "timeStamp": self.timestamp(), "location": 0, "target": {}}

    def key(self, kind, key, code, shift, repeat=False):
        ev = self.key_event(kind, key, code, shift, repeat)
        self.deliver(self.w.events, ev, f"{kind} {ev['key']!r} {code}{' shift' if shift else ''}"
                                        f"{' repeat' if repeat else ''}")

    def ack(self, how="newest"):
        """The companion reports a drawn picture: ``how`` newest, late, duplicate, missing, junk."""
        w = self.w
        bid = w.scene.buffer_model_id
        arrived = self.page.arrived[bid]
        if how == "missing":  # the page drops what it has (a hidden tab): no acknowledgement
            self.note(f"ack missing (dropped {arrived[-3:]})")
            arrived.clear()
            return
        if how == "junk":
            seq = self.rng.choice(["7", True, -1, 10 ** 9, None, 2.5, [1]])
            content = {"event": "drawn", "seq": seq} if self.rng.random() < 0.8 else {"event": "drawn"}
            self.deliver(w.companion, content, f"ack junk {content!r}")
            return
        if how == "late":
            seq = self._last_acked - self.rng.randint(0, 3) if self._last_acked else None
            if seq is None or seq < 1:
                return
            self.deliver(w.companion, {"event": "drawn", "seq": seq}, f"ack late {seq}")
            return
        if how == "duplicate":
            if self._last_acked:
                self.deliver(w.companion, {"event": "drawn", "seq": self._last_acked},
                             f"ack duplicate {self._last_acked}")
            return
        if not arrived:
            return
        seq = arrived[-1]
        arrived.clear()
        self._last_acked = seq
        self.deliver(w.companion, {"event": "drawn", "seq": seq}, f"ack {seq}")

    def answer_screenshots(self):
        asks = self.page.screenshot_asks.get(self.w.companion.comm.comm_id)
        while asks:
            rid = asks.pop(0)
            self.deliver(self.w.companion, {"event": "screenshot", "id": rid,
                                            "error": "no canvas of this view is in the page"},
                         f"screenshot answer {rid} (error)")

    # -- sessions -----------------------------------------------------------------
    def make(self, kind):
        from rot4d_widget.view.widget import Rot4DWidget

        args, kwargs = KINDS[kind](self.rng)
        return Rot4DWidget(*args, _clock=self.clock, _autotick=False, **kwargs)

    def start_session(self, kind):
        self.kind = kind
        self.models_before = set(_models())
        self.note(f"new widget: {kind}")
        self.w = self.make(kind)
        self.report.sessions += 1
        self.held.clear()
        self.pad_held.clear()
        self.pad = []
        self._last_acked = 0
        self._seen_outputs = self.w.errors.outputs
        self.report.max_in_flight_allowed = self.w._pump.max_in_flight
        if self.w.keypad:
            self.find_pad()

    def find_pad(self):
        """The key pad's buttons and the ipyevents Event watching each (found as the page would)."""
        buttons = []

        def walk(wd):
            for c in getattr(wd, "children", ()):
                if isinstance(c, ipywidgets.Button) and "rot4d-pad-button" in c._dom_classes:
                    buttons.append(c)
                walk(c)

        walk(self.w)
        from ipyevents import Event

        by_source = {}
        for m in list(_models().values()):
            if isinstance(m, Event) and m.source is not None:
                by_source[id(m.source)] = m
        self.pad = []
        for b in buttons:
            ev = by_source.get(id(b))
            if ev is None:
                continue
            tip = b.tooltip
            shift = tip.startswith("Shift+")
            key = tip[len("Shift+"):] if shift else tip
            self.pad.append((ev, key.split(":", 1)[0], shift))

    def end_session(self):
        """Release everything, let the page catch up, check the session, close, count models."""
        w = self.w
        self.stop_injecting()
        for code, (key, shift) in list(self.held.items()):
            self.key("keyup", key, code, shift)
            del self.held[code]
        for ev in list(self.pad_held):
            self.deliver(ev, {"type": "mouseup", "button": 0, "timeStamp": self.timestamp()}, "pad mouseup (end)")
        self.pad_held.clear()
        if w.held_keys != ():
            self.fail("held after release", f"w.held_keys == {w.held_keys!r} after every keyup ({self.kind})")
            self.deliver(w.events, {"type": "mouseleave", "event": "mouseleave", "timeStamp": self.timestamp()},
                         "mouseleave (end)")
        self.settle()
        self.check_picture()
        self.check_replay()
        self.answer_screenshots()
        self.note(f"close widget: {self.kind}")
        try:
            w.close()
        except Exception as exc:
            self.fail("close raised", f"{self.kind}: {exc!r}")
        self.w = None
        gc.collect()
        left = {k: m for k, m in list(_models().items()) if k not in self.models_before}
        if left:
            kinds = collections.Counter(type(m).__name__ + (f" {m.description!r}" if getattr(m, "description", "")
                                                            else "") for m in left.values())
            self.fail("widget models leaked", f"{len(left)} models left open after closing a {self.kind} "
                                              f"widget and its replay: {dict(kinds)}")
            for m in left.values():  # not counted again in the next session
                m.close()

    def settle(self):
        """Acknowledge and run time until nothing is in flight and nothing is dirty (bounded)."""
        for _ in range(200):
            self.ack("newest")
            self.advance(0.05)
            if self.w._pump.n_in_flight == 0 and not self.w._pump.dirty and not self.page.arrived[
                    self.w.scene.buffer_model_id]:
                break
        self.advance(2.0 * self.w._pump.timeout + 0.1)
        self.ack("newest")
        self.advance(0.05)

    def check_picture(self):
        """With a healthy comm and everything acknowledged, the page shows the kernel's picture."""
        w = self.w
        bid = w.scene.buffer_model_id
        model = _models().get(bid)
        page = self.page.models.get(bid, {})
        if model is None:
            self.fail("picture", "the scene's buffer model is gone")
            return
        kernel = wire_state(model)
        diff = [k for k in ("array", "_rot4d_seq", "_rot4d_counts", "_rot4d_turn", "_rot4d_surface")
                if k in kernel and page.get(k) != kernel[k]]
        if diff:
            self.fail("picture lost", f"{self.kind}: at rest the page's buffer differs from the kernel's in {diff} "
                                      f"(page seq {page.get('_rot4d_seq')}, kernel seq {kernel.get('_rot4d_seq')}, "
                                      f"scene.update_id {w.scene.update_id}); sends failed so far: "
                                      f"{SoakComm.injected}")
            return

    def check_replay(self):
        w = self.w
        try:
            w2 = self.make(self.kind)
        except Exception as exc:
            self.fail("replay", f"making a second {self.kind} widget raised {exc!r}")
            return
        try:
            rec = w.recording
            self.report.steps += sum(1 for e in rec.events if hasattr(e, "action"))
            w2.replay(rec)
            diffs = {}
            dm = float(np.max(np.abs(np.asarray(w2.state.matrix) - np.asarray(w.state.matrix))))
            diffs["matrix"] = dm
            for name in ("theta0", "alpha", "c0"):
                diffs[name] = abs(getattr(w2.state, name) - getattr(w.state, name))
            num = max(diffs.values())
            self.report.replay_max_diff = max(self.report.replay_max_diff, num)
            bad = [f"{k} differs by {v:.3g}" for k, v in diffs.items() if not v <= REPLAY_TOL]
            for name in ("levels", "slices", "spacing", "arrangement"):
                a, b = getattr(w, name), getattr(w2, name)
                if isinstance(a, float) and isinstance(b, float):
                    same = abs(a - b) <= REPLAY_TOL * max(1.0, abs(a))
                elif isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b):
                    same = all(abs(x - y) <= REPLAY_TOL * max(1.0, abs(x)) for x, y in zip(a, b))
                else:
                    same = a == b
                if not same:
                    bad.append(f"{name}: live {a!r}, replayed {b!r}")
            if bad:
                self.fail("replay differs", f"{self.kind} ({len(rec.events)} events): " + "; ".join(bad))
        except Exception as exc:
            self.fail("replay raised", f"{self.kind}: {type(exc).__name__}: {exc}")
        finally:
            w2.close()

    # -- invariants ---------------------------------------------------------------
    def check(self):
        w = self.w
        pump = w._pump
        n = pump.n_in_flight
        self.report.max_in_flight = max(self.report.max_in_flight, n)
        if n > pump.max_in_flight:
            self.fail("in-flight bound", f"{n} updates in flight > max_in_flight {pump.max_in_flight}")
        m = np.asarray(w.state.matrix)
        e = float(np.linalg.norm(m @ m.T - np.eye(4)))
        self.report.max_ortho = max(self.report.max_ortho, e)
        if not e <= ORTHO_TOL:
            self.fail("orthonormal", f"‖RRᵀ−I‖ = {e:.3g} > {ORTHO_TOL}")
        if not np.array_equal(np.asarray(w.orientation), m):
            self.fail("orientation trait", "w.orientation differs from w.state.matrix")
        self.check_values()
        self.check_errors()

    def check_values(self):
        w = self.w
        st = w.state
        size = float(w.source.size)
        lo, hi = BOUNDS["theta0"]
        problems = []
        if not (math.isfinite(st.theta0) and lo < st.theta0 <= hi):
            problems.append(f"theta0 = {st.theta0!r} not in (0, pi]")
        if not (math.isfinite(st.alpha) and abs(st.alpha) <= BOUNDS["alpha"]):
            problems.append(f"alpha = {st.alpha!r} beyond ±{BOUNDS['alpha']:.3g}")
        if not (math.isfinite(st.c0) and abs(st.c0) <= BOUNDS["c0"] * size):
            problems.append(f"c0 = {st.c0!r} beyond ±{BOUNDS['c0']} x size ({size:g})")
        if w.spacing is not None:
            s_lo, s_hi = BOUNDS["spacing"]
            if not (math.isfinite(w.spacing) and s_lo * size <= w.spacing <= s_hi * size):
                problems.append(f"spacing = {w.spacing!r} outside [{s_lo:g}, {s_hi:g}] x size ({size:g})")
        if w.levels is not None:
            src = getattr(w.source, "source", w.source)
            d_lo, d_hi = getattr(src, "data_range", (-math.inf, math.inf))
            span = (d_hi - d_lo) * BOUNDS["levels_span"]
            for v in w.levels:
                if not (math.isfinite(v) and d_lo - span <= v <= d_hi + span):
                    problems.append(f"level {v!r} outside the data range {d_lo:.3g}..{d_hi:.3g} ± one span")
        for p in problems:
            self.fail("value bounded: " + p.split(" ", 1)[0], p)

    def check_errors(self):
        w = self.w
        outs = w.errors.outputs
        if outs is not self._seen_outputs:
            new = [o for o in outs if o not in (self._seen_outputs or ())]
            self._seen_outputs = outs
            for o in new:
                text = o.get("text", "") if isinstance(o, dict) else str(o)
                if "InjectedSendError" not in text:
                    self.fail("unexpected error shown: " + _last_line(text)[:60],
                              f"w.errors shows an error not injected:\n{text}")
        recs = self.log.records
        while self._seen_errors < len(recs):
            name, level, text = recs[self._seen_errors]
            self._seen_errors += 1
            if "Exception in callback" in text or "Exception in widget method" in text:
                self.fail("exception escaped into ipywidgets: " + _last_line(text)[:60],
                          f"a front-end message handler raised (logged by ipywidgets):\n{text}")
            elif "error while handling a key" in text:
                if "InjectedSendError" in text:
                    self.report.injected_caught += 1
                else:
                    self.fail("unexpected error caught: " + _last_line(text)[:60], f"the widget reported:\n{text}")
            elif "could not report an error" in text:
                if "InjectedSendError" not in text:
                    self.fail("error report failed", text)
            elif name.startswith("rot4d_widget") or level in ("ERROR", "CRITICAL"):
                self.fail("log: " + text.splitlines()[0][:60], f"{name} {level}: {text}")

    # -- the random events ----------------------------------------------------------
    def event(self):
        r = self.rng.random()
        w = self.w
        table = (
            (0.16, self.ev_keydown),
            (0.13, self.ev_keyup),
            (0.05, self.ev_repeat),
            (0.01, self.ev_mouseleave),
            (0.005, self.ev_focus_lost),
            (0.05, self.ev_ack_odd),
            (0.01, self.ev_stall),
            (0.035, self.ev_set_valid),
            (0.025, self.ev_set_invalid),
            (0.06 if self.pad and w.keypad else 0.0, self.ev_pad),  # hidden buttons get no clicks
            (0.006, self.ev_fail_phase),
            (0.006, self.ev_release_all),
            (0.003, self.ev_press_api),
        )
        acc = 0.0
        for p, fn in table:
            acc += p
            if r < acc:
                fn()
                break
        else:
            self.note("idle")
        # time passes, the ticker runs, the page draws and usually acknowledges
        self.advance(self.rng.expovariate(1 / 0.02))
        if self.rng.random() < 0.75:
            self.ack("newest")
        if self.rng.random() < 0.02:
            self.answer_screenshots()
        if self.injecting:
            self.injecting -= 1
            if not self.injecting:  # the comm is healthy again: at rest, the page must catch up
                self.stop_injecting()
                self.check()
                self.ev_release_all()
                self.settle()
                self.check_picture()
        self.check()

    def ev_keydown(self):
        keys = _KEYS
        weights = [_KEY_WEIGHTS.get(k, 1.0) for k, _ in keys]
        key, code = self.rng.choices(keys, weights)[0]
        shift = self.rng.random() < 0.3
        self.key("keydown", key, code, shift)
        self.held[code] = (key, shift)

    def ev_keyup(self):
        if self.held and self.rng.random() < 0.93:
            code = self.rng.choice(list(self.held))
            key, shift = self.held.pop(code)
            if self.rng.random() < 0.2:
                shift = not shift  # Shift pressed or released while the key was down
        else:
            key, code = self.rng.choice(_KEYS)
            shift = False
        self.key("keyup", key, code, shift)

    def ev_repeat(self):
        if not self.held:
            return
        code = self.rng.choice(list(self.held))
        key, shift = self.held[code]
        self.key("keydown", key, code, shift, repeat=True)

    def ev_mouseleave(self):
        self.deliver(self.w.events, {"type": "mouseleave", "event": "mouseleave", "timeStamp": self.timestamp(),
                                     "relativeX": -1, "relativeY": 20}, "mouseleave")
        self.held.clear()
        if self.w.held_keys != () and not self.pad_held:
            self.fail("held after mouseleave", f"w.held_keys == {self.w.held_keys!r} after mouseleave")

    def ev_focus_lost(self):
        self.deliver(self.w.companion, {"event": "focus_lost", "reason": self.rng.choice(["blur", "hidden"])},
                     "focus_lost")
        self.held.clear()
        self.pad_held.clear()
        if self.w.held_keys != ():
            self.fail("held after focus lost", f"w.held_keys == {self.w.held_keys!r} after focus_lost")

    def ev_ack_odd(self):
        self.ack(self.rng.choice(["late", "duplicate", "missing", "junk"]))

    def ev_stall(self):
        dt = self.rng.uniform(0.3, 2.5)
        self.note(f"stall {dt:.2f} s")
        self.advance(dt)

    def ev_release_all(self):
        for code, (key, shift) in list(self.held.items()):
            self.key("keyup", key, code, shift)
        self.held.clear()
        for ev in list(self.pad_held):
            self.deliver(ev, {"type": "mouseup", "button": 0, "timeStamp": self.timestamp()}, "pad mouseup")
        self.pad_held.clear()
        if self.w.held_keys != ():
            self.fail("held after release", f"w.held_keys == {self.w.held_keys!r} after a keyup for every key "
                                            f"down")

    def ev_pad(self):
        if not self.pad or not self.w.keypad:
            return
        if self.pad_held and self.rng.random() < 0.5:
            ev = self.rng.choice(list(self.pad_held))
            kind = self.rng.choice(["mouseup", "mouseup", "mouseleave", "touchend", "touchcancel"])
            self.pad_held.discard(ev)
        else:
            ev, key, shift = self.rng.choice(self.pad)
            kind = self.rng.choice(["mousedown", "mousedown", "touchstart"])
            self.pad_held.add(ev)
        content = {"type": kind, "button": 0, "buttons": 1 if kind == "mousedown" else 0,
                   "timeStamp": self.timestamp(), "relativeX": 10, "relativeY": 8}
        if kind == "mousedown" and self.rng.random() < 0.05:
            content["button"] = 2  # a right click: no press
        self.deliver(ev, content, f"pad {kind} {ev.source.description!r}")
        if kind in ("mouseup", "mouseleave", "touchend", "touchcancel"):
            pad_ids = [k for k in self.w.held_keys if str(k).startswith("pad:")]
            if not self.pad_held and pad_ids:
                self.fail("held after pad release", f"w.held_keys == {self.w.held_keys!r} after every pad release")

    def start_injecting(self):
        self.injecting = self.rng.randint(*self.fail_phase)
        SoakComm.fail_rate = self.fail_rate
        self.note(f"comm failure phase: {self.injecting} events at rate {self.fail_rate}")

    def stop_injecting(self):
        if SoakComm.fail_rate:
            self.note("comm healthy again")
        SoakComm.fail_rate = 0.0
        self.injecting = 0

    def ev_fail_phase(self):
        if not self.injecting:
            self.start_injecting()

    def ev_press_api(self):
        key = self.rng.choice(["4", "c", "l", "n", "b", "o"])
        self.api_call(f"w.press({key!r})", lambda: self.w.press(key), valid=True)

    # -- trait sets -------------------------------------------------------------------
    def valid_values(self):
        w, rng = self.w, self.rng
        size = float(w.source.size)
        vals = {
            # alpha keeps its ratio to theta0, and alpha and beta stay within [-pi, pi]
            "theta0": lambda: rng.uniform(1e-3, self.theta0_max()),
            "alpha": lambda: rng.uniform(max(-1.0, w.theta0 - math.pi), min(1.0, math.pi)),
            "c0": lambda: rng.uniform(-size, size),
            "color_by": lambda: rng.choice(["group", "#ff8800", "#0af", (0.2, 0.4, 0.6)]),
            "ball_radius": lambda: rng.uniform(0.01, 0.2),
            "bar_radius": lambda: rng.uniform(0.005, 0.1),
            "face_opacity": lambda: rng.uniform(0.0, 1.0),
            "background": lambda: rng.choice(["#ffffff", "#123456", "#000"]),
            "show_balls": lambda: rng.random() < 0.7,
            "show_bars": lambda: rng.random() < 0.7,
            "show_faces": lambda: rng.random() < 0.7,
            "keypad": lambda: rng.random() < 0.5,
            "slices": lambda: rng.randint(1, 7),
        }
        if w.levels is not None:
            src = getattr(w.source, "source", w.source)
            lo, hi = src.data_range
            vals["levels"] = lambda: tuple(rng.uniform(lo + 0.05 * (hi - lo), hi - 0.05 * (hi - lo))
                                           for _ in range(rng.randint(1, 3)))
        if w.slices is not None:
            vals["spacing"] = lambda: rng.uniform(0.05, 1.5) * size
            vals["arrangement"] = lambda: rng.choice(["oval", "grid", "stack"])
        return vals

    def theta0_max(self) -> float:
        """The largest theta0 a set may take now: alpha/theta0 is kept and |alpha|, |beta| <= pi."""
        ratio = self.w.alpha / self.w.theta0
        return min(math.pi, *(math.pi / abs(r) for r in (ratio, 1.0 - ratio) if r != 0.0))

    def invalid_values(self):
        w = self.w
        bad_num = [float("nan"), float("inf"), "x", None, True, [1.0]]
        vals = {
            "theta0": [0.0, -0.1, 4.0] + bad_num,
            "alpha": [4.0, -3.5] + bad_num,
            "c0": bad_num,
            "color_by": ["nope", (2.0, 0.0, 0.0), 5, None],
            "ball_radius": [0.0, -1.0, 11.0] + bad_num,
            "face_opacity": [1.5, -0.1] + bad_num,
            "background": ["blue?", "#12", 3, None],
            "show_faces": ["yes", None, 2],
            "keypad": ["yes", None, 2],
            "slices": [0, -1, 65, 2.5, "3", True],
            "levels": [(), "x", (float("nan"),), ("a",)] if w.levels is not None else [(0.1,), 0.2],
            "spacing": [0.0, -1.0, float("inf"), "x", True] if w.slices is not None else [0.5],
            "arrangement": ["spiral", 3, ""] if w.slices is not None else ["grid"],
        }
        return vals

    def ev_set_valid(self):
        vals = self.valid_values()
        name = self.rng.choice(sorted(vals))
        value = vals[name]()
        self.report.valid_sets += 1

        def do():
            setattr(self.w, name, value)

        if self.api_call(f"w.{name} = {value!r}", do, valid=True) and name not in ("levels",):
            got = getattr(self.w, name)
            ok = (got == value or (isinstance(value, float) and isinstance(got, float)
                                   and abs(got - value) <= 1e-12 * max(1.0, abs(value)))
                  or (name == "color_by" and isinstance(value, tuple) and tuple(got) == value))
            if not ok:
                self.fail(f"set {name} not kept", f"w.{name} = {value!r} left w.{name} == {got!r}")
        if name == "keypad":
            if self.w.keypad and not self.pad:
                self.find_pad()
            if not self.w.keypad:
                self.pad_held.clear()

    def ev_set_invalid(self):
        vals = self.invalid_values()
        name = self.rng.choice(sorted(vals))
        value = self.rng.choice(vals[name])
        self.report.invalid_sets += 1
        before = getattr(self.w, name)

        def do():
            setattr(self.w, name, value)

        self.api_call(f"w.{name} = {value!r} (invalid)", do, valid=False)
        after = getattr(self.w, name)
        same = after == before or (isinstance(before, float) and isinstance(after, float)
                                   and math.isnan(before) and math.isnan(after))
        if not same:
            self.fail(f"invalid {name} changed it", f"w.{name} = {value!r} was refused but w.{name} went from "
                                                    f"{before!r} to {after!r}")

    def api_call(self, what, fn, *, valid):
        """A Python API call; True if it returned.  Valid: must not raise (but the injected comm
        error).  Invalid: must raise TraitError, ValueError or TypeError."""
        self.note(what)
        try:
            fn()
        except InjectedSendError:
            self.report.injected_raised += 1
            return False
        except Exception as exc:
            chain = _chain(exc)
            if any(isinstance(e, InjectedSendError) for e in chain):
                self.report.injected_raised += 1
                return False
            if valid or not isinstance(exc, (traitlets.TraitError, ValueError, TypeError)):
                self.fail(f"{'valid' if valid else 'invalid'} set raised {type(exc).__name__}: "
                          + str(exc).splitlines()[0][:70],
                          f"{what} raised {type(exc).__name__}: {exc}\n" + "".join(traceback.format_exception(exc))[-1500:])
            return False
        if not valid:
            self.fail(f"invalid accepted: {what.split(' =')[0]}", f"{what} was accepted")
        return True

    # -- the run ---------------------------------------------------------------------
    def run(self) -> SoakReport:
        self.log = _LogCapture()
        # every warning comes here; the widget's and ipywidgets' (traitlets') go nowhere else
        # while the soak runs (thousands of injected errors would flood a test report)
        loggers = [logging.getLogger(), logging.getLogger("rot4d_widget"), logging.getLogger("traitlets")]
        propagate = [lg.propagate for lg in loggers]
        for lg in loggers:
            lg.addHandler(self.log)
        for lg in loggers[1:]:
            lg.propagate = False
        t0 = time.perf_counter()
        SoakComm.injected = 0
        SoakComm.rng = random.Random(self.seed + 1)
        try:
            with install_comm(self.page):
                self._run()
        finally:
            for lg, p in zip(loggers, propagate):
                lg.removeHandler(self.log)
                lg.propagate = p
            self.report.seconds = time.perf_counter() - t0
        return self.report

    def _run(self):
        rep = self.report
        warm_events = None
        kinds = list(self.kinds)
        k = 0
        while self.i < self.n_events:
            kind = kinds[k % len(kinds)]
            k += 1
            self.start_session(kind)
            n = min(self.rng.randint(*self.session_events), self.n_events - self.i)
            try:
                for _ in range(n):
                    self.i += 1
                    self.event()
            except SoakFailure:
                raise
            except Exception as exc:
                self.fail("driver error", f"{type(exc).__name__}: {exc}\n{traceback.format_exc()[-2000:]}")
            stats = self.w.stats
            rep.updates += stats.updates
            rep.acks += stats.acks
            rep.timeouts += stats.timeouts
            self.end_session()
            if warm_events is None and k >= min(len(kinds), 3) and self.i < self.n_events:
                gc.collect()
                rep.rss_start, rep.gc_start, warm_events = rss_mb(), len(gc.get_objects()), self.i
            if self.verbose:
                print(f"  session {k} {kind}: {self.i} events, {len(rep.failures)} failure kinds", file=sys.stderr)
        gc.collect()
        rep.events = self.i
        rep.rss_end, rep.gc_end = rss_mb(), len(gc.get_objects())
        rep.injected = SoakComm.injected
        rep.page_messages = self.page.messages
        rep.page_mbytes = self.page.bytes / 1e6
        if warm_events is not None:
            rep.rss_allowed = RSS_SLACK_MB + RSS_MB_PER_10K * (self.i - warm_events) / 1e4
            growth = rep.rss_end - rep.rss_start
            if growth > rep.rss_allowed:
                self.fail("memory growth", f"RSS grew {growth:.1f} MB over {self.i - warm_events} events after "
                                           f"warm-up (allowed {rep.rss_allowed:.1f} MB); gc objects "
                                           f"{rep.gc_start} -> {rep.gc_end}")


def _models() -> dict:
    """Every open widget model by id (ipywidgets' registry, without its deprecation warning)."""
    from ipywidgets.widgets import widget as widget_module

    registry = getattr(widget_module, "_instances", None)
    if registry is None:  # older ipywidgets
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            registry = ipywidgets.Widget.widgets
    return registry


def _chain(exc):
    out = []
    while exc is not None and exc not in out:
        out.append(exc)
        exc = exc.__cause__ or exc.__context__
    return out


def _last_line(text):
    lines = [ln for ln in str(text).strip().splitlines() if ln.strip()]
    return lines[-1].strip() if lines else ""


# ============================================================================ the threaded phase
def threaded_phase(seconds=2.0, seed=1, slow_observer=0.0, bound=None):
    """The real ticker thread (``_autotick=True``, real clock) with two threads pressing keys and
    a third acknowledging, for ``seconds``; ``slow_observer`` s of sleep in a c0 observer.
    Returns (ok, text).  The whole phase runs in a worker thread waited on for ``bound`` s:
    a freeze is reported (with every thread's stack), never waited on forever."""
    import faulthandler
    import tempfile

    bound = bound if bound is not None else seconds + 15.0 + 20.0 * slow_observer
    result = {}
    page = Page()
    saved = comm_package.create_comm
    SoakComm.page = page
    comm_package.create_comm = lambda *a, **k: SoakComm(*a, **k)
    worker = threading.Thread(target=_threaded_body, args=(page, seconds, seed, slow_observer, result),
                              name="soak-threaded-phase", daemon=True)
    try:
        worker.start()
        worker.join(bound)
        if worker.is_alive():
            with tempfile.TemporaryFile("w+") as f:
                faulthandler.dump_traceback(f, all_threads=True)
                f.seek(0)
                stacks = f.read()
            where = result.get("stage", "?")
            return False, (f"FROZE: the phase did not finish within {bound:.0f} s (stage: {where}); "
                           f"thread stacks:\n{stacks[-4000:]}")
    finally:
        if not worker.is_alive():
            comm_package.create_comm = saved
            SoakComm.page = None
        # else: a frozen worker may still make widgets; leave the soak comm in place (daemon threads)
    return result.get("ok", False), result.get("text", "no result")


def _threaded_body(page, seconds, seed, slow_observer, result):
    from rot4d_widget.view.widget import Rot4DWidget

    problems = []
    result["stage"] = "making the widget"
    before = set(_models())
    w = Rot4DWidget("24-cell", _autotick=True)
    if slow_observer:
        w.observe(lambda ch: time.sleep(slow_observer), names="c0")
    stop = threading.Event()
    counts = [0, 0]
    max_flight = [0]
    latencies = []

    def presser(j):
        rng = random.Random(seed * 10 + j)
        keys = [("4", "Digit4"), ("c", "KeyC"), ("l", "KeyL"), ("h", "KeyH"), ("z", "KeyZ"), ("k", "KeyK")]
        down = {}

        def send(kind, key, code):
            ev = {"type": kind, "event": kind, "key": key, "code": code, "shiftKey": False,
                  "altKey": False, "ctrlKey": False, "metaKey": False, "repeat": False,
                  "timeStamp": time.monotonic() * 1000.0, "location": 0, "target": {}}
            t = time.monotonic()
            try:
                w.events.comm.handler(custom_msg(ev))
            except Exception as exc:  # noqa: BLE001
                problems.append(f"thread {j}: {exc!r}")
            latencies.append(time.monotonic() - t)

        while not stop.is_set():
            key, code = rng.choice(keys)
            if code in down and rng.random() < 0.6:
                send("keyup", key, code)
                down.pop(code)
            else:
                send("keydown", key, code)
                down[code] = key
            counts[j] += 1
            time.sleep(rng.uniform(0.0, 0.03))
        for code, key in list(down.items()):
            send("keyup", key, code)

    result["stage"] = "pressing from two threads"
    threads = [threading.Thread(target=presser, args=(j,), name=f"soak-presser-{j}", daemon=True)
               for j in range(2)]
    for t in threads:
        t.start()
    t_end = time.monotonic() + seconds
    bid = w.scene.buffer_model_id
    while time.monotonic() < t_end:
        arrived = page.arrived[bid]
        if arrived:
            seq = arrived[-1]
            arrived.clear()
            w.companion.comm.handler(custom_msg({"event": "drawn", "seq": seq}))
        max_flight[0] = max(max_flight[0], w._pump.n_in_flight)
        time.sleep(0.01)
    stop.set()
    result["stage"] = "joining the pressing threads"
    for t in threads:
        t.join()
    time.sleep(0.3)
    result["stage"] = "checking"
    if w.held_keys != ():
        problems.append(f"held_keys == {w.held_keys!r} after every keyup")
    if max_flight[0] > w._pump.max_in_flight:
        problems.append(f"{max_flight[0]} in flight > {w._pump.max_in_flight}")
    m = np.asarray(w.state.matrix)
    e = float(np.linalg.norm(m @ m.T - np.eye(4)))
    if e > ORTHO_TOL:
        problems.append(f"‖RRᵀ−I‖ = {e:.3g}")
    if w.errors.outputs:
        problems.append(f"errors shown: {_last_line(w.errors.outputs[-1].get('text', ''))}")
    worst = max(latencies) if latencies else 0.0
    if worst > 3 * slow_observer + 0.5:  # its own observer call and the one running, plus slack
        problems.append(f"a key event took {worst:.2f} s to be handled (slow observer {slow_observer} s)")
    result["stage"] = "closing"
    t = time.monotonic()
    w.close()
    if time.monotonic() - t > 3.0:
        problems.append(f"close() took {time.monotonic() - t:.1f} s")
    if w._pump.thread_alive:
        problems.append("the ticker thread is alive after close()")
    gc.collect()
    left = [type(m).__name__ for k, m in list(_models().items()) if k not in before]
    if left:
        problems.append(f"{len(left)} widget models open after close: {dict(collections.Counter(left))}")
    text = (f"{sum(counts)} key events from 2 threads in {seconds:g} s, max in flight {max_flight[0]}, "
            f"slowest handling {worst * 1e3:.0f} ms")
    result["ok"] = not problems
    result["text"] = text + ("" if not problems else "; PROBLEMS: " + "; ".join(problems))
    result["stage"] = "done"


def run_soak(events=5000, seed=1, **kwargs) -> SoakReport:
    return Soak(events, seed, **kwargs).run()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--events", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--no-threads", action="store_true", help="skip the real-ticker phase")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    print(f"python benchmarks/soak.py --events {args.events} --seed {args.seed}")
    rep = run_soak(args.events, args.seed, verbose=args.verbose)
    if not args.no_threads:
        ok, text = threaded_phase(2.0, args.seed)
        ok2, text2 = threaded_phase(2.0, args.seed, slow_observer=0.2)
        rep.threaded = f"{'ok' if ok else 'FAILED'}: {text}\n{'':32}slow observer 0.2 s: " \
                       f"{'ok' if ok2 else 'FAILED'}: {text2}"
    print(rep.table())
    print()
    print(rep.failure_text())
    return 0 if rep.ok else 1


if __name__ == "__main__":
    sys.exit(main())
