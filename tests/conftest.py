"""Shared fixtures: a recording comm, a fake clock, widgets made with them."""

import pytest

import recording_comm


def pytest_xdist_make_scheduler(config, log):
    """Run in two processes (``python -m pytest -n 2``, the README's command), the browser tests
    stay together in one of them -- one JupyterLab server and one Chromium at a time, which is
    what their timings are written for -- while the other runs the rest a file at a time (a
    module's fixtures are built once; a notebook's cells run in order in one kernel).  The browser
    tests are collected first (``--no-loadscope-reorder``), so the longest work starts first.

    (xdist's own ``--dist loadgroup`` cannot do this under pytest 9.2: it renames items by
    assigning ``item._nodeid``, which pytest no longer reads.)"""
    from xdist.scheduler import LoadFileScheduling

    class BrowserTogether(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return "tests/browser" if nodeid.startswith("tests/browser/") else super()._split_scope(nodeid)

    return BrowserTogether(config, log)


@pytest.fixture
def recording_comms(monkeypatch):
    """Widgets created in the test send through RecordingComm; yields its log."""
    yield recording_comm.install(monkeypatch)


class FakeClock:
    def __init__(self, t=100.0):
        self.t = t

    def __call__(self):
        return self.t


@pytest.fixture
def clock():
    return FakeClock()


@pytest.fixture
def make(clock):
    """Build Rot4DWidgets on the fake clock without a ticker thread; closed afterwards."""
    from rot4d_widget.view.widget import Rot4DWidget

    made = []

    def _make(*args, **kwargs):
        kwargs.setdefault("_clock", clock)
        kwargs.setdefault("_autotick", False)
        w = Rot4DWidget(*args, **kwargs)
        made.append(w)
        return w

    yield _make
    for w in made:
        w.close()
