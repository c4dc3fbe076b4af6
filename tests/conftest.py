"""Shared fixtures: a recording comm, a fake clock, widgets made with them."""

import pytest

import recording_comm


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
