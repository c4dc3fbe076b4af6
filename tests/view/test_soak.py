"""Soak: thousands of random front-end events through the widget's own comms (slow).

The driver is benchmarks/soak.py (one copy, also run at 10^5 events there): key events as
ipyevents delivers them (a custom comm message to the canvas's ``Event`` model, which hands the
dict to its ``on_dom_event`` callbacks), key pad button events the same way, the companion's
"drawn" acknowledgements (newest, late, duplicate, missing, malformed) and focus losses as the
companion's comm messages, trait sets (valid and invalid), source switches (a polytope, a
Field4D, a stack; ``slices`` and key n on a single view), and phases where the comm raises on
``send``.  Fake clock, ``_autotick=False``, ``w._pump.service(now)`` between events.  A failed
check names the seed, the first event and the last events; every kind of failure of the run is
listed, the first one first.

    SOAK_EVENTS=20000 SOAK_SEED=7 pytest -m slow tests/view/test_soak.py
"""

from __future__ import annotations

import os
import pathlib
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "benchmarks"))
import soak  # noqa: E402  (the driver lives with the benchmark that runs it at 10^5 events)

#: Events of the default run: about 30 s here (~600 events/s), well under 3 min on a busy 2-core machine.
EVENTS = int(os.environ.get("SOAK_EVENTS", "15000"))
SEED = int(os.environ.get("SOAK_SEED", "20240"))


@pytest.mark.slow
def test_soak_random_events_keep_every_invariant():
    report = soak.run_soak(EVENTS, SEED)
    print(report.table())
    assert report.events == EVENTS
    assert report.injected > 0 and report.valid_sets > 0 and report.invalid_sets > 0  # the soak did soak
    assert report.ok, report.failure_text()


@pytest.mark.slow
def test_soak_real_ticker_two_pressing_threads():
    """The real ticker thread and two threads pressing: bounded in time, nothing held, no freeze."""
    ok, text = soak.threaded_phase(2.0, SEED)
    assert ok, text


@pytest.mark.slow
def test_soak_real_ticker_with_a_slow_observer():
    """A 0.2 s observer of c0 while keys are held must not freeze the key handling."""
    ok, text = soak.threaded_phase(2.0, SEED, slow_observer=0.2)
    assert ok, text
