"""The update pump: at most ``max_in_flight`` scene updates in flight, acknowledged by the page.

`UpdatePump` sends an update computed from the latest state whenever fewer than its bound in force
(`limit`) await the page's "drawn"; an acknowledgement retires its update and every older one, so
nothing queues and the view settles as soon as the state stops changing.  The bound grows for a
page far away (what leaves in one round trip, at most `MAX_IN_FLIGHT_CAP`) and shrinks for a slow
page (what it draws in `PAGE_BUDGET`, never below two); with no answer the oldest update is given
up after a timeout (at most `MAX_ACK_TIMEOUT`).  Time advances through ``service(now)``, called by
a daemon thread (``autotick``) or by tests with their own clock.  Every entry point runs under one
re-entrant lock shared with the owner (``pump.lock``); a ``send`` that is a generator does its slow
part outside it.  Errors from ``tick``/``send`` go to ``on_error``.  Why, and the rules that keep
a slow kernel from freezing the keys: docs/design.md, "Flow control".
"""

from __future__ import annotations

import inspect
import math
import threading
import time
from dataclasses import dataclass

__all__ = ["UpdatePump", "PumpStats", "ACK_TIMEOUT", "MAX_ACK_TIMEOUT", "MAX_IN_FLIGHT", "PAGE_BUDGET",
           "MAX_IN_FLIGHT_CAP"]

ACK_TIMEOUT = 0.5
#: The adaptive acknowledgement timeout never exceeds this (s).
MAX_ACK_TIMEOUT = 5.0
#: The ticker thread always waits at least this long between services (s): the lock is free then.
MIN_WAIT = 0.001
#: Updates allowed in flight at once (1: strictly one at a time).
MAX_IN_FLIGHT = 3
#: The page's time for what is in flight, at most (s): a slow page gets fewer updates in flight.
PAGE_BUDGET = 0.25
#: However far the page, at most this many updates in flight (a 400 ms round trip at 30 Hz).
MAX_IN_FLIGHT_CAP = 12
#: Recent acknowledgement times the adaptive timeout (and the page's times the bound) look at.
_ACK_WINDOW = 8


def _lower_median(values) -> float:
    times = sorted(values)
    return times[(len(times) - 1) // 2]


def _complete(gen, result):
    """Send ``result`` into a two-phase send's generator; the update id it returns."""
    try:
        gen.send(result)
    except StopIteration as stop:
        return stop.value
    raise RuntimeError("a two-phase send must yield exactly once")


@dataclass
class PumpStats:
    """Counters of one pump.

    updates: sent; acks: acknowledgements that retired updates; acknowledged:
    updates they retired (an acknowledgement retires every older update too);
    timeouts: updates given up unanswered.  At any time
    ``updates - acknowledged - timeouts`` (the initial picture aside) is what is in flight.
    """

    updates: int = 0
    acks: int = 0
    acknowledged: int = 0
    timeouts: int = 0

    def as_dict(self) -> dict:
        return {"updates": self.updates, "acks": self.acks, "acknowledged": self.acknowledged,
                "timeouts": self.timeouts}


class UpdatePump:
    """At most ``max_in_flight`` updates in flight (`MAX_IN_FLIGHT`: three), each acknowledged by the page.

    Parameters
    ----------
    send : callable () -> int or None, or a generator function
        Compute and send the latest state; return the update's id when an
        update left (an acknowledgement is then awaited), None when nothing
        changed on screen.  A generator yields once a callable (the slow
        part, run without the lock on the ticker thread), receives its result
        and returns the id (docs/design.md, "Flow control").
    tick : callable (now) -> None, optional
        Advance time-driven state (held keys) to ``now``.
    deadline : callable () -> float or None, optional
        When ``tick`` next wants to run.
    clock : callable () -> seconds
    ack_timeout : float
        Seconds to wait for an acknowledgement at least (docs/design.md, "Flow control").
    max_in_flight : int >= 1
        The bound near the page; far from it, ``ceil(round trip x tick_rate)`` (`limit`).
    tick_rate : float, optional
        The widget's ticks per second (held keys), for `limit`.
    autotick : bool
        Run the daemon thread when there is something to wait for.
    on_error : callable (exception) -> None
    """

    def __init__(self, send, *, tick=None, deadline=None, clock=None, ack_timeout=ACK_TIMEOUT,
                 max_in_flight=MAX_IN_FLIGHT, autotick=True, on_error=None, name="rot4d-ticker", tick_rate=None):
        self._send = send
        self._tick = tick
        self._deadline = deadline
        self.clock = clock if clock is not None else time.monotonic
        self.ack_timeout = float(ack_timeout)
        if isinstance(max_in_flight, bool) or not isinstance(max_in_flight, int) or max_in_flight < 1:
            raise ValueError(f"Expected `max_in_flight` to be an int >= 1, got {max_in_flight!r}")
        self.max_in_flight = max_in_flight
        self.tick_rate = tick_rate  # Hz: with the round trip, how many updates may be in flight
        self.autotick = bool(autotick)
        self._on_error = on_error
        self._name = name
        self.lock = threading.RLock()
        self._wakeup = threading.Condition(self.lock)
        self.stats = PumpStats()
        self._dirty = False
        self._flight = {}  # update id -> clock time sent, oldest first
        self._ack_times = []  # recent send -> acknowledgement durations
        self._draw_times = []  # recent arrival -> acknowledgement durations the page reported
        self._thread = None
        self._closed = False
        self._sending = False  # a send is being computed outside the lock (ticker thread)
        self._failed = False  # the last send raised: retried on the next ack, key or flush, not at once

    def connect(self, send, *, tick=None, deadline=None) -> None:
        """The callbacks, for an owner whose units are made after the pump (they take its lock):
        ``send``, and optionally ``tick`` and ``deadline``, as the constructor's."""
        self._send, self._tick, self._deadline = send, tick, deadline

    # -- state ----------------------------------------------------------------
    @property
    def closed(self) -> bool:
        """True once `shut` (or `close`): nothing is sent, acknowledged or ticked any more."""
        return self._closed

    def check_open(self) -> None:
        """Raise RuntimeError when `closed` (the widget's API refuses to act then)."""
        if self._closed:
            raise RuntimeError("This Rot4DWidget is closed")

    @property
    def in_flight(self):
        """Id of the newest update awaiting its acknowledgement, or None."""
        return next(reversed(self._flight), None)

    @property
    def n_in_flight(self) -> int:
        return len(self._flight)

    @property
    def round_trip(self) -> float | None:
        """The page's recent round trip (s): the median send -> acknowledgement time less the median
        time the page itself took (arrival -> acknowledgement); None before any is known."""
        if not self._ack_times or not self._draw_times:
            return None
        return max(0.0, _lower_median(self._ack_times) - _lower_median(self._draw_times))

    @property
    def limit(self) -> int:
        """Updates allowed in flight now: ``max_in_flight``, or for a page far away as many as leave in
        one round trip at the tick rate (``ceil(round_trip * tick_rate)``, at most `MAX_IN_FLIGHT_CAP`:
        a remote kernel keeps the page drawing every tick); fewer for a slow page, as many as it
        draws in `PAGE_BUDGET` by its recent median ``draw_time`` (at least two; module docs)."""
        want = self.max_in_flight
        rtt = self.round_trip
        if rtt is not None and self.tick_rate and self.max_in_flight > 2:
            want = max(want, min(MAX_IN_FLIGHT_CAP, math.ceil(rtt * self.tick_rate)))
        if not self._draw_times or self.max_in_flight <= 2:
            return want
        t = _lower_median(self._draw_times)
        fits = int(PAGE_BUDGET / t) if t > 0 else want
        return max(2, min(want, fits))

    @property
    def timeout(self) -> float:
        """The acknowledgement timeout in force: ``ack_timeout``, or 4 x the recent median if larger."""
        times = sorted(self._ack_times)
        recent = 4.0 * times[(len(times) - 1) // 2] if times else 0.0  # the lower median
        return max(self.ack_timeout, min(recent, MAX_ACK_TIMEOUT))

    @property
    def dirty(self) -> bool:
        """The state changed since the last update was computed."""
        return self._dirty

    def mark_dirty(self) -> None:
        """The state changed: send it as soon as flow control allows (call ``flush``)."""
        self._dirty = True
        self._failed = False

    # -- entry points -----------------------------------------------------------
    def flush(self, now=None) -> None:
        """Send the latest state unless `limit` updates are in flight (and none timed out).

        With ``autotick`` the ticker thread sends (this wakes it); otherwise it sends here."""
        with self.lock:
            if self._closed or not self._dirty:
                return
            self._failed = False
            if self.autotick and threading.current_thread() is not self._thread:
                self.wake()
                return
            self._flush(self.clock() if now is None else now)

    def wait_sent(self, timeout: float = 60.0) -> bool:
        """From code on another thread than the ticker's: wait until the latest state has left
        (True), or flow control holds it (updates in flight await the page), or the send failed, or
        ``timeout`` seconds passed (False).  The ticker thread computes a send outside the lock, so
        without this a caller could read the widget (its readout, its buffers) before the update
        it asked for.  Woken by the ticker's `wake` when a send ends (at most every 50 ms otherwise)."""
        if not self.autotick or threading.current_thread() is self._thread:
            return not self._dirty
        end = time.monotonic() + timeout
        with self.lock:
            while True:
                if self._closed or not (self._dirty or self._sending):
                    return not self._dirty
                if self._failed or (not self._sending and self._held(self.clock())):
                    return False  # failed (reported, retried on the next key), or sent when the page answers
                left = end - time.monotonic()
                if left <= 0:
                    return False
                self._wakeup.wait(min(left, 0.05))

    def _held(self, now) -> bool:
        """Flow control holds the next update: `limit` await the page, the oldest for less than the
        timeout."""
        return len(self._flight) >= self.limit and now - next(iter(self._flight.values())) < self.timeout

    def _may_send(self, now) -> bool:
        """Flow control: True if an update may leave now (gives up the oldest after the timeout)."""
        if self._sending or self._held(now):
            return False
        if len(self._flight) >= self.limit:
            del self._flight[next(iter(self._flight))]  # the page does not answer: stop waiting for the oldest
            self.stats.timeouts += 1
        return True

    def _flush(self, now, *, worker: bool = False) -> None:
        if self._dirty and self._may_send(now):
            self._send_locked(now, True, worker)
        self.wake()

    def send_now(self, now=None, *, expect_ack=True) -> None:
        """Compute and send the latest state now, here, whatever is in flight (the initial
        picture).  If ``send`` raises, the state stays dirty (the picture is not lost) and the
        exception propagates."""
        with self.lock:
            self._send_locked(now, expect_ack, False)

    def _send_locked(self, now, expect_ack, worker) -> None:
        """Send under the lock.  ``worker`` (the ticker thread): a two-phase send's slow part goes
        to a worker thread, so ticks go on meanwhile; the worker finishes the send under the lock
        (`_work`), and until then no other send starts."""
        self._dirty = False
        self._sending = True
        try:
            seq = self._send()
            if inspect.isgenerator(seq):
                try:
                    work = next(seq)
                except StopIteration as stop:
                    seq = stop.value
                else:
                    if worker:
                        threading.Thread(target=self._work, args=(seq, work, now, expect_ack),
                                         name=f"{self._name}-slice", daemon=True).start()
                        return  # still sending: `_work` ends it
                    seq = _complete(seq, work())
        except BaseException:
            self._sending = False
            self._dirty = self._failed = True
            raise
        self._sending = False
        self._sent(seq, now, expect_ack)

    def _sent(self, seq, now, expect_ack) -> None:
        if seq is not None:
            self.stats.updates += 1
            if expect_ack:
                self._flight[seq] = self.clock() if now is None else now

    def _work(self, gen, work, now, expect_ack) -> None:
        """The worker: the slow part without the lock, then the rest of the send under it."""
        try:
            result, error = work(), None
        except BaseException as exc:  # reported under the lock, like any failed send
            result, error = None, exc
        with self.lock:
            try:
                if error is not None:
                    gen.close()
                    raise error
                self._sent(_complete(gen, result), self.clock() if now is None else now, expect_ack)
            except Exception as exc:
                self._dirty = self._failed = True
                self._report(exc)
            finally:
                self._sending = False
                self.wake()  # the latest state may be waiting

    def acknowledge(self, seq, draw_time=None) -> bool:
        """The page drew update ``seq`` (and so every older one); True if it was awaited.
        ``draw_time``: the page's seconds from the update's arrival to this acknowledgement, if it
        said (a finite number >= 0, else ignored): a slow page gets fewer in flight (`limit`)."""
        if isinstance(seq, bool) or not isinstance(seq, int):
            return False
        with self.lock:
            if self._closed or seq not in self._flight:
                return False  # late, duplicate (another view), unknown, or after a timeout
            sent = self._flight[seq]
            for k in [k for k in self._flight if k <= seq]:
                del self._flight[k]
                self.stats.acknowledged += 1
            self._ack_times = (self._ack_times + [min(max(0.0, self.clock() - sent), MAX_ACK_TIMEOUT)])[-_ACK_WINDOW:]
            if (isinstance(draw_time, (int, float)) and not isinstance(draw_time, bool)
                    and 0.0 <= draw_time < math.inf):
                self._draw_times = (self._draw_times + [min(float(draw_time), MAX_ACK_TIMEOUT)])[-_ACK_WINDOW:]
            self.stats.acks += 1
            self._failed = False
            self.flush()
            return True

    def service(self, now=None, *, worker: bool = False):
        """Run due ticks, honour the timeout, send if allowed; the clock time to run next (or None).

        ``worker`` (the ticker thread): a two-phase send's slow part runs on a worker thread."""
        with self.lock:
            if self._closed:
                return None
            now = self.clock() if now is None else now
            try:
                if self._tick is not None:
                    self._tick(now)
            except Exception as exc:
                self._report(exc)
            try:
                self._flush(now, worker=worker)
            except Exception as exc:  # the state stays dirty: the next ack, key or flush retries
                self._report(exc)
            return self.next_deadline()

    def next_deadline(self):
        deadlines = []
        if self._deadline is not None:
            d = self._deadline()
            if d is not None:
                deadlines.append(d)
        if self._dirty and len(self._flight) >= self.limit:
            deadlines.append(next(iter(self._flight.values())) + self.timeout)
        elif self._dirty and self.autotick and not self._sending and not self._failed:
            deadlines.append(self.clock())  # a flush woke the thread: send now
        return min(deadlines) if deadlines else None

    # -- the thread -------------------------------------------------------------
    def wake(self) -> None:
        """Start the ticker thread if there is something to wait for; let it recompute its deadline."""
        with self.lock:
            if not self.autotick or self._closed:
                return
            if self._thread is None:
                if self.next_deadline() is None:
                    return
                self._thread = threading.Thread(target=self._run, name=self._name, daemon=True)
                self._thread.start()
            self._wakeup.notify_all()

    def _run(self) -> None:
        """The ticker: one `service` per turn under the lock, then a wait (at least `MIN_WAIT`)
        that releases it, so other threads always get the lock between ticks."""
        while True:
            self.service(worker=True)  # the lock for this service only; slicing goes to a worker
            with self.lock:
                if self._closed:
                    return
                deadline = self.next_deadline()  # again: a flush may have come in meanwhile
                if deadline is None:
                    self._wakeup.wait()
                else:
                    self._wakeup.wait(max(deadline - self.clock(), MIN_WAIT))

    @property
    def thread_alive(self) -> bool:
        t = self._thread
        return t is not None and t.is_alive()

    def shut(self) -> None:
        """From now on `closed`: nothing more is sent; the thread ends (`close` joins it)."""
        with self.lock:
            self._closed = True
            self._wakeup.notify_all()

    def close(self) -> None:
        """`shut`, and join the thread (unless called from it); idempotent."""
        with self.lock:
            self.shut()
            thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)

    def _report(self, exc) -> None:
        if self._on_error is not None:
            self._on_error(exc)
